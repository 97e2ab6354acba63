/// The results of `gpilqg profile`: JSON, a terminal table, HDF5 (atomically) and the Pareto plot.

#include <H5Cpp.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_memory_file.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/core/version.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/experiments/plot_script.hpp"

namespace gpilqg {

namespace {

bool scored(const ProfileRow& row) { return row.status == "ok"; }

nlohmann::json number_or_null(const ProfileRow& row, double value) {
  return scored(row) && std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

void write_string_attribute(H5::H5Object& object, const std::string& name, const std::string& value) {
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  const char* data = value.c_str();
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, &data);
}

void write_int_attribute(H5::H5Object& object, const std::string& name, long value) {
  object.createAttribute(name, H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_LONG, &value);
}

template <class Get>
void write_column(H5::Group& group, const std::string& name, const std::vector<ProfileRow>& rows, Get&& get) {
  std::vector<double> values;
  for (const ProfileRow& row : rows) values.push_back(get(row));
  const hsize_t dims[1] = {values.size()};
  group.createDataSet(name, H5::PredType::IEEE_F64LE, H5::DataSpace(1, dims))
      .write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

template <class Get>
void write_strings(H5::Group& group, const std::string& name, const std::vector<ProfileRow>& rows, Get&& get) {
  std::vector<std::string> strings;
  for (const ProfileRow& row : rows) strings.push_back(get(row));
  std::vector<const char*> pointers;
  for (const std::string& s : strings) pointers.push_back(s.c_str());
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  const hsize_t dims[1] = {pointers.size()};
  group.createDataSet(name, type, H5::DataSpace(1, dims)).write(pointers.data(), type);
}

}  // namespace

nlohmann::json profile_json(const ProfileReport& report) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ProfileRow& row : report.rows) {
    nlohmann::json parameters = nullptr;
    if (scored(row)) parameters = std::vector<double>(row.parameters.data(), row.parameters.data() + row.parameters.size());
    rows.push_back({{"backend", row.backend},
                    {"size", row.size},
                    {"status", row.status},
                    {"reason", row.reason},
                    {"fit_s", number_or_null(row, row.fit_seconds)},
                    {"predict_s", number_or_null(row, row.predict_seconds)},
                    {"smse", number_or_null(row, row.smse)},
                    {"mnlp", number_or_null(row, row.mnlp)},
                    {"msll", number_or_null(row, row.msll)},
                    {"nlml", number_or_null(row, row.nlml)},
                    {"evaluations", row.evaluations},
                    {"termination", row.termination},
                    {"conditioning", row.conditioning},
                    {"parameters", parameters}});
  }
  const ProfileOptions& o = report.options;
  return {{"file", report.file},
          {"data",
           {{"name", report.data.name},
            {"format", report.data.format},
            {"target", report.data.target},
            {"input_dim", report.data.train.input_dim()},
            {"test_points", report.test_points}}},
          {"settings",
           {{"backends", o.backends},
            {"restarts", o.fit.restarts},
            {"max_evaluations", o.fit.max_evaluations},
            {"seed", o.fit.seed},
            {"start", o.start_from_reference ? "reference" : "data"},
            {"inducing", o.settings.inducing},
            {"frequencies", o.settings.frequencies},
            {"compact_neighbours", o.settings.compact_neighbours},
            {"compact_max_neighbours", o.settings.compact_max_neighbours},
            {"threads", o.settings.threads},
            {"memory_budget_gib", o.memory_budget_bytes / (1ull << 30)},
            {"time_budget_s", o.time_budget_seconds}}},
          {"rows", rows}};
}

std::string format_profile(const ProfileReport& report) {
  std::ostringstream os;
  os << fmt::format("{} ({}, target {}, D = {}, {} test points)\n", report.file, report.data.format, report.data.target,
                    report.data.train.input_dim(), report.test_points);
  os << fmt::format("{:<16} {:>7} {:>10} {:>10} {:>9} {:>9} {:>9} {:>6}  {}\n", "backend", "N", "fit [s]", "predict [s]",
                    "SMSE", "MNLP", "MSLL", "evals", "note");
  for (const ProfileRow& row : report.rows) {
    if (!scored(row)) {
      os << fmt::format("{:<16} {:>7}  {}: {}\n", row.backend, row.size, row.status, row.reason);
      continue;
    }
    os << fmt::format("{:<16} {:>7} {:>10.3f} {:>10.3f} {:>9.5f} {:>9.5f} {:>9.5f} {:>6}  {}{}\n", row.backend, row.size,
                      row.fit_seconds, row.predict_seconds, row.smse, row.mnlp, row.msll, row.evaluations,
                      row.reason.empty() ? row.termination : row.reason,
                      row.conditioning == "ok" ? "" : ", " + row.conditioning);
  }
  return os.str();
}

void write_profile_hdf5(const std::filesystem::path& file, const ProfileReport& report) {
  H5::Exception::dontPrint();
  try {
    write_hdf5_atomically(file, [&](H5::H5File& h5) {
      H5::Group root = h5.openGroup("/");
      write_int_attribute(root, "schema_version", 1);
      write_string_attribute(root, "gpilqg_version", kVersionString);
      write_string_attribute(root, "created", utc_timestamp());
      write_string_attribute(root, "data_file", report.file);
      write_string_attribute(root, "data_name", report.data.name);
      write_string_attribute(root, "target", report.data.target);
      write_string_attribute(root, "settings", profile_json(report)["settings"].dump());
      write_int_attribute(root, "test_points", report.test_points);
      write_int_attribute(root, "input_dim", report.data.train.input_dim());
      H5::Group rows = h5.createGroup("rows");
      const auto& r = report.rows;
      // Rows that were skipped or failed measured nothing: their numbers are 0 and their status says
      // why (no NaN in a result file).
      auto value = [&](double ProfileRow::*field) {
        return [field](const ProfileRow& row) { return scored(row) && std::isfinite(row.*field) ? row.*field : 0.0; };
      };
      write_strings(rows, "backend", r, [](const ProfileRow& row) { return row.backend; });
      write_strings(rows, "status", r, [](const ProfileRow& row) { return row.status; });
      write_strings(rows, "reason", r, [](const ProfileRow& row) { return row.reason; });
      write_column(rows, "size", r, [](const ProfileRow& row) { return static_cast<double>(row.size); });
      write_column(rows, "fit_s", r, value(&ProfileRow::fit_seconds));
      write_column(rows, "predict_s", r, value(&ProfileRow::predict_seconds));
      write_column(rows, "smse", r, value(&ProfileRow::smse));
      write_column(rows, "mnlp", r, value(&ProfileRow::mnlp));
      write_column(rows, "msll", r, value(&ProfileRow::msll));
      write_column(rows, "nlml", r, value(&ProfileRow::nlml));
      write_column(rows, "evaluations", r, [](const ProfileRow& row) { return static_cast<double>(row.evaluations); });
    });
  } catch (const H5::Exception& e) {
    throw std::runtime_error(file.string() + ": writing the profile failed (HDF5: " + e.getDetailMsg() + ")");
  }
}

void plot_profile(const std::filesystem::path& h5, const std::filesystem::path& directory) {
  run_plot_script("plot_profile.py", h5, directory);
}

}  // namespace gpilqg
