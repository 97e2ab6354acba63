#include "gpilqg/experiments/run_merge.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "config_difference.hpp"
#include "run_result_part.hpp"
#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/config_model.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {
namespace {

using Parts = std::vector<RunResultPart>;
using Seeds = std::vector<std::uint64_t>;

/// Where the merged file takes one seed of an algorithm from: a part and the seed's index there.
struct Source {
  std::size_t part = 0;
  std::size_t column = 0;
};

/// What the merged file holds for one task, and which part each piece comes from.
struct TaskPlan {
  std::string name;
  std::vector<std::string> algorithms;
  std::map<std::string, std::map<std::uint64_t, Source>> sources;  ///< per algorithm, per seed
  std::map<std::string, std::size_t> reference;  ///< per algorithm, the first part holding it
  std::string main_algorithm = "gp_ilqg";        ///< the algorithm /<task>/data belongs to
  bool main_link = false;                        ///< /<task>/gp_ilqg is a soft link to main_algorithm
  std::map<std::uint64_t, std::size_t> data;     ///< per seed, the part whose /<task>/data rows are taken
};

std::string name_of(const RunResultPart& part) { return part.file.string(); }

/// A dataset's row-major values around one axis: `outer` blocks, each of `length` slices of `inner` values.
struct AxisBlocks {
  std::size_t outer = 1, length = 1, inner = 1;
  AxisBlocks(const std::vector<std::uint64_t>& dims, std::size_t axis) {
    for (std::size_t d = 0; d < dims.size(); ++d) (d < axis ? outer : d == axis ? length : inner) *= dims[d];
  }
  /// The index of the first value of slice `slice` in block `block`.
  std::size_t at(std::size_t block, std::size_t slice) const { return (block * length + slice) * inner; }
};

// ---- refusals ------------------------------------------------------------------------------------

void require_distinct_files(const std::vector<std::filesystem::path>& files, const std::filesystem::path& out) {
  if (files.size() < 2)
    throw InputError(fmt::format("merge: {} file given; expected two or more result files of `gpilqg run` to join", files.size()));
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (same_file(out, files[i]))
      throw InputError(fmt::format("merge: the output {} is one of the files to merge; write the merged result to another file",
                                   out.string()));
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(files[i], files[j]))
        throw InputError(fmt::format("merge: {} and {} are the same file; give each part once", files[j].string(), files[i].string()));
  }
}

/// Where two texts of RunConfig::files_text first differ: the file (its header, config_file_header)
/// and the line in it.
std::string first_difference(const std::string& here, const std::string& there) {
  std::istringstream a(here), b(there);
  std::string line_a, line_b, file = "no file";
  for (long line = 0;; ++line) {
    const bool more_a = static_cast<bool>(std::getline(a, line_a)), more_b = static_cast<bool>(std::getline(b, line_b));
    if (!more_a && !more_b) return "equal";
    if (!more_a || !more_b || line_a != line_b)
      return fmt::format("{}, line {}: {} here, {} there", file, line, more_a ? '"' + line_a + '"' : std::string("nothing"),
                         more_b ? '"' + line_b + '"' : std::string("nothing"));
    if (const std::optional<std::string> named = config_file_of_header(line_a)) {
      file = *named;
      line = 0;
    }
  }
}

/// The parts must be runs of one experiment: the same system, gpilqg version, config and files it names.
void require_same_run(const Parts& parts) {
  const RunResultPart& first = parts.front();
  const auto config_of = [](const RunResultPart& part) {
    return TomlFields::parse_text(part.config, name_of(part) + "@config");
  };
  const toml::table reference = config_of(first);
  for (std::size_t p = 1; p < parts.size(); ++p) {
    const RunResultPart& part = parts[p];
    const auto refuse = [&](const std::string& field, const std::string& here, const std::string& there) {
      throw InputError(
          fmt::format("{}: its {} differs from {}'s ({} here, {} there)", name_of(part), field, name_of(first), here, there));
    };
    if (part.system != first.system) refuse("system", '"' + part.system + '"', '"' + first.system + '"');
    if (part.gpilqg_version != first.gpilqg_version)
      refuse("gpilqg_version", '"' + part.gpilqg_version + '"', '"' + first.gpilqg_version + '"');
    if (const auto difference = config_difference(config_of(part), reference))
      throw InputError(fmt::format("{}: its config differs from {}'s in {} ({} here, {} there)", name_of(part), name_of(first),
                                   difference->field, difference->value_a, difference->value_b));
    if (part.model_files != first.model_files)
      throw InputError(fmt::format("{}: the files its config names read differently from {}'s ({}); the parts ran "
                                   "different models, which one experiment cannot join",
                                   name_of(part), name_of(first),
                                   first_difference(part.model_files, first.model_files)));
  }
}

/// The two parts hold the same datasets for `algorithm`, with the same shapes but for the seed axis.
void require_same_datasets(const Parts& parts, const std::string& task, const std::string& algorithm, std::size_t a, std::size_t b) {
  const auto& names_a = parts[a].task(task)->datasets.at(algorithm);
  const auto& names_b = parts[b].task(task)->datasets.at(algorithm);
  const std::string group = fmt::format("/{}/{}/", task, algorithm);
  for (const auto& name : names_b)
    if (!contains_name(names_a, name))
      throw InputError(fmt::format("{}: dataset '{}{}' is not in {}; the parts were run differently (e.g. another --iterations)",
                                   name_of(parts[b]), group, name, name_of(parts[a])));
  for (const auto& name : names_a)
    if (!contains_name(names_b, name))
      throw InputError(fmt::format("{}: dataset '{}{}' of {} is missing; the parts were run differently (e.g. another --iterations)",
                                   name_of(parts[b]), group, name, name_of(parts[a])));
  for (const auto& name : names_a) {
    auto dims_a = parts[a].shape(group + name), dims_b = parts[b].shape(group + name);
    const std::size_t axis = *seed_axis(name);
    if (dims_a.size() == dims_b.size()) dims_a[axis] = dims_b[axis];
    if (dims_a != dims_b)
      throw InputError(fmt::format("{}: dataset '{}{}' has shape ({}) here and ({}) in {}; parts may differ only along "
                                   "the seed axis ({})",
                                   name_of(parts[b]), group, name, fmt::join(parts[b].shape(group + name), ", "),
                                   fmt::join(parts[a].shape(group + name), ", "), name_of(parts[a]), axis));
  }
}

/// Seeds of `algorithm` that both parts hold must be equal in every dataset but the wall-clock times.
void require_equal_copies(const Parts& parts, const std::string& task, const std::string& algorithm, std::size_t a, std::size_t b,
                          const Seeds& seeds) {
  const std::string group = fmt::format("/{}/{}/", task, algorithm);
  struct Values {
    std::vector<double> a, b;
    AxisBlocks in_a, in_b;
  };
  std::map<std::string, Values> read;  // each dataset read once
  for (const std::uint64_t seed : seeds)
    for (const auto& name : parts[a].task(task)->datasets.at(algorithm)) {
      if (is_wall_clock_time(name)) continue;
      const std::size_t axis = *seed_axis(name);
      auto found = read.find(name);
      if (found == read.end()) {
        const std::string path = group + name;
        Values v{parts[a].read(path), parts[b].read(path), AxisBlocks(parts[a].shape(path), axis), AxisBlocks(parts[b].shape(path), axis)};
        found = read.emplace(name, std::move(v)).first;
      }
      const Values& v = found->second;
      const std::size_t ca = parts[a].column_of(seed), cb = parts[b].column_of(seed);
      const std::size_t bytes = v.in_a.inner * sizeof(double);
      for (std::size_t block = 0; block < v.in_a.outer; ++block)
        if (bytes > 0 && std::memcmp(v.a.data() + v.in_a.at(block, ca), v.b.data() + v.in_b.at(block, cb), bytes) != 0)
          throw InputError(fmt::format("{} and {} both hold seed {} of {} on task {}, with different values (first in '{}')",
                                       name_of(parts[a]), name_of(parts[b]), seed, algorithm, task, name));
    }
}

// ---- the plan: which part gives what -------------------------------------------------------------

TaskPlan plan_task(const Parts& parts, const std::string& task, const Seeds& seeds) {
  TaskPlan plan;
  plan.name = task;
  // The main GP algorithm first: parts with the link gp_ilqg and parts with an algorithm gp_ilqg
  // (run with and without --backends) do not fit in one file.
  std::string linked, plain;
  for (const RunResultPart& part : parts)
    if (const RunTaskPart* t = part.task(task)) {
      if (t->has_main_link && linked.empty()) {
        linked = name_of(part);
        plan.main_link = true;
        plan.main_algorithm = t->main_algorithm;
      }
      if (contains_name(t->algorithms, "gp_ilqg") && plain.empty()) plain = name_of(part);
    }
  if (!linked.empty() && !plain.empty())
    throw InputError(fmt::format("{} has gp_ilqg as a link to {} on task {}, {} as an algorithm of its own; parts run with and "
                                 "without --backends cannot be joined",
                                 linked, plan.main_algorithm, task, plain));

  for (std::size_t p = 0; p < parts.size(); ++p) {
    const RunTaskPart* in_part = parts[p].task(task);
    if (!in_part) continue;
    for (const std::string& algorithm : in_part->algorithms) {
      if (!contains_name(plan.algorithms, algorithm)) {
        plan.algorithms.push_back(algorithm);
        plan.reference[algorithm] = p;
      } else {
        require_same_datasets(parts, task, algorithm, plan.reference[algorithm], p);
      }
      auto& sources = plan.sources[algorithm];
      std::map<std::size_t, Seeds> shared;  // seeds already taken, by the part they are taken from
      for (const std::uint64_t seed : parts[p].seeds) {
        const auto taken = sources.find(seed);
        if (taken == sources.end()) sources[seed] = {p, parts[p].column_of(seed)};
        else shared[taken->second.part].push_back(seed);
      }
      for (const auto& [q, same_seeds] : shared) require_equal_copies(parts, task, algorithm, q, p, same_seeds);
    }
  }

  for (const std::string& algorithm : plan.algorithms) {
    Seeds has;
    for (const auto& [seed, source] : plan.sources[algorithm]) has.push_back(seed);
    if (has == seeds) continue;
    std::vector<std::string> files;
    for (const RunResultPart& part : parts)
      if (part.task(task) && contains_name(part.task(task)->algorithms, algorithm)) files.push_back(name_of(part));
    throw InputError(fmt::format("{} on task {} has seeds {} but the merged file has seeds {}: every algorithm needs every "
                                 "seed (it is in {})",
                                 algorithm, task, fmt::join(has, ", "), fmt::join(seeds, ", "), fmt::join(files, ", ")));
  }

  for (const std::uint64_t seed : seeds) {
    for (std::size_t p = 0; p < parts.size() && !plan.data.count(seed); ++p) {
      const RunTaskPart* t = parts[p].task(task);
      if (t && t->main_algorithm == plan.main_algorithm && parts[p].column_of(seed) < parts[p].seeds.size()) plan.data[seed] = p;
    }
    if (!plan.data.count(seed))
      throw InputError(fmt::format("task {}: no part holds the transitions {} collected for seed {} (the parts' /{}/data "
                                   "belong to another GP backend)",
                                   task, plan.main_algorithm, seed, task));
  }
  return plan;
}

// ---- writing -------------------------------------------------------------------------------------

void write_task_attributes(Hdf5Writer& h5, const Parts& parts, const TaskPlan& plan) {
  const RunResultPart& part = parts[plan.reference.at(plan.algorithms.front())];
  const std::string group = "/" + plan.name;
  h5.attribute(group, "algorithms", plan.algorithms);
  as_input_error(part.file, [&] {
    h5.attribute(group, "transfer", static_cast<std::int64_t>(part.h5->number_attribute(group, "transfer")));
    h5.attribute(group, "horizon", static_cast<std::int64_t>(part.h5->number_attribute(group, "horizon")));
    h5.attribute(group, "dt", part.h5->number_attribute(group, "dt"));
  });
}

/// Every dataset of `algorithm`, its seeds joined along the seed axis in ascending order.
void write_algorithm(Hdf5Writer& h5, const Parts& parts, const TaskPlan& plan, const std::string& algorithm) {
  const RunResultPart& reference = parts[plan.reference.at(algorithm)];
  const auto& sources = plan.sources.at(algorithm);
  for (const std::string& name : reference.task(plan.name)->datasets.at(algorithm)) {
    const std::string path = fmt::format("/{}/{}/{}", plan.name, algorithm, name);
    const std::size_t axis = *seed_axis(name);
    std::map<std::size_t, std::pair<std::vector<double>, AxisBlocks>> in;  // per part, read once
    for (const auto& [seed, source] : sources)
      if (!in.count(source.part))
        in.emplace(source.part, std::pair{parts[source.part].read(path), AxisBlocks(parts[source.part].shape(path), axis)});
    std::vector<std::uint64_t> dims = reference.shape(path);
    dims[axis] = sources.size();
    const AxisBlocks out_blocks(dims, axis);
    std::vector<double> out(out_blocks.outer * out_blocks.length * out_blocks.inner);
    for (std::size_t block = 0; block < out_blocks.outer; ++block) {
      std::size_t slice = 0;
      for (const auto& [seed, source] : sources) {
        const auto& [values, blocks] = in.at(source.part);
        const double* from = values.data() + blocks.at(block, source.column);
        std::copy(from, from + blocks.inner, out.begin() + static_cast<std::ptrdiff_t>(out_blocks.at(block, slice++)));
      }
    }
    h5.write_array(path, dims, out);
    if (name == "diagnosed_from")  // its per-seed texts (run_results_io.hpp), in the seeds' new order
      for (const char* attribute : {"diagnosis", "model"}) {
        std::vector<std::string> texts;
        for (const auto& [seed, source] : sources)
          texts.push_back(parts[source.part].h5->string_list_attribute(path, attribute).at(source.column));
        h5.attribute(path, attribute, texts);
      }
  }
}

/// /<task>/data: each seed's rows from its data part, in ascending seed order. Returns the rows.
std::size_t write_data(Hdf5Writer& h5, const Parts& parts, const TaskPlan& plan) {
  const std::string group = "/" + plan.name + "/data/";
  const RunResultPart& first = parts[plan.data.begin()->second];
  const auto& names = first.task(plan.name)->data;
  std::map<std::size_t, std::vector<double>> row_seeds;  // per data part, its data/seed
  for (const auto& [seed, p] : plan.data) {
    if (parts[p].task(plan.name)->data != names)
      throw InputError(fmt::format("{}: the datasets of '{}' differ from {}'s", name_of(parts[p]), group, name_of(first)));
    if (!row_seeds.count(p)) row_seeds[p] = parts[p].read(group + "seed");
  }
  std::size_t rows = 0;
  for (const std::string& name : names) {
    const std::string path = group + name;
    std::vector<std::uint64_t> dims = first.shape(path);
    std::map<std::size_t, std::vector<double>> values;  // per data part, read once
    for (const auto& [seed, p] : plan.data) {
      if (values.count(p)) continue;
      auto part_dims = parts[p].shape(path);
      part_dims[0] = dims[0];  // the rows may differ
      if (part_dims != dims)
        throw InputError(fmt::format("{}: dataset '{}' has shape ({}) here and ({}) in {}", name_of(parts[p]), path,
                                     fmt::join(parts[p].shape(path), ", "), fmt::join(dims, ", "), name_of(first)));
      values[p] = parts[p].read(path);
    }
    std::size_t width = 1;
    for (std::size_t d = 1; d < dims.size(); ++d) width *= dims[d];
    std::vector<double> out;
    rows = 0;
    for (const auto& [seed, p] : plan.data) {
      const std::vector<double>& of_row = row_seeds.at(p);
      for (std::size_t row = 0; row < of_row.size(); ++row)
        if (static_cast<std::uint64_t>(of_row[row]) == seed) {
          const double* from = values.at(p).data() + row * width;
          out.insert(out.end(), from, from + width);
          ++rows;
        }
    }
    dims[0] = rows;
    h5.write_array(path, dims, out);
  }
  return rows;
}

/// /<task>/figure1 and its attributes, copied from the part that gave the smallest seed's data.
void write_figure1(Hdf5Writer& h5, const Parts& parts, const TaskPlan& plan) {
  const RunResultPart& part = parts[plan.data.begin()->second];
  const std::string group = "/" + plan.name + "/figure1";
  for (const std::string& name : part.task(plan.name)->figure1) {
    const std::string path = group + "/" + name;
    h5.write_array(path, part.shape(path), part.read(path));
  }
  if (part.task(plan.name)->figure1.empty()) return;
  as_input_error(part.file, [&] {
    for (const char* name : {"output", "input", "output_unit", "input_unit"})
      if (part.h5->has_attribute(group, name)) h5.attribute(group, name, part.h5->string_attribute(group, name));
  });
}

MergeSummary write_merged(const std::filesystem::path& file, const Parts& parts, const Seeds& seeds,
                          const std::vector<TaskPlan>& plans) {
  MergeSummary summary;
  summary.parts = parts.size();
  summary.seeds = seeds;
  Hdf5Writer h5(file);
  const RunResultPart& first = parts.front();
  h5.attribute("/", "schema_version", kRunResultsSchemaVersion);
  h5.attribute("/", "gpilqg_version", first.gpilqg_version);
  h5.attribute("/", "config", first.config);
  h5.attribute("/", "model_files", first.model_files);
  h5.attribute("/", "seed", static_cast<std::int64_t>(seeds.front()));
  h5.attribute("/", "created", utc_timestamp());
  h5.attribute("/", "system", first.system);
  h5.write_vector("/seeds", std::vector<double>(seeds.begin(), seeds.end()));
  for (const TaskPlan& plan : plans) {
    write_task_attributes(h5, parts, plan);
    const std::size_t rows = write_data(h5, parts, plan);
    for (const std::string& algorithm : plan.algorithms) write_algorithm(h5, parts, plan, algorithm);
    if (plan.main_link) h5.link("/" + plan.name + "/gp_ilqg", "/" + plan.name + "/" + plan.main_algorithm);
    write_figure1(h5, parts, plan);
    summary.tasks.push_back({plan.name, plan.algorithms, rows});
  }
  h5.close();
  return summary;
}

}  // namespace

MergeSummary merge_run_results(const std::vector<std::filesystem::path>& files, const std::filesystem::path& out) {
  require_distinct_files(files, out);
  Parts parts;
  for (const auto& file : files) parts.push_back(read_run_result_part(file));
  require_same_run(parts);

  std::set<std::uint64_t> all_seeds;
  std::vector<std::string> tasks;
  for (const RunResultPart& part : parts) {
    all_seeds.insert(part.seeds.begin(), part.seeds.end());
    for (const RunTaskPart& task : part.tasks)
      if (!contains_name(tasks, task.name)) tasks.push_back(task.name);
  }
  const Seeds seeds(all_seeds.begin(), all_seeds.end());
  std::vector<TaskPlan> plans;
  for (const std::string& task : tasks) plans.push_back(plan_task(parts, task, seeds));

  MergeSummary summary;
  write_atomically(out, [&](const std::filesystem::path& temporary) { summary = write_merged(temporary, parts, seeds, plans); });
  return summary;
}

}  // namespace gpilqg
