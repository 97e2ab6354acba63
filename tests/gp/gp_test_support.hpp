#pragma once
/// @file gp_test_support.hpp
/// Shared pieces of the GP tests: the gp_oracle reference data (tests/reference/gp_oracle) and its
/// prior mean m(x) = sum_d sin(x_d), the JSON golden numbers, and the list of backends for typed tests.

#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/compact.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "gpilqg/gp/prior_mean.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::test {

using ::gpilqg::test::matrices_near;
using ::gpilqg::test::read_numeric_csv;
using ::gpilqg::test::data_dir;
using ::gpilqg::test::reference_dir;

inline std::filesystem::path oracle_dir() { return reference_dir() / "gp_oracle"; }

/// The oracle's stand-in simulator: m(x) = sum_d sin(x_d), dm/dx_d = cos(x_d).
inline double sum_of_sines(const VectorCRef& x, Vector* gradient) {
  if (gradient != nullptr) *gradient = x.array().cos().matrix();
  return x.array().sin().sum();
}

/// The oracle's data with the prior mean subtracted from the targets (README: "Every GP here models
/// y - m(X)").
struct OracleData {
  TrainingSet train;      ///< X.csv, y.csv - m(X)
  Matrix test_inputs;     ///< Xs.csv
  Hyperparameters hyp;    ///< hyp.csv
  TrainingSet fit;        ///< Xfit.csv, yfit.csv - m(Xfit)
};

inline OracleData load_oracle() {
  const auto dir = oracle_dir() / "data";
  OracleData o;
  TrainingSet raw{read_numeric_csv(dir / "X.csv"), read_numeric_csv(dir / "y.csv").col(0)};
  o.train = subtract_prior_mean(raw, &sum_of_sines);
  o.test_inputs = read_numeric_csv(dir / "Xs.csv");
  const Vector hyp = read_numeric_csv(dir / "hyp.csv").row(0).transpose();
  o.hyp = Hyperparameters::unpack(hyp, static_cast<int>(hyp.size()) - 2);
  TrainingSet raw_fit{read_numeric_csv(dir / "Xfit.csv"), read_numeric_csv(dir / "yfit.csv").col(0)};
  o.fit = subtract_prior_mean(raw_fit, &sum_of_sines);
  return o;
}

inline nlohmann::json load_oracle_json(const std::string& name) {
  std::ifstream in(oracle_dir() / "results" / (name + ".json"));
  if (!in) throw std::runtime_error("cannot open oracle results " + name + ".json");
  return nlohmann::json::parse(in);
}

/// A JSON array of numbers (or of arrays of numbers: rows) as a matrix.
inline Matrix json_matrix(const nlohmann::json& value) {
  if (!value.is_array() || value.empty()) throw std::runtime_error("expected a non-empty JSON array");
  if (!value.front().is_array()) {
    Matrix m(static_cast<Eigen::Index>(value.size()), 1);
    for (std::size_t i = 0; i < value.size(); ++i) m(static_cast<Eigen::Index>(i), 0) = value[i].get<double>();
    return m;
  }
  Matrix m(static_cast<Eigen::Index>(value.size()), static_cast<Eigen::Index>(value.front().size()));
  for (std::size_t i = 0; i < value.size(); ++i)
    for (std::size_t j = 0; j < value[i].size(); ++j)
      m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = value[i][j].get<double>();
  return m;
}

// ---------------------------------------------------------------------------------------------------
// Backends for typed tests: one struct per backend (`make()`, its gradient tolerance and whether its
// variance reverts to the prior) and one entry in BackendCases. The backend extras (pseudo-inputs,
// frequencies) come from the objective's data-driven initial values (parameters_for).

struct ExactCase {
  static constexpr const char* name = "exact";
  static std::unique_ptr<GpBackend> make() { return std::make_unique<ExactGpBackend>(); }
  /// Relative tolerance of the NLML gradient against central differences.
  static constexpr double gradient_tolerance = 1e-6;
  /// Whether the variance returns to sf^2 far from the data (FITC and exact: yes; SSGP: no).
  static constexpr bool reverts_to_prior = true;
};

/// FITC with 7 pseudo-inputs (as the oracle; with M >= N they would sit on the training inputs).
struct FitcCase {
  static constexpr const char* name = "fitc";
  static std::unique_ptr<GpBackend> make() {
    FitcOptions options;
    options.inducing = 7;
    return std::make_unique<FitcBackend>(options);
  }
  static constexpr double gradient_tolerance = 1e-6;
  static constexpr bool reverts_to_prior = true;
};

/// SSGP with 10 spectral points (as the oracle).
struct SsgpCase {
  static constexpr const char* name = "ssgp";
  static std::unique_ptr<GpBackend> make() {
    SsgpOptions options;
    options.frequencies = 10;
    return std::make_unique<SsgpBackend>(options);
  }
  static constexpr double gradient_tolerance = 1e-6;
  static constexpr bool reverts_to_prior = false;
};

/// Exact GP with Wendland's compactly supported kernel (CHOLMOD). With the oracle's length-scales as
/// support radii, K(X, X) on its 20 points is sparse but not diagonal.
struct CompactCase {
  static constexpr const char* name = "compact";
  static std::unique_ptr<GpBackend> make() { return std::make_unique<CompactBackend>(); }
  static constexpr double gradient_tolerance = 1e-6;
  static constexpr bool reverts_to_prior = true;
};

using BackendCases = ::testing::Types<ExactCase, FitcCase, SsgpCase, CompactCase>;

/// The backend's full parameter vector for `data` with the shared part set to `hyp` and the extras
/// (pseudo-inputs, frequencies) at the objective's data-driven initial values.
inline Vector parameters_for(const GpBackend& backend, const TrainingSet& data, const Hyperparameters& hyp) {
  auto objective = backend.objective(data, FitOptions{});
  Vector theta = objective->initial_parameters();
  theta.head(Hyperparameters::count(hyp.input_dim())) = hyp.pack();
  return theta;
}

/// |a - e| <= tol * (|e| + max|e|): relative to each entry and to the largest one.
inline ::testing::AssertionResult near_relative(const Matrix& actual, const Matrix& expected, double tol) {
  return matrices_near(actual, expected, tol * expected.cwiseAbs().maxCoeff(), tol);
}

/// The 1 x 1 matrix holding v.
inline Matrix scalar(double v) { return Matrix::Constant(1, 1, v); }

/// Analytic against central-difference gradient: each entry within 1e-6 relative plus 1e-7 of the
/// largest entry (the differences' rounding error scales with the NLML's magnitude).
inline ::testing::AssertionResult gradient_near(const Vector& analytic, const Vector& numeric) {
  return matrices_near(analytic, numeric, 1e-7 * numeric.cwiseAbs().maxCoeff(), 1e-6);
}

/// Central-difference gradient of a sparse GP's NLML (FitcLikelihood, SsgpLikelihood) at theta.
template <class Likelihood>
Vector numeric_gradient(const Likelihood& lik, const Vector& theta, double h = 1e-5) {
  return ::gpilqg::test::numeric_jacobian(
             [&](const Vector& t) { return Vector::Constant(1, lik.evaluate(t).value); }, theta, h)
      .transpose();
}

/// Predictions at test points, one row of the gradients per point.
struct Predictions {
  Vector mean, variance;
  Matrix dmean, dvariance;
};

}  // namespace gpilqg::gp::test
