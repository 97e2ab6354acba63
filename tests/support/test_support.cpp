#include "test_support.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "gpilqg/core/systems.hpp"

namespace gpilqg::test {

std::filesystem::path reference_dir() { return source_dir() / "tests" / "reference"; }
std::filesystem::path data_dir() { return source_dir() / "data"; }
std::filesystem::path source_dir() { return GPILQG_SOURCE_DIR; }

std::filesystem::path temporary_dir(const std::string& label) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = label;
  if (info != nullptr) name += std::string("_") + info->test_suite_name() + "_" + info->name();
  for (char& c : name)
    if (c == '/') c = '_';
  // One folder per test process, so that test programs running at the same time (ctest -j, two
  // builds on one machine) never write into each other's files; folders of processes that no longer
  // run are removed the first time.
  const auto root = std::filesystem::temp_directory_path() / "gpilqg_tests";
  static const bool cleaned = [&root] {
    std::error_code ignored;
    for (const auto& entry : std::filesystem::directory_iterator(root, ignored)) {
      const std::string pid = entry.path().filename().string();
      if (pid.find_first_not_of("0123456789") == std::string::npos && !std::filesystem::exists("/proc/" + pid))
        std::filesystem::remove_all(entry.path(), ignored);
    }
    return true;
  }();
  static_cast<void>(cleaned);
  auto dir = root / std::to_string(::getpid()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

Matrix read_numeric_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open reference file " + file.string());
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) row.push_back(std::stod(field));
    rows.push_back(std::move(row));
  }
  if (rows.empty()) throw std::runtime_error("empty reference file " + file.string());
  Matrix m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows[0].size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != rows[0].size())
      throw std::runtime_error("ragged reference file " + file.string());
    for (std::size_t j = 0; j < rows[i].size(); ++j)
      m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = rows[i][j];
  }
  return m;
}

::testing::AssertionResult matrices_near(const Matrix& actual, const Matrix& expected, double abs_tol,
                                         double rel_tol) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols())
    return ::testing::AssertionFailure() << "shape " << actual.rows() << "x" << actual.cols()
                                         << " differs from expected " << expected.rows() << "x"
                                         << expected.cols();
  double worst = -1.0;
  Eigen::Index wi = 0, wj = 0;
  for (Eigen::Index i = 0; i < actual.rows(); ++i)
    for (Eigen::Index j = 0; j < actual.cols(); ++j) {
      const double excess = std::abs(actual(i, j) - expected(i, j)) -
                            (abs_tol + rel_tol * std::abs(expected(i, j)));
      if (!(excess <= 0.0) && (worst < 0.0 || !(excess <= worst))) {
        worst = std::isnan(excess) ? std::numeric_limits<double>::infinity() : excess;
        wi = i;
        wj = j;
      }
    }
  if (worst < 0.0) return ::testing::AssertionSuccess();
  Eigen::IOFormat fmt(Eigen::FullPrecision, 0, ", ", "\n", "[", "]");
  return ::testing::AssertionFailure()
         << "entry (" << wi << ", " << wj << "): actual " << actual(wi, wj) << " vs expected "
         << expected(wi, wj) << ", difference " << std::abs(actual(wi, wj) - expected(wi, wj))
         << " > tolerance " << abs_tol << " + " << rel_tol << " * |expected|\nactual:\n"
         << actual.format(fmt) << "\nexpected:\n"
         << expected.format(fmt);
}

Matrix numeric_jacobian(const std::function<Vector(const Vector&)>& g, const Vector& x, double h) {
  const Vector g0 = g(x);
  Matrix J(g0.size(), x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    Vector xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    J.col(j) = (g(xp) - g(xm)) / (2.0 * h);
  }
  return J;
}

Vector random_vector(int size, double lo, double hi, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> dist(lo, hi);
  Vector v(size);
  for (int i = 0; i < size; ++i) v(i) = dist(gen);
  return v;
}

namespace {
std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

std::string program_path() {
  if (const auto* test = ::testing::UnitTest::GetInstance()->current_test_info()) {
    const std::string_view suite = test->test_suite_name();
    const std::string_view bare = suite.substr(suite.find('/') + 1);  // "Prefix/Suite" of a parametrised test
    if (!bare.ends_with("Cli"))
      ADD_FAILURE() << suite << "." << test->name() << " runs the gpilqg program, so its test suite's name must "
                    << "end in Cli (the ctest label cli, tests/CMakeLists.txt)";
  }
  if (!std::filesystem::exists(GPILQG_CLI_PATH))
    ADD_FAILURE() << GPILQG_CLI_PATH << " does not exist: the tests labelled cli run the gpilqg program, which the "
                  << "default target builds (cmake --build <build folder>)";
  return GPILQG_CLI_PATH;
}

CommandResult run_cli(const std::string& arguments) {
  const auto dir = temporary_dir("cli");
  const auto out = dir / "stdout.txt";
  const auto err = dir / "stderr.txt";
  const std::string command = "'" + program_path() + "' " + arguments + " >'" +
                              out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int raw = std::system(command.c_str());
  CommandResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = read_file(out);
  result.err = read_file(err);
  return result;
}

const SystemSignature& cartpole_signature() {
  static const SystemSignature signature = system_signature("cartpole");
  return signature;
}

std::string quote(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

std::filesystem::path write_text(const std::filesystem::path& file, const std::string& text) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << text;
  return file;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace gpilqg::test
