/// The paper's Figure 1 in one dimension: a simulator with a known error, a handful of noisy
/// measurements of the real system, and the GP with the simulator as its mean function, fitted by the
/// library (gp::ResidualModel with the exact backend) and sliced by model_slice as `gpilqg run` does.
///
///   simulator   x' = phi_sim(x, u) = x + dt (-a x + u)
///   real world  x' = phi_sim(x, u) + dt c sin(w x)        (the known residual)
///   measured    x'_k = real(x_k, 0) + e_k,  e_k ~ N(0, sigma^2)
///
/// Near the measurements the corrected model x' = phi_sim + mu follows the real world with a narrow
/// band; away from them mu -> 0 and the band widens to the prior's sf: the model is the simulator again.
///
/// usage: gpilqg_gp_1d [--out FILE.h5] [--plots DIR] [--seed N]
///   writes /gp_1d/figure1 (the layout of model_slice_io.hpp) to FILE.h5 (default gp_1d.h5) and, with
///   --plots, draws it with experiments/plots/plot_slice.py into DIR.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/experiments/model_slice.hpp"
#include "gpilqg/experiments/model_slice_io.hpp"
#include "gpilqg/experiments/plot_script.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace {

using gpilqg::StepJacobians;
using gpilqg::StepModel;
using gpilqg::StepWorkspace;
using gpilqg::Vector;
using gpilqg::VectorCRef;
using gpilqg::VectorRef;

constexpr double kDt = 0.1;
constexpr double kDecay = 0.5;      // a
constexpr double kAmplitude = 1.5;  // c: the residual is at most dt c = 0.15 per step
constexpr double kFrequency = 2.0;  // w
constexpr double kNoiseStd = 0.01;  // sigma

/// x' = x + dt (-a x + u), plus dt c sin(w x) for the real world.
class FirstOrderSystem final : public StepModel {
 public:
  explicit FirstOrderSystem(bool real) : real_(real) {}
  int state_dim() const override { return 1; }
  int control_dim() const override { return 1; }
  double dt() const override { return kDt; }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians, StepWorkspace&) const override {
    x_next(0) = x(0) + kDt * (-kDecay * x(0) + u(0));
    double dx = 1.0 - kDt * kDecay;
    if (real_) {
      x_next(0) += kDt * kAmplitude * std::sin(kFrequency * x(0));
      dx += kDt * kAmplitude * kFrequency * std::cos(kFrequency * x(0));
    }
    if (jacobians != nullptr) {
      jacobians->A.setConstant(1, 1, dx);
      jacobians->B.setConstant(1, 1, kDt);
    }
  }

 private:
  bool real_;
};

struct Options {
  std::string out = "gp_1d.h5";
  std::string plots;
  std::uint64_t seed = 1;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      std::cout << "usage: gpilqg_gp_1d [--out FILE.h5] [--plots DIR] [--seed N]\n";
      std::exit(0);
    }
    if (flag != "--out" && flag != "--plots" && flag != "--seed")
      throw std::invalid_argument("unknown option " + flag + " (see --help)");
    if (i + 1 >= argc) throw std::invalid_argument(flag + " needs a value");
    const std::string value = argv[++i];
    if (flag == "--out") o.out = value;
    else if (flag == "--plots") o.plots = value;
    else {
      const bool digits = !value.empty() && value.size() <= 19 && value.find_first_not_of("0123456789") == std::string::npos;
      if (!digits) throw std::invalid_argument("--seed " + value + ": expected a whole number below 1e19");
      o.seed = std::stoull(value);
    }
  }
  return o;
}

/// Eight measurements of the real world at u = 0, at states in two clusters, x in [-2, -0.8] and
/// [0.6, 1.2], so that the figure shows the band narrow at each and wider between and beyond them.
gpilqg::TransitionData measure(const StepModel& real, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> left(-2.0, -0.8), right(0.6, 1.2);
  std::normal_distribution<double> noise(0.0, kNoiseStd);
  constexpr int kRows = 8;
  gpilqg::TransitionData data;
  data.x.resize(kRows, 1), data.u = gpilqg::Matrix::Zero(kRows, 1), data.x_next.resize(kRows, 1);
  data.iteration.assign(kRows, 0);
  Vector x_next(1);
  for (int r = 0; r < kRows; ++r) {
    data.x(r, 0) = r < 5 ? left(gen) : right(gen);
    real.step(data.x.row(r).transpose(), data.u.row(r).transpose(), x_next);
    data.x_next(r, 0) = x_next(0) + noise(gen);
  }
  return data;
}

int run(const Options& o) {
  const auto simulator = std::make_shared<const FirstOrderSystem>(false);
  const FirstOrderSystem real(true);
  const gpilqg::TransitionData data = measure(real, o.seed);
  const gpilqg::gp::ResidualData residuals = gpilqg::gp::make_residual_data(*simulator, data.x, data.u, data.x_next);
  gpilqg::gp::ResidualModelOptions fit;
  fit.fit.seed = o.seed;
  const gpilqg::gp::ResidualModel model =
      gpilqg::gp::ResidualModel::fit(simulator, residuals, gpilqg::gp::ExactGpBackend{}, fit);
  const gpilqg::ModelSlice slice = gpilqg::model_slice(real, model, data);

  const gpilqg::SystemSignature signature{"gp_1d", {{"x", ""}}, {{"u", ""}}};
  const std::filesystem::path out(o.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  gpilqg::Hdf5Writer h5(out);
  h5.attribute("/", "system", std::string("gp_1d"));
  h5.attribute("/", "description",
               std::string("x' = x + dt (-a x + u) (simulator); the real world adds dt c sin(w x); measured at u = 0 "
                           "with noise std sigma"));
  h5.attribute("/", "parameters", std::vector<double>{kDt, kDecay, kAmplitude, kFrequency, kNoiseStd});
  h5.attribute("/", "parameter_names", std::vector<std::string>{"dt", "a", "c", "w", "sigma"});
  gpilqg::write_model_slice(h5, "/gp_1d", slice, signature);
  h5.close();
  std::cout << "wrote " << o.out << " (" << data.size() << " measurements, length-scale "
            << slice.length_scales(0) << ")\n";
  if (!o.plots.empty()) gpilqg::run_plot_script("plot_slice.py", o.out, o.plots);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
