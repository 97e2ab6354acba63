// The dependency-free evaluators (evaluator/: the C function and the C++ header) and the docs' Python
// function run a policy file's law exactly as the library's AffinePolicy::control does: on 1,000
// random states per policy, many of them clamped, reading the arrays as the policy file stores them.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <fmt/format.h>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg_policy.h"
#include "gpilqg_policy.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

struct Case {
  int n, m;
  bool lower, upper;  ///< which limits the policy has
};

constexpr int kHorizon = 25;
constexpr int kStates = 1000;

/// A random policy with limits that clamp about a third of the controls on each side.
PolicyFile random_policy(const Case& c, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const auto random = [&](int rows, int cols) {
    Matrix out(rows, cols);
    for (double& v : out.reshaped()) v = normal(rng);
    return out;
  };
  PolicyFile p;
  p.policy.x_bar = random(c.n, kHorizon + 1);
  p.policy.u_bar = random(c.m, kHorizon);
  p.policy.k = Matrix::Zero(c.m, kHorizon);
  for (int t = 0; t < kHorizon; ++t) p.policy.K.push_back(random(c.m, c.n));
  // u = u_bar + K e with e ~ N(0, 4 I) below: std of u about 2 sqrt(n); limits at -+0.4 of that.
  const double spread = 2.0 * std::sqrt(static_cast<double>(c.n));
  if (c.lower) p.policy.u_min = Vector::Constant(c.m, -0.4 * spread);
  if (c.upper) p.policy.u_max = Vector::Constant(c.m, 0.4 * spread);
  p.dt = 0.05;
  p.system = "test";
  for (int i = 0; i < c.n; ++i) p.state_names.push_back(fmt::format("s{}", i));
  for (int j = 0; j < c.m; ++j) p.control_names.push_back(fmt::format("c{}", j));
  p.gpilqg_version = "test";
  return p;
}

/// (t, x) pairs around the nominal states.
struct Queries {
  std::vector<int> t;
  Matrix x;  ///< n x kStates
};
Queries random_queries(const PolicyFile& p, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 2.0);
  std::uniform_int_distribution<int> step(0, kHorizon - 1);
  Queries q;
  q.x.resize(p.policy.x_bar.rows(), kStates);
  for (int s = 0; s < kStates; ++s) {
    q.t.push_back(step(rng));
    for (Eigen::Index i = 0; i < q.x.rows(); ++i) q.x(i, s) = p.policy.x_bar(i, q.t.back()) + normal(rng);
  }
  return q;
}

/// The library's controls (m x kStates), and how many entries the limits changed.
Matrix library_controls(const PolicyFile& p, const Queries& q, int& clamped) {
  Matrix u(p.policy.u_bar.rows(), kStates);
  AffinePolicy unlimited = p.policy;
  unlimited.u_min = unlimited.u_max = Vector();
  Vector free(u.rows());
  clamped = 0;
  for (int s = 0; s < kStates; ++s) {
    Vector column(u.rows());
    p.policy.control(q.t[static_cast<std::size_t>(s)], q.x.col(s), column);
    unlimited.control(q.t[static_cast<std::size_t>(s)], q.x.col(s), free);
    clamped += static_cast<int>(((column - free).array() != 0.0).count());
    u.col(s) = column;
  }
  return u;
}

/// The policy file's arrays as a controller would load them (row-major, straight from the datasets).
struct RawPolicy {
  std::vector<double> x_bar, u_bar, K, u_min, u_max;
};
RawPolicy raw(const fs::path& file) {
  const Hdf5Reader h5(file);
  RawPolicy r{h5.read_array("/policy/x_bar"), h5.read_array("/policy/u_bar"), h5.read_array("/policy/K"), {}, {}};
  if (h5.has_attribute("/policy", "u_min")) r.u_min = h5.number_list_attribute("/policy", "u_min");
  if (h5.has_attribute("/policy", "u_max")) r.u_max = h5.number_list_attribute("/policy", "u_max");
  return r;
}

class PolicyEvaluator : public ::testing::TestWithParam<Case> {};

TEST_P(PolicyEvaluator, CAndCxxEqualTheLibraryOnAThousandStates) {
  const Case c = GetParam();
  const fs::path dir = test::temporary_dir("policy_evaluator");
  const PolicyFile policy = random_policy(c, 11u + static_cast<unsigned>(c.n * 10 + c.m));
  write_policy_file(dir / "policy.h5", policy, nullptr);
  const Queries q = random_queries(policy, 7);
  int clamped = 0;
  const Matrix expected = library_controls(policy, q, clamped);
  if (c.lower || c.upper) {
    EXPECT_GT(clamped, kStates * c.m / 10) << "too few clamped controls to test the limits";
    EXPECT_LT(clamped, kStates * c.m * 9 / 10) << "too few free controls to test the law";
  }

  const RawPolicy r = raw(dir / "policy.h5");
  const gpilqg_policy cp{kHorizon, c.n, c.m, r.x_bar.data(), r.u_bar.data(), r.K.data(),
                         r.u_min.empty() ? nullptr : r.u_min.data(), r.u_max.empty() ? nullptr : r.u_max.data()};
  const evaluator::AffinePolicy cxx(kHorizon, c.n, c.m, r.x_bar, r.u_bar, r.K, r.u_min, r.u_max);
  Vector u_c(c.m), u_cxx(c.m);
  for (int s = 0; s < kStates; ++s) {
    const int t = q.t[static_cast<std::size_t>(s)];
    const Vector x = q.x.col(s);
    ASSERT_EQ(gpilqg_policy_control(&cp, t, x.data(), u_c.data()), GPILQG_POLICY_OK);
    ASSERT_EQ(cxx.control(t, x.data(), u_cxx.data()), evaluator::Status::ok);
    EXPECT_TRUE(test::matrices_near(u_c, expected.col(s), 1e-12, 1e-12)) << "C, state " << s;
    EXPECT_TRUE(test::matrices_near(u_cxx, expected.col(s), 1e-12, 1e-12)) << "C++, state " << s;
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, PolicyEvaluator,
                         ::testing::Values(Case{4, 1, true, true}, Case{12, 4, true, true}, Case{3, 2, false, true},
                                           Case{6, 3, false, false}),
                         [](const auto& info) {
                           const Case& c = info.param;
                           return fmt::format("n{}_m{}_{}{}", c.n, c.m, c.lower ? "min" : "", c.upper ? "max" : "");
                         });

TEST(PolicyEvaluatorStatus, OutOfRangeStepsAndNonFiniteStatesLeaveTheControlUntouched) {
  const PolicyFile p = random_policy({2, 1, true, true}, 3);
  const AffinePolicy a = file_policy(p.policy);
  const RowMajorMatrix x_bar = a.x_bar.transpose(), u_bar = a.u_bar.transpose();
  std::vector<double> K;
  for (const Matrix& gain : a.K) {
    const RowMajorMatrix rows = gain;
    K.insert(K.end(), rows.data(), rows.data() + rows.size());
  }
  const gpilqg_policy cp{kHorizon, 2, 1, x_bar.data(), u_bar.data(), K.data(), a.u_min.data(), a.u_max.data()};
  const evaluator::AffinePolicy cxx(kHorizon, 2, 1, {x_bar.data(), x_bar.data() + x_bar.size()},
                                    {u_bar.data(), u_bar.data() + u_bar.size()}, K);
  double u = 42.0;
  const double x[2] = {0.1, 0.2};
  const double nan[2] = {0.1, std::numeric_limits<double>::quiet_NaN()};
  const double inf[2] = {std::numeric_limits<double>::infinity(), 0.0};
  EXPECT_EQ(gpilqg_policy_control(&cp, -1, x, &u), GPILQG_POLICY_TIME_OUT_OF_RANGE);
  EXPECT_EQ(gpilqg_policy_control(&cp, kHorizon, x, &u), GPILQG_POLICY_TIME_OUT_OF_RANGE);
  EXPECT_EQ(gpilqg_policy_control(&cp, 0, nan, &u), GPILQG_POLICY_NON_FINITE_STATE);
  EXPECT_EQ(gpilqg_policy_control(&cp, 0, inf, &u), GPILQG_POLICY_NON_FINITE_STATE);
  EXPECT_EQ(gpilqg_policy_control(nullptr, 0, x, &u), GPILQG_POLICY_BAD_ARGUMENT);
  EXPECT_EQ(gpilqg_policy_control(&cp, 0, x, nullptr), GPILQG_POLICY_BAD_ARGUMENT);
  EXPECT_EQ(cxx.control(kHorizon, x, &u), evaluator::Status::time_out_of_range);
  EXPECT_EQ(cxx.control(0, nan, &u), evaluator::Status::non_finite_state);
  EXPECT_EQ(u, 42.0);
  EXPECT_EQ(gpilqg_policy_control(&cp, kHorizon - 1, x, &u), GPILQG_POLICY_OK);
  EXPECT_NE(u, 42.0);
  EXPECT_THROW(evaluator::AffinePolicy(kHorizon, 2, 1, {1.0}, {}, {}), std::invalid_argument);
}

/// The ```python block after the marker line in docs/real-robot.md.
std::string docs_python_function() {
  std::ifstream in(test::source_dir() / "docs" / "real-robot.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const auto marker = doc.find("<!-- evaluator: python -->");
  EXPECT_NE(marker, std::string::npos) << "docs/real-robot.md has no Python evaluator";
  const auto start = doc.find("```python\n", marker);
  const auto end = doc.find("```", start + 10);
  if (marker == std::string::npos || start == std::string::npos || end == std::string::npos) return "";
  return doc.substr(start + 10, end - start - 10);
}

TEST(PolicyEvaluatorPython, TheDocsFunctionEqualsTheLibraryOnAThousandStates) {
  const std::string function = docs_python_function();
  ASSERT_FALSE(function.empty());
  long lines = std::count(function.begin(), function.end(), '\n');
  EXPECT_LE(lines, 20) << "the docs promise a 20-line function";
  const fs::path python = "/usr/bin/python3";  // the interpreter with h5py and NumPy (scripts/bootstrap.sh)
  if (!fs::exists(python)) GTEST_SKIP() << "no /usr/bin/python3";

  for (const Case& c : {Case{4, 1, true, true}, Case{5, 2, false, true}, Case{3, 2, false, false}}) {
    SCOPED_TRACE(fmt::format("n {} m {}", c.n, c.m));
    const fs::path dir = test::temporary_dir("policy_evaluator_python");
    const PolicyFile policy = random_policy(c, 5u + static_cast<unsigned>(c.n));
    write_policy_file(dir / "policy.h5", policy, nullptr);
    const Queries q = random_queries(policy, 9);
    int clamped = 0;
    const Matrix expected = library_controls(policy, q, clamped);
    {
      std::ofstream states(dir / "states.csv");
      for (int s = 0; s < kStates; ++s) {
        states << q.t[static_cast<std::size_t>(s)];
        for (Eigen::Index i = 0; i < q.x.rows(); ++i) states << fmt::format(",{:.17g}", q.x(i, s));
        states << '\n';
      }
      std::ofstream script(dir / "run.py");
      script << function << R"(
import sys
policy = Policy(sys.argv[1])
rows = np.loadtxt(sys.argv[2], delimiter=",", ndmin=2)
u = np.array([policy(int(r[0]), r[1:]) for r in rows])
np.savetxt(sys.argv[3], u, delimiter=",", fmt="%.17g")
)";
    }
    const std::string command = fmt::format("{} '{}' '{}' '{}' '{}' 2> '{}'", python.string(), (dir / "run.py").string(),
                                            (dir / "policy.h5").string(), (dir / "states.csv").string(),
                                            (dir / "controls.csv").string(), (dir / "python.err").string());
    ASSERT_EQ(std::system(command.c_str()), 0) << std::ifstream(dir / "python.err").rdbuf();
    const Matrix u = test::read_numeric_csv(dir / "controls.csv");
    ASSERT_EQ(u.rows(), kStates);
    ASSERT_EQ(u.cols(), c.m);
    EXPECT_TRUE(test::matrices_near(u.transpose(), expected, 1e-12, 1e-12));
  }
}

}  // namespace
}  // namespace gpilqg
