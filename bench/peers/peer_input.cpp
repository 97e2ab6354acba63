#include "peer_input.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::bench {

namespace {

/// "FILE:/DATASET: what", the command line's form of a bad-input message.
[[noreturn]] void fail(const Hdf5Reader& reader, const std::string& object, const std::string& what) {
  throw std::runtime_error(reader.file().string() + ":" + object + ": " + what);
}

void require_finite(const Hdf5Reader& reader, const std::string& path, const Eigen::Ref<const Matrix>& values) {
  for (Eigen::Index j = 0; j < values.cols(); ++j)
    for (Eigen::Index i = 0; i < values.rows(); ++i)
      if (!std::isfinite(values(i, j)))
        fail(reader, path, "entry (" + std::to_string(i) + ", " + std::to_string(j) + ") is not finite");
}

void require_dataset(const Hdf5Reader& reader, const std::string& path, const std::string& what) {
  if (!reader.exists(path)) fail(reader, path, "missing; expected " + what + " (bench/peers/peer_input.hpp)");
}

Matrix read_points(const Hdf5Reader& reader, const std::string& path, Eigen::Index columns) {
  require_dataset(reader, path, "a points x inputs matrix");
  if (reader.shape(path).size() != 2) fail(reader, path, "expected a 2-D dataset (points x inputs)");
  Matrix points = reader.read_matrix(path);
  if (columns > 0 && points.cols() != columns)
    fail(reader, path, "has " + std::to_string(points.cols()) + " columns; expected D = " + std::to_string(columns));
  if (points.rows() == 0 || points.cols() == 0) fail(reader, path, "is empty");
  require_finite(reader, path, points);
  return points;
}

Vector read_values(const Hdf5Reader& reader, const std::string& path, Eigen::Index size, const std::string& expected) {
  require_dataset(reader, path, "a 1-D dataset");
  if (reader.shape(path).size() != 1) fail(reader, path, "expected a 1-D dataset");
  Vector values = reader.read_vector(path);
  if (size >= 0 && values.size() != size)
    fail(reader, path, "has " + std::to_string(values.size()) + " entries; expected " + expected);
  require_finite(reader, path, values);
  return values;
}

gp::TrainingSet read_training_set(const Hdf5Reader& reader, const std::string& group, Eigen::Index columns) {
  gp::TrainingSet data;
  data.inputs = read_points(reader, group + "/X", columns);
  data.targets = read_values(reader, group + "/y", data.inputs.rows(),
                             "one per row of " + group + "/X (" + std::to_string(data.inputs.rows()) + ")");
  return data;
}

std::string number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

/// A size attribute: a whole number in [D, rows].
int read_size(const Hdf5Reader& reader, const std::string& name, double value, int input_dim, int rows) {
  if (!(value == std::floor(value)) || value < input_dim || value > rows)
    fail(reader, "/", "attribute " + name + " = " + number(value) + "; expected a whole number of rows in [" +
                          std::to_string(input_dim) + ", " + std::to_string(rows) + "] (the rows of /exact/X)");
  return static_cast<int>(value);
}

}  // namespace

PeerInput read_peer_input(const std::filesystem::path& file) {
  const Hdf5Reader reader(file);
  PeerInput in;
  in.exact = read_training_set(reader, "/exact", 0);
  const int d = in.exact.input_dim();
  const int rows = in.exact.size();
  in.exact_theta = read_values(reader, "/exact/theta", gp::Hyperparameters::count(d),
                               "D + 2 = " + std::to_string(d + 2) + " (log l, log sf, log sn)");
  in.test_points = read_points(reader, "/exact/X_test", d);

  in.fitc = read_training_set(reader, "/fitc", d);
  in.fitc_theta = read_values(reader, "/fitc/theta", -1, "");
  try {
    in.fitc_inducing = gp::FitcLayout::from_size(static_cast<int>(in.fitc_theta.size()), d).inducing;
  } catch (const std::invalid_argument& e) {
    fail(reader, "/fitc/theta", std::string("expected D + 2 + M D entries: ") + e.what());
  }

  for (const char* name : {"nlml_sizes", "fit_size", "fit_sizes", "predict_size"})
    if (!reader.has_attribute("/", name))
      fail(reader, "/", std::string("attribute ") + name + " is missing (bench/peers/peer_input.hpp)");
  for (const double n : reader.number_list_attribute("/", "nlml_sizes"))
    in.nlml_sizes.push_back(read_size(reader, "nlml_sizes", n, d, rows));
  if (in.nlml_sizes.empty()) fail(reader, "/", "attribute nlml_sizes is empty; expected at least one N");
  in.fit_size = read_size(reader, "fit_size", reader.number_attribute("/", "fit_size"), d, rows);
  for (const double n : reader.number_list_attribute("/", "fit_sizes"))
    in.fit_sizes.push_back(read_size(reader, "fit_sizes", n, d, rows));
  in.predict_size = read_size(reader, "predict_size", reader.number_attribute("/", "predict_size"), d, rows);
  return in;
}

}  // namespace gpilqg::bench
