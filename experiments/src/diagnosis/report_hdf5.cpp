#include "gpilqg/experiments/diagnosis/report_hdf5.hpp"

#include <H5Cpp.h>

#include <chrono>
#include <ctime>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"

namespace gpilqg::diagnosis {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void write_string_attribute(H5::H5Object& object, const std::string& name, const std::string& value) {
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  const char* data = value.c_str();
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, &data);
}

void write_int_attribute(H5::H5Object& object, const std::string& name, long value) {
  object.createAttribute(name, H5::PredType::NATIVE_LONG, H5::DataSpace(H5S_SCALAR)).write(H5::PredType::NATIVE_LONG, &value);
}

void write_strings(H5::Group& group, const std::string& name, const std::vector<std::string>& values, bool attribute) {
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  std::vector<const char*> data;
  for (const auto& v : values) data.push_back(v.c_str());
  const hsize_t dims[1] = {values.size()};
  const H5::DataSpace space(1, dims);
  if (values.empty()) return;
  if (attribute)
    group.createAttribute(name, type, space).write(type, data.data());
  else
    group.createDataSet(name, type, space).write(data.data(), type);
}

/// Any shape as float64 in row-major order; `dims` gives the shape.
void write_array(H5::Group& group, const std::string& name, const double* data, std::vector<hsize_t> dims) {
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  group.createDataSet(name, H5::PredType::IEEE_F64LE, space).write(data, H5::PredType::NATIVE_DOUBLE);
}

void write_matrix(H5::Group& group, const std::string& name, const MatrixCRef& m) {
  const RowMajor rows = m;
  write_array(group, name, rows.data(), {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())});
}

void write_vector(H5::Group& group, const std::string& name, const VectorCRef& v) {
  const Vector copy = v;
  write_array(group, name, copy.data(), {static_cast<hsize_t>(v.size())});
}

template <class Int>
void write_ints(H5::Group& group, const std::string& name, const std::vector<Int>& values) {
  std::vector<long> data(values.begin(), values.end());
  const hsize_t dims[1] = {data.size()};
  group.createDataSet(name, H5::PredType::STD_I64LE, H5::DataSpace(1, dims)).write(data.data(), H5::PredType::NATIVE_LONG);
}

void write_data(H5::Group root, const DiagnosisReport& r) {
  H5::Group data = root.createGroup("data");
  write_matrix(data, "x", r.data.x);
  write_matrix(data, "u", r.data.u);
  write_matrix(data, "x_next", r.data.x_next);
  write_vector(data, "t", r.data.t);
  write_ints(data, "episode", r.data.episode);
  write_ints(data, "heldout", std::vector<int>(r.data.heldout.begin(), r.data.heldout.end()));

  H5::Group compare = root.createGroup("compare");
  write_matrix(compare, "predicted", r.predicted);
  write_matrix(compare, "residual", r.residual);
  write_matrix(compare, "gp_mean", r.gp.mean);
  write_matrix(compare, "gp_std", r.gp.variance.cwiseSqrt());
  H5::Group states = compare.createGroup("states");
  const auto n = static_cast<Eigen::Index>(r.states.size());
  Vector rmse(n), floor(n), heldout(n), fit(n), structure(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const StateScore& s = r.states[static_cast<std::size_t>(i)];
    rmse(i) = s.rmse;
    floor(i) = s.noise_floor;
    heldout(i) = s.heldout_rmse;
    fit(i) = s.fit_percent;
    structure(i) = s.gp_explained;
  }
  write_vector(states, "rmse", rmse);
  write_vector(states, "noise_floor", floor);
  write_vector(states, "heldout_rmse", heldout);
  write_vector(states, "fit_percent", fit);
  write_vector(states, "gp_explained", structure);
  for (const KStepScore& k : r.k_step) {
    H5::Group g = compare.createGroup("k_" + std::to_string(k.k));
    write_int_attribute(g, "k", k.k);
    write_int_attribute(g, "stride", k.stride);
    write_matrix(g, "measured", k.predictions.measured);
    write_matrix(g, "predicted", k.predictions.predicted);
    write_ints(g, "episode", k.predictions.episode);
    write_ints(g, "start", k.predictions.start);
  }
}

void write_where(H5::Group root, const DiagnosisReport& r) {
  H5::Group where = root.createGroup("where");
  write_matrix(where, "relevance", r.relevance);
  write_matrix(where, "sensitivity", r.sensitivity);
  write_matrix(where, "episode_rmse", r.episode_rms);
  H5::Group bins = where.createGroup("bins");
  for (const BinnedResidual& b : r.bins) {
    H5::Group g = bins.createGroup(b.input);
    write_vector(g, "edges", b.edges);
    write_matrix(g, "rmse", b.rms);
    write_ints(g, "count", b.count);
  }
  H5::Group xc = where.createGroup("cross_correlation");
  const int L = r.xcorr.max_lag;
  Vector lags(2 * L + 1);
  for (int k = -L; k <= L; ++k) lags(k + L) = k;
  write_vector(xc, "lags", lags);
  const auto n = r.xcorr.values.size();
  const auto m = n > 0 ? r.xcorr.values[0].size() : 0;
  std::vector<double> values;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) values.insert(values.end(), r.xcorr.values[i][j].data(), r.xcorr.values[i][j].data() + 2 * L + 1);
  write_array(xc, "values", values.data(), {n, m, static_cast<hsize_t>(2 * L + 1)});
  write_matrix(xc, "band", r.xcorr.band);
}

void write_ranking(H5::Group root, const DiagnosisReport& r) {
  H5::Group g = root.createGroup("ranking");
  const int state = worst_state(r);
  write_string_attribute(g, "heldout_state", r.state_names[static_cast<std::size_t>(state)]);
  if (r.ranking.empty()) return;
  std::vector<std::string> effect, parameter, unit, aliases;
  const auto G = static_cast<Eigen::Index>(r.ranking.size());
  Vector estimate(G), low(G), high(G), explained(G), explained_ci(G), z(G), before(G), after(G);
  for (Eigen::Index k = 0; k < G; ++k) {
    const RankedEffect& e = r.ranking[static_cast<std::size_t>(k)];
    effect.push_back(e.fit.effect);
    parameter.push_back(e.fit.parameters[0].name);
    unit.push_back(e.fit.parameters[0].unit);
    std::string list;
    for (const EffectFit& a : e.aliases) list += (list.empty() ? "" : ",") + a.effect;
    aliases.push_back(list);
    estimate(k) = e.fit.estimate(0);
    low(k) = e.fit.ci_low(0);
    high(k) = e.fit.ci_high(0);
    explained(k) = e.fit.explained;
    explained_ci(k) = e.fit.explained_ci;
    z(k) = e.fit.z_score;
    before(k) = e.fit.heldout_rmse_before(state);
    after(k) = e.fit.heldout_rmse_after(state);
  }
  write_strings(g, "effect", effect, false);
  write_strings(g, "parameter_name", parameter, false);
  write_strings(g, "unit", unit, false);
  write_strings(g, "aliases", aliases, false);
  write_vector(g, "estimate", estimate);
  write_vector(g, "ci_low", low);
  write_vector(g, "ci_high", high);
  write_vector(g, "explained", explained);
  write_vector(g, "explained_ci", explained_ci);
  write_vector(g, "z_score", z);
  write_vector(g, "heldout_rmse_before", before);
  write_vector(g, "heldout_rmse_after", after);
}

void write_add(H5::Group root, const DiagnosisReport& r) {
  if (r.comparison.empty()) return;
  H5::Group g = root.createGroup("add");
  write_string_attribute(g, "effect", r.comparison_effect);
  std::vector<std::string> names;
  Matrix rmse(static_cast<Eigen::Index>(r.comparison.size()), static_cast<Eigen::Index>(r.states.size()));
  Matrix variance(2, static_cast<Eigen::Index>(r.states.size()));
  int with_gp = 0;
  for (std::size_t k = 0; k < r.comparison.size(); ++k) {
    names.push_back(r.comparison[k].name);
    rmse.row(static_cast<Eigen::Index>(k)) = r.comparison[k].heldout_rmse.transpose();
    if (r.comparison[k].signal_variance.size() > 0 && with_gp < 2) variance.row(with_gp++) = r.comparison[k].signal_variance.transpose();
  }
  write_strings(g, "model", names, false);
  write_matrix(g, "heldout_rmse", rmse);
  write_matrix(g, "signal_variance", variance);
  write_matrix(g, "residual_before", r.residual_base);
  write_matrix(g, "residual_after", r.residual_after);
  write_matrix(g, "relevance_before", r.relevance_base);
}

std::string now_utc() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char buffer[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

}  // namespace

void write_report_hdf5(const std::filesystem::path& file, const DiagnosisReport& r) {
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    try {
      H5::Exception::dontPrint();
      H5::H5File h5(temporary.string(), H5F_ACC_TRUNC);
      H5::Group root = h5.openGroup("/");
      write_int_attribute(root, "schema_version", 1);
      write_string_attribute(root, "gpilqg_version", GPILQG_VERSION_STRING);
      write_string_attribute(root, "system", r.system);
      write_string_attribute(root, "created", now_utc());
      write_string_attribute(root, "status", r.verdict.status);
      write_string_attribute(root, "verdict_effect", r.verdict.effect ? r.verdict.effect->effect : std::string());
      write_int_attribute(root, "consistent", r.consistent ? 1 : 0);
      write_string_attribute(root, "model", model_file_text(r.model));
      write_string_attribute(root, "model_next", model_file_text(r.model_next));
      write_string_attribute(root, "report", report_json(r).dump());
      write_strings(root, "state_names", r.state_names, true);
      write_strings(root, "control_names", r.control_names, true);
      write_strings(root, "input_names", r.input_names, true);
      write_data(root, r);
      write_where(root, r);
      write_ranking(root, r);
      write_add(root, r);
    } catch (const H5::Exception& e) {
      throw std::runtime_error(file.string() + ": writing the HDF5 report failed (" + e.getDetailMsg() + ")");
    }
  });
}

}  // namespace gpilqg::diagnosis
