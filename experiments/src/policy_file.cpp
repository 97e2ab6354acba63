#include "gpilqg/experiments/policy_file.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/gp_io.hpp"

namespace gpilqg {
namespace {

constexpr const char* kPolicy = "/policy";
constexpr const char* kModel = "/model";

std::vector<double> as_list(const VectorCRef& v) { return {v.data(), v.data() + v.size()}; }
Vector as_vector(const std::vector<double>& v) { return Eigen::Map<const Vector>(v.data(), static_cast<Eigen::Index>(v.size())); }

void check_shapes(const PolicyFile& p) {
  const AffinePolicy& a = p.policy;
  const Eigen::Index n = static_cast<Eigen::Index>(p.state_names.size());
  const Eigen::Index m = static_cast<Eigen::Index>(p.control_names.size());
  const int T = a.horizon();
  const auto fail = [](const std::string& what) { throw std::invalid_argument("policy file: " + what); };
  if (T < 1) fail("the horizon must be >= 1");
  if (a.x_bar.rows() != n || a.x_bar.cols() != T + 1) fail("x_bar is not n x (T+1)");
  if (a.u_bar.rows() != m) fail("u_bar is not m x T");
  if (static_cast<int>(a.K.size()) != T) fail("K does not have T gains");
  for (const Matrix& gain : a.K)
    if (gain.rows() != m || gain.cols() != n || !gain.allFinite()) fail("a gain is not a finite m x n matrix");
  if (!a.x_bar.allFinite() || !a.u_bar.allFinite()) fail("x_bar or u_bar has non-finite entries");
  if ((a.u_min.size() && a.u_min.size() != m) || (a.u_max.size() && a.u_max.size() != m)) fail("a limit is not of size m");
  if (!(p.dt > 0.0) || !std::isfinite(p.dt)) fail("dt must be finite and > 0");
  if (!std::isfinite(p.predicted_cost) || !std::isfinite(p.expected_cost)) fail("the costs must be finite");
}

/// The checks of the values a policy file holds, each failing with an InputError naming the file
/// and the attribute or dataset: a controller runs these numbers on a robot, so a NaN, an infinite
/// gain or inverted limits are refused on reading rather than discovered at the first step.
class PolicyValues {
 public:
  explicit PolicyValues(const std::filesystem::path& file) : file_(file) {}

  [[noreturn]] void fail(const std::string& object, const std::string& problem) const {
    throw InputError(fmt::format("{}: {} '{}': {}", file_.string(), object.find('@') == std::string::npos ? "dataset" : "attribute",
                                 object, problem));
  }

  /// Every entry of a list finite; the first that is not is named with its index.
  void finite(const std::string& object, const Vector& values) const {
    for (Eigen::Index i = 0; i < values.size(); ++i)
      if (!std::isfinite(values(i))) fail(object, fmt::format("entry {} is {}; expected finite numbers", i, values(i)));
  }

  /// Every entry of a dataset stored transposed (x_bar, u_bar: one row per step) finite; the first
  /// that is not is named by its [row, column] in the file.
  void finite_rows(const std::string& object, const Matrix& columns) const {
    for (Eigen::Index t = 0; t < columns.cols(); ++t)
      for (Eigen::Index i = 0; i < columns.rows(); ++i)
        if (!std::isfinite(columns(i, t)))
          fail(object, fmt::format("entry [{}, {}] is {}; expected finite numbers", t, i, columns(i, t)));
  }

  void check(const PolicyFile& p) const {
    const AffinePolicy& a = p.policy;
    if (p.system.empty()) fail("/policy@system", "is empty; expected the name of the planned system");
    if (p.state_names.empty()) fail("/policy@state_names", "is empty; expected one name per state");
    if (p.control_names.empty()) fail("/policy@control_names", "is empty; expected one name per control");
    if (!(std::isfinite(p.dt) && p.dt > 0.0)) fail("/policy@dt", fmt::format("is {}; expected a finite number > 0", p.dt));
    for (const auto& [name, value] : {std::pair{"predicted_cost", p.predicted_cost}, std::pair{"expected_cost", p.expected_cost}})
      if (!std::isfinite(value)) fail(fmt::format("/policy@{}", name), fmt::format("is {}; expected a finite number", value));
    finite_rows("/policy/x_bar", a.x_bar);
    finite_rows("/policy/u_bar", a.u_bar);
    for (std::size_t t = 0; t < a.K.size(); ++t)
      for (Eigen::Index r = 0; r < a.K[t].rows(); ++r)
        for (Eigen::Index c = 0; c < a.K[t].cols(); ++c)
          if (!std::isfinite(a.K[t](r, c)))
            fail("/policy/K", fmt::format("entry [{}, {}, {}] is {}; expected finite numbers", t, r, c, a.K[t](r, c)));
    finite("/policy@u_min", a.u_min);
    finite("/policy@u_max", a.u_max);
    if (a.u_min.size() && a.u_max.size())
      for (Eigen::Index i = 0; i < a.u_min.size(); ++i)
        if (!(a.u_min(i) <= a.u_max(i)))
          fail("/policy@u_min", fmt::format("entry {} is {}, above u_max's {}; expected u_min <= u_max", i, a.u_min(i), a.u_max(i)));
  }

 private:
  const std::filesystem::path& file_;
};

/// Whether the system a policy was planned for is `asked`: the same name, or two model files of the
/// same file name. A policy names its model file by the path the planner used (relative to the plan
/// config's folder); the controller may load the same model from another folder or machine, and
/// the state and control names, checked by each caller, must match as well.
bool same_planned_system(const std::string& planned, const std::string& asked) {
  if (planned == asked) return true;
  return is_model_file_name(planned) && is_model_file_name(asked) &&
         std::filesystem::path(planned).filename() == std::filesystem::path(asked).filename();
}

}  // namespace

AffinePolicy file_policy(const AffinePolicy& policy) {
  AffinePolicy out = policy;
  if (out.k.size()) out.u_bar += out.k;
  out.k = Matrix::Zero(out.u_bar.rows(), out.u_bar.cols());
  return out;
}

void write_policy_file(const std::filesystem::path& file, const PolicyFile& p, const gp::ResidualModel* model) {
  check_shapes(p);
  const AffinePolicy a = file_policy(p.policy);
  const int T = a.horizon();
  const auto n = static_cast<std::uint64_t>(a.x_bar.rows()), m = static_cast<std::uint64_t>(a.u_bar.rows());
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    {
      Hdf5Writer h5(temporary);
      h5.write_matrix(std::string(kPolicy) + "/x_bar", a.x_bar.transpose());
      h5.write_matrix(std::string(kPolicy) + "/u_bar", a.u_bar.transpose());
      std::vector<double> gains;
      gains.reserve(static_cast<std::size_t>(T) * m * n);
      for (const Matrix& gain : a.K) {
        const RowMajorMatrix rows = gain;
        gains.insert(gains.end(), rows.data(), rows.data() + rows.size());
      }
      h5.write_array(std::string(kPolicy) + "/K", {static_cast<std::uint64_t>(T), m, n}, gains);
      h5.attribute(kPolicy, "dt", p.dt);
      h5.attribute(kPolicy, "horizon", static_cast<std::int64_t>(T));
      h5.attribute(kPolicy, "system", p.system);
      h5.attribute(kPolicy, "state_names", p.state_names);
      h5.attribute(kPolicy, "control_names", p.control_names);
      if (a.u_min.size()) h5.attribute(kPolicy, "u_min", as_list(a.u_min));
      if (a.u_max.size()) h5.attribute(kPolicy, "u_max", as_list(a.u_max));
      h5.attribute(kPolicy, "predicted_cost", p.predicted_cost);
      h5.attribute(kPolicy, "expected_cost", p.expected_cost);
      h5.attribute(kPolicy, "round", static_cast<std::int64_t>(p.round));
      h5.attribute(kPolicy, "data_files", p.data_files);
      h5.attribute(kPolicy, "created", p.created.empty() ? utc_timestamp() : p.created);
      h5.attribute(kPolicy, "gpilqg_version", p.gpilqg_version);
      if (!p.simulator_model.empty()) h5.attribute(kPolicy, "simulator_model", p.simulator_model);
      h5.close();
    }
    if (model != nullptr) gp::save_residual_model(temporary, kModel, *model);
  });
}

PolicyFile read_policy_file(const std::filesystem::path& file) {
  check_input_file_as<InputError>(file, kMaxDataFileBytes, "a policy file of `gpilqg plan`");
  return as_input_error(file, [&] {
    const Hdf5Reader h5(file);
    const std::string g = kPolicy;
    for (const char* dataset : {"x_bar", "u_bar", "K"})
      if (!h5.exists(g + "/" + dataset))
        throw InputError(fmt::format("{}: dataset '{}/{}' is missing; expected a policy file of `gpilqg plan`",
                                     file.string(), g, dataset));
    PolicyFile p;
    p.dt = h5.number_attribute(g, "dt");
    const double horizon = h5.number_attribute(g, "horizon");
    p.system = h5.string_attribute(g, "system");
    p.state_names = h5.string_list_attribute(g, "state_names");
    p.control_names = h5.string_list_attribute(g, "control_names");
    p.predicted_cost = h5.number_attribute(g, "predicted_cost");
    p.expected_cost = h5.number_attribute(g, "expected_cost");
    const double round = h5.number_attribute(g, "round");
    if (!(round >= 0.0 && round <= 1e6) || std::floor(round) != round)
      throw InputError(fmt::format("{}: attribute '{}@round' is {}; expected a whole number in [0, 1000000]", file.string(), g, round));
    p.round = static_cast<int>(round);
    p.data_files = h5.has_attribute(g, "data_files") ? h5.string_list_attribute(g, "data_files") : std::vector<std::string>{};
    p.created = h5.string_attribute(g, "created");
    p.gpilqg_version = h5.string_attribute(g, "gpilqg_version");
    if (h5.has_attribute(g, "simulator_model")) p.simulator_model = h5.string_attribute(g, "simulator_model");
    const auto n = static_cast<std::uint64_t>(p.state_names.size()), m = static_cast<std::uint64_t>(p.control_names.size());
    const auto T = static_cast<std::uint64_t>(horizon);
    const auto expect = [&](const std::string& name, std::vector<std::uint64_t> dims, const char* shape) {
      if (h5.shape(g + "/" + name) != dims)
        throw InputError(fmt::format("{}: dataset '{}/{}' has the wrong shape; expected {} = {}", file.string(), g, name,
                                     shape, fmt::join(dims, " x ")));
    };
    if (horizon < 1 || horizon != static_cast<double>(T))
      throw InputError(fmt::format("{}: attribute '{}@horizon' is {}; expected a whole number >= 1", file.string(), g, horizon));
    expect("x_bar", {T + 1, n}, "(T+1) x n");
    expect("u_bar", {T, m}, "T x m");
    expect("K", {T, m, n}, "T x m x n");
    p.policy.x_bar = h5.read_matrix(g + "/x_bar").transpose();
    p.policy.u_bar = h5.read_matrix(g + "/u_bar").transpose();
    const std::vector<double> gains = h5.read_array(g + "/K");
    for (std::uint64_t t = 0; t < T; ++t)
      p.policy.K.push_back(Eigen::Map<const RowMajorMatrix>(gains.data() + t * m * n, static_cast<Eigen::Index>(m),
                                                            static_cast<Eigen::Index>(n)));
    p.policy.k = Matrix::Zero(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(T));
    for (const char* limit : {"u_min", "u_max"}) {
      if (!h5.has_attribute(g, limit)) continue;
      const std::vector<double> values = h5.number_list_attribute(g, limit);
      if (values.size() != m)
        throw InputError(fmt::format("{}: attribute '{}@{}' has {} entries; expected one per control ({})", file.string(),
                                     g, limit, values.size(), m));
      (std::string(limit) == "u_min" ? p.policy.u_min : p.policy.u_max) = as_vector(values);
    }
    PolicyValues(file).check(p);
    if (h5.exists(std::string(kModel) + "/0")) p.model_backend = h5.string_attribute(std::string(kModel) + "/0", "backend");
    try {
      check_shapes(p);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: {}", file.string(), e.what()));
    }
    return p;
  });
}

void check_policy_system(const PolicyFile& policy, const std::filesystem::path& file, const std::string& system) {
  if (!same_planned_system(policy.system, system))
    throw InputError(fmt::format("{}: attribute '/policy@system' is '{}'; expected '{}', the system it is used for",
                                 file.string(), policy.system, system));
}

std::shared_ptr<const gp::ResidualModel> read_policy_model(const std::filesystem::path& file,
                                                           std::shared_ptr<const StepModel> simulator,
                                                           const gp::BackendSettings& settings) {
  const PolicyFile p = read_policy_file(file);
  if (p.model_backend.empty())
    throw InputError(file.string() + ": group '/model' is missing; expected the fitted GP of a plan with data");
  return as_input_error(file, [&] {
    const auto backend = gp::make_backend(p.model_backend, settings);
    return std::make_shared<const gp::ResidualModel>(
        gp::load_residual_model(file, kModel, std::move(simulator), *backend));
  });
}

nlohmann::json policy_json(const PolicyFile& p, const gp::ResidualModel* model) {
  const AffinePolicy a = file_policy(p.policy);
  nlohmann::json policy;
  const auto rows = [](const Matrix& columns) {  // one list per column of `columns` (per time step)
    nlohmann::json out = nlohmann::json::array();
    for (Eigen::Index t = 0; t < columns.cols(); ++t) out.push_back(as_list(columns.col(t)));
    return out;
  };
  policy["x_bar"] = rows(a.x_bar);
  policy["u_bar"] = rows(a.u_bar);
  nlohmann::json gains = nlohmann::json::array();
  for (const Matrix& gain : a.K) gains.push_back(rows(gain.transpose()));
  policy["K"] = gains;
  policy["dt"] = p.dt;
  policy["horizon"] = a.horizon();
  policy["system"] = p.system;
  policy["state_names"] = p.state_names;
  policy["control_names"] = p.control_names;
  if (a.u_min.size()) policy["u_min"] = as_list(a.u_min);
  if (a.u_max.size()) policy["u_max"] = as_list(a.u_max);
  policy["predicted_cost"] = p.predicted_cost;
  policy["expected_cost"] = p.expected_cost;
  policy["round"] = p.round;
  policy["data_files"] = p.data_files;
  policy["created"] = p.created;
  policy["gpilqg_version"] = p.gpilqg_version;
  nlohmann::json out;
  out["policy"] = policy;
  out["model"] = nullptr;
  if (model != nullptr) {
    nlohmann::json m;
    m["backend"] = std::string(model->output(0).backend_name());
    m["points"] = model->output(0).training_set().size();
    nlohmann::json hyper = nlohmann::json::array();
    for (int i = 0; i < model->state_dim(); ++i) hyper.push_back(as_list(model->output(i).parameters()));
    m["hyperparameters"] = hyper;
    out["model"] = m;
  }
  return out;
}

}  // namespace gpilqg
