#pragma once
/// @file test_support.hpp
/// Shared helpers for the test suites: one matrix-compare assertion, reference-file paths, CSV
/// loading of reference numbers, and central-difference checks of analytic derivatives.

#include <filesystem>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg::test {

/// tests/reference: independent reference numbers, each folder with a README of its provenance.
std::filesystem::path reference_dir();
/// data/: sample measurement sets and the GP benchmark sets.
std::filesystem::path data_dir();
/// The repository root.
std::filesystem::path source_dir();
/// A fresh empty temporary folder for one test, <tmp>/gpilqg_tests/<pid>/<label>_<suite>_<test>: left
/// for inspection, removed by the first test of a later process once this one has ended.
std::filesystem::path temporary_dir(const std::string& label);

/// Reads a headerless numeric CSV (as in tests/reference) into a matrix.
Matrix read_numeric_csv(const std::filesystem::path& file);

/// Passes when |actual - expected| <= abs_tol + rel_tol * |expected| elementwise and the shapes agree;
/// the failure message shows the worst entry and both matrices.
::testing::AssertionResult matrices_near(const Matrix& actual, const Matrix& expected, double abs_tol,
                                         double rel_tol = 0.0);

/// Central-difference Jacobian of g at x with absolute step h (a test-side twin, independent of the
/// library's finite_difference.hpp so the two check each other).
Matrix numeric_jacobian(const std::function<Vector(const Vector&)>& g, const Vector& x, double h);

/// Step and tolerance of the central-difference checks of analytic derivatives. With h = 1e-6 the
/// truncation error ~ h^2 |f'''| / 6 and the round-off ~ eps |f| / h stay below 1e-8 for |f|, |f'''|
/// up to ~100: a tolerance of 1e-7 leaves a margin of 10 and still catches any wrong term (those are
/// O(0.01) or larger).
inline constexpr double kFdStep = 1e-6;
inline constexpr double kFdTolerance = 1e-7;

/// The built-in cart-pole's signature (its states, controls and measurement names).
const SystemSignature& cartpole_signature();

/// Random vector with entries uniform in [lo, hi], from a fixed-seed generator per call site.
Vector random_vector(int size, double lo, double hi, unsigned seed);

/// Options of `gpilqg diagnose` that keep a test of it fast: a small GP without restarts.
inline const std::string kFastDiagnose = " --gp-points 100 --gp-restarts 0";

/// The gpilqg program, for a test that runs it. Such a test belongs to a test suite whose name ends in
/// `Cli`: tests/CMakeLists.txt labels those tests `cli` by that name (docs/testing.md says what runs
/// where). A test of another suite that asks for the program fails, naming the rule.
std::string program_path();

/// Runs the gpilqg program with `arguments` (shell-quoted by the caller), capturing stdout and
/// stderr separately; returns the exit status.
struct CommandResult {
  int status = -1;
  std::string out;
  std::string err;
};
CommandResult run_cli(const std::string& arguments);

/// `path` in single quotes, for the arguments of run_cli (the tests' paths hold no quote).
std::string quote(const std::filesystem::path& path);

/// Writes `text` to `file` byte for byte (creating its folder) and returns `file`.
std::filesystem::path write_text(const std::filesystem::path& file, const std::string& text);

/// The bytes of `file` ("" when it cannot be read).
std::string read_text(const std::filesystem::path& file);

}  // namespace gpilqg::test

#define EXPECT_MATRIX_NEAR(actual, expected, abs_tol) \
  EXPECT_TRUE(::gpilqg::test::matrices_near((actual), (expected), (abs_tol)))
