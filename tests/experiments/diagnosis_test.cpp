#include <gtest/gtest.h>

#include <chrono>
#include <iostream>

#include "diagnosis_support.hpp"

namespace gpilqg {
namespace {

using diagnosis::DiagnosisReport;

void print(const DiagnosisReport& r) {
  for (const auto& s : r.states)
    std::cout << s.name << " rmse " << s.rmse << " floor " << s.noise_floor << " heldout " << s.heldout_rmse
              << " gpexpl " << s.gp_explained << " fit% " << s.fit_percent << (s.structured ? " STRUCT" : "") << "\n";
  std::cout << "gp explained total " << r.gp_explained_total << " consistent " << r.consistent << "\n";
  for (const auto& g : r.ranking) {
    std::cout << "  " << g.fit.effect << " theta " << g.fit.estimate.transpose() << " [" << g.fit.ci_low.transpose()
              << ", " << g.fit.ci_high.transpose() << "] lin " << g.fit.linear_estimate.transpose() << " expl "
              << g.fit.explained << " +- " << g.fit.explained_ci << " z " << g.fit.z_score << " evals "
              << g.fit.evaluations << " aliases:";
    for (const auto& a : g.aliases) std::cout << " " << a.effect << "(" << a.explained << ")";
    std::cout << "\n";
  }
  std::cout << "verdict " << r.verdict.status << " " << r.verdict.reason << "\n";
  for (const auto& m : r.comparison)
    std::cout << m.name << " rmse " << m.heldout_rmse.transpose() << " sf2 " << m.signal_variance.transpose() << "\n";
}

TEST(DiagnosisProbe, Cases) {
  struct Case { std::string system, effect; double value; };
  for (const Case& c : std::vector<Case>{{"cartpole", "cart_coulomb_friction", 1.0},
                                         {"cartpole", "cart_viscous_friction", 0.8},
                                         {"cartpole", "actuator_gain", 0.8},
                                         {"cartpole", "param:pole_length", 1.3},
                                         {"cartpole", "", 0.0},
                                         {"quadrotor", "param:mass", 0.7},
                                         {"quadrotor", "quadratic_drag", 0.3}}) {
    ModelSpec world;
    world.system = c.system;
    if (!c.effect.empty()) world = world.with(find_effect(c.system, c.effect), Vector::Constant(1, c.value));
    const int m = c.system == "cartpole" ? 1 : 4;
    const auto data = test::hidden_effect_data(world.build(test::actuator_noise(m, c.system == "cartpole" ? 0.02 : 0.002)), 3);
    const auto start = std::chrono::steady_clock::now();
    const auto report = diagnosis::diagnose(data, test::fast_options(c.system));
    std::cout << "=== " << c.system << " " << c.effect << " " << c.value << " ("
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s)\n";
    print(report);
  }
}

}  // namespace
}  // namespace gpilqg
