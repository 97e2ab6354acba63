#include "run_result_part.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_results_io.hpp"

namespace gpilqg {
namespace {

/// "a/b/c" -> {"a", "b/c"}; {"a", ""} without a '/'.
std::pair<std::string, std::string> split_first(const std::string& path) {
  const std::size_t slash = path.find('/');
  if (slash == std::string::npos) return {path, ""};
  return {path.substr(0, slash), path.substr(slash + 1)};
}

/// The index of flat entry `i` of a row-major array of shape `dims`: "[2, 0]" ("[i]" for a scalar).
std::string entry_index(std::size_t i, const std::vector<std::uint64_t>& dims) {
  std::vector<std::uint64_t> index(dims.size());
  for (std::size_t axis = dims.size(); axis-- > 0;) {
    index[axis] = dims[axis] == 0 ? 0 : i % dims[axis];
    i = dims[axis] == 0 ? i : i / dims[axis];
  }
  return fmt::format("[{}]", index.empty() ? std::to_string(i) : fmt::format("{}", fmt::join(index, ", ")));
}

class PartChecker {
 public:
  explicit PartChecker(RunResultPart& part) : part_(part), h5_(*part.h5) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(fmt::format("{}: {}", part_.file.string(), problem));
  }

  void read_root() {
    if (!h5_.has_attribute("/", "schema_version"))
      fail("no 'schema_version' attribute; expected a result file of `gpilqg run`");
    const double schema = h5_.number_attribute("/", "schema_version");
    if (schema != static_cast<double>(kRunResultsSchemaVersion))
      fail(fmt::format("attribute 'schema_version' is {}; this gpilqg reads result files of schema_version {}", schema,
                       kRunResultsSchemaVersion));
    part_.gpilqg_version = required_string("gpilqg_version");
    part_.config = required_string("config");
    if (h5_.has_attribute("/", "model_files")) part_.model_files = required_string("model_files");
    part_.system = required_string("system");
    if (!h5_.exists("/seeds")) fail("dataset '/seeds' is missing; expected a result file of `gpilqg run`");
    std::set<std::uint64_t> seen;
    for (const double seed : h5_.read_array("/seeds")) {
      if (!(seed >= 0.0 && seed <= static_cast<double>(limits::kMaxSeed)) || std::floor(seed) != seed)
        fail(fmt::format("dataset '/seeds' holds {}; expected whole numbers in [0, {}]", seed, limits::kMaxSeed));
      if (!seen.insert(static_cast<std::uint64_t>(seed)).second) fail(fmt::format("dataset '/seeds' holds {} twice", seed));
      part_.seeds.push_back(static_cast<std::uint64_t>(seed));
    }
    if (part_.seeds.empty()) fail("dataset '/seeds' is empty");
  }

  /// Sorts every dataset of the file into its task's lists; anything else is an unknown dataset.
  void read_datasets() {
    for (const std::string& path : h5_.datasets()) {
      if (path == "/seeds") continue;
      const auto [task_name, in_task] = split_first(path.substr(1));
      const auto [group, name] = split_first(in_task);
      if (name.empty()) unknown(path);
      RunTaskPart& task = task_named(task_name);
      if (group == "data") task.data.push_back(name);
      else if (group == "figure1") task.figure1.push_back(name);
      else if (contains_name(task.algorithms, group) && seed_axis(name)) task.datasets[group].push_back(name);
      else unknown(path);
    }
  }

  void check_tasks() {
    for (const RunTaskPart& task : part_.tasks) {
      for (const std::string& algorithm : task.algorithms) {
        const auto found = task.datasets.find(algorithm);
        if (found == task.datasets.end())
          fail(fmt::format("algorithm '{}' of task '{}' (its 'algorithms' attribute) has no datasets", algorithm, task.name));
        for (const std::string& name : found->second) check_seed_axis(fmt::format("/{}/{}/{}", task.name, algorithm, name), name);
      }
      if (task.has_main_link && !contains_name(task.algorithms, task.main_algorithm))
        fail(fmt::format("the soft link '/{}/gp_ilqg' points to '{}', which is not one of the task's algorithms", task.name,
                         task.main_algorithm));
      check_data(task);
    }
  }

  /// Every value of every dataset is finite: `gpilqg run` writes none other (a diverged rollout is
  /// counted in `diverged`, its cost stays finite), so a NaN or inf is a damaged or edited file and
  /// would otherwise be copied into the merged result and every mean over seeds.
  void check_finite() const {
    for (const std::string& path : h5_.datasets()) {
      const std::vector<double> values = h5_.read_array(path);
      const auto bad = std::find_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); });
      if (bad != values.end())
        fail(fmt::format("dataset '{}' entry {} is {}; expected finite numbers", path,
                         entry_index(static_cast<std::size_t>(bad - values.begin()), h5_.shape(path)), *bad));
    }
  }

 private:
  std::string required_string(const std::string& name) const {
    if (!h5_.has_attribute("/", name)) fail(fmt::format("no '{}' attribute; expected a result file of `gpilqg run`", name));
    return h5_.string_attribute("/", name);
  }

  [[noreturn]] void unknown(const std::string& path) const {
    fail(fmt::format("dataset '{}' is not part of the result layout this gpilqg writes; the file was made by "
                     "another version of gpilqg",
                     path));
  }

  RunTaskPart& task_named(const std::string& name) {
    for (RunTaskPart& task : part_.tasks)
      if (task.name == name) return task;
    const std::string group = "/" + name;
    if (!h5_.has_attribute(group, "algorithms"))
      fail(fmt::format("group '{}' has no 'algorithms' attribute; expected a task of a result file of `gpilqg run`", group));
    RunTaskPart task;
    task.name = name;
    task.algorithms = h5_.string_list_attribute(group, "algorithms");
    if (const auto target = h5_.soft_link_target(group + "/gp_ilqg")) {
      task.has_main_link = true;
      task.main_algorithm = target->substr(target->find_last_of('/') + 1);
    } else {
      task.main_algorithm = "gp_ilqg";
    }
    part_.tasks.push_back(std::move(task));
    return part_.tasks.back();
  }

  void check_seed_axis(const std::string& path, const std::string& name) const {
    const std::size_t axis = *seed_axis(name);
    const auto dims = h5_.shape(path);
    if (dims.size() <= axis || dims[axis] != part_.seeds.size())
      fail(fmt::format("dataset '{}' has shape ({}); expected one entry per seed ({}) along axis {}", path,
                       fmt::join(dims, ", "), part_.seeds.size(), axis));
  }

  /// data/seed names a seed of the file for every row, and every data/ dataset has one row per entry.
  void check_data(const RunTaskPart& task) const {
    const std::string group = "/" + task.name + "/data";
    if (!contains_name(task.data, "seed")) fail(fmt::format("dataset '{}/seed' is missing", group));
    const std::vector<double> seeds = h5_.read_array(group + "/seed");
    for (const double seed : seeds)
      if (!(seed >= 0.0 && seed <= static_cast<double>(limits::kMaxSeed)) || seed != std::floor(seed) ||
          part_.column_of(static_cast<std::uint64_t>(seed)) == part_.seeds.size())
        fail(fmt::format("dataset '{}/seed' holds {}, which is not one of the file's seeds", group, seed));
    for (const std::string& name : task.data) {
      const auto dims = h5_.shape(group + "/" + name);
      if (dims.empty() || dims[0] != seeds.size())
        fail(fmt::format("dataset '{}/{}' has shape ({}); expected {} rows, one per entry of '{}/seed'", group, name,
                         fmt::join(dims, ", "), seeds.size(), group));
    }
    if (!seeds.empty() && !contains_name(task.algorithms, task.main_algorithm))
      fail(fmt::format("'{}' holds transitions but the task has no algorithm '{}' that collected them", group, task.main_algorithm));
  }

  RunResultPart& part_;
  const Hdf5Reader& h5_;
};

}  // namespace

bool contains_name(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

const RunTaskPart* RunResultPart::task(const std::string& name) const {
  for (const RunTaskPart& t : tasks)
    if (t.name == name) return &t;
  return nullptr;
}

std::size_t RunResultPart::column_of(std::uint64_t seed) const {
  return static_cast<std::size_t>(std::find(seeds.begin(), seeds.end(), seed) - seeds.begin());
}

std::vector<double> RunResultPart::read(const std::string& path) const {
  return as_input_error(file, [&] { return h5->read_array(path); });
}

std::vector<std::uint64_t> RunResultPart::shape(const std::string& path) const {
  return as_input_error(file, [&] { return h5->shape(path); });
}

RunResultPart read_run_result_part(const std::filesystem::path& file) {
  RunResultPart part;
  part.file = file;
  try {
    part.h5 = std::make_unique<Hdf5Reader>(file);
  } catch (const DataError& e) {
    throw InputError(e.what());
  } catch (const std::runtime_error&) {
    throw InputError(fmt::format("{}: not an HDF5 file; expected a result file of `gpilqg run`", file.string()));
  }
  as_input_error(file, [&] {
    PartChecker checker(part);
    checker.read_root();
    checker.read_datasets();
    checker.check_tasks();
    checker.check_finite();
  });
  return part;
}

}  // namespace gpilqg
