#pragma once
/// @file run_result_part.hpp
/// One result file of `gpilqg run` as `gpilqg merge` sees it (run_merge.hpp): its root attributes,
/// seeds, tasks and, per task, the algorithms with the names of their datasets, checked against the
/// layout of run_results_io.hpp. The values stay in the file and are read dataset by dataset.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/hdf5_reader.hpp"

namespace gpilqg {

struct RunTaskPart {
  std::string name;
  std::vector<std::string> algorithms;  ///< the task's algorithms attribute, in run order
  /// Per algorithm, its datasets relative to /<task>/<algorithm>/, sorted ("cost", "iter_0/K", ...).
  std::map<std::string, std::vector<std::string>> datasets;
  /// The algorithm whose transitions /<task>/data holds: the target of the soft link /<task>/gp_ilqg
  /// when there is one (GP backends compared), else "gp_ilqg".
  std::string main_algorithm;
  bool has_main_link = false;
  std::vector<std::string> data;     ///< the datasets of /<task>/data/ (rows), by name
  std::vector<std::string> figure1;  ///< the datasets of /<task>/figure1/, by name
};

struct RunResultPart {
  std::filesystem::path file;
  std::unique_ptr<Hdf5Reader> h5;
  std::string gpilqg_version, config, system;
  /// The texts of the files its config named (RunConfig::files_text); "" in a file of an earlier
  /// gpilqg, which did not store them.
  std::string model_files;
  std::vector<std::uint64_t> seeds;  ///< /seeds, in the file's order
  std::vector<RunTaskPart> tasks;    ///< by name

  /// The task named `name`, or null.
  const RunTaskPart* task(const std::string& name) const;
  /// The column of `seed` along the seed axes (its index in `seeds`).
  std::size_t column_of(std::uint64_t seed) const;
  /// The dataset at `path` flattened in row-major order; a failure is an InputError naming the file.
  std::vector<double> read(const std::string& path) const;
  /// Its shape; fails like read().
  std::vector<std::uint64_t> shape(const std::string& path) const;
};

/// Opens `file` and checks it is a result of `gpilqg run` of this layout: schema_version
/// kRunResultsSchemaVersion; /seeds of distinct whole numbers; every dataset known to the layout
/// (seed_axis() for the algorithms' datasets) with one slice per seed along its seed axis; data/
/// datasets of one row per entry of data/seed; every value of every dataset finite. Throws
/// InputError naming the file and the dataset or attribute otherwise (a file that is not HDF5, not
/// a run result, made by another version, or holding a NaN or inf: "dataset '/swing_up/gp_ilqg/cost'
/// entry [0, 1] is nan; expected finite numbers").
RunResultPart read_run_result_part(const std::filesystem::path& file);

/// True when `name` is one of `names` (a task's algorithms, the tasks of the parts).
bool contains_name(const std::vector<std::string>& names, const std::string& name);

}  // namespace gpilqg
