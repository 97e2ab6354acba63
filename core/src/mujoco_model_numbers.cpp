#include "mujoco_model_numbers.hpp"

#include <cmath>
#include <cstring>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mujoco/mjxmacro.h>

namespace gpilqg {
namespace {

/// One real array of an mjModel (MJMODEL_POINTERS): rows x columns values of double or of float.
struct RealArray {
  std::string_view name;
  long rows = 0;
  long columns = 0;
  double* doubles = nullptr;
  float* floats = nullptr;
  long size() const { return rows * columns; }
  double at(long i) const { return doubles != nullptr ? doubles[i] : static_cast<double>(floats[i]); }
};

void add(std::vector<RealArray>& out, std::string_view name, long rows, long columns, double* values) {
  out.push_back({name, rows, columns, values, nullptr});
}
void add(std::vector<RealArray>& out, std::string_view name, long rows, long columns, float* values) {
  out.push_back({name, rows, columns, nullptr, values});
}
template <typename Other>
void add(std::vector<RealArray>&, std::string_view, long, long, Other*) {}  // integers, bytes, names

/// Every real array of `m` with its size in this model.
std::vector<RealArray> real_arrays(mjModel* m) {
  std::vector<RealArray> out;
  MJMODEL_POINTERS_PREAMBLE(m)
#define X(type, name, nr, nc) add(out, #name, static_cast<long>(m->nr), static_cast<long>(nc), m->name);
  MJMODEL_POINTERS
#undef X
  return out;
}

/// The MuJoCo object whose row an mjModel array's name starts with ("jnt_axis": a joint), for naming it.
struct RowOwner {
  std::string_view prefix;
  mjtObj type;
  const char* word;
};

constexpr RowOwner kRowOwners[] = {
    {"body_", mjOBJ_BODY, "body"},       {"jnt_", mjOBJ_JOINT, "joint"},       {"geom_", mjOBJ_GEOM, "geom"},
    {"site_", mjOBJ_SITE, "site"},       {"cam_", mjOBJ_CAMERA, "camera"},     {"light_", mjOBJ_LIGHT, "light"},
    {"mesh_", mjOBJ_MESH, "mesh"},       {"skin_", mjOBJ_SKIN, "skin"},        {"hfield_", mjOBJ_HFIELD, "height field"},
    {"tex_", mjOBJ_TEXTURE, "texture"},  {"mat_", mjOBJ_MATERIAL, "material"}, {"pair_", mjOBJ_PAIR, "contact pair"},
    {"eq_", mjOBJ_EQUALITY, "equality"}, {"tendon_", mjOBJ_TENDON, "tendon"},  {"actuator_", mjOBJ_ACTUATOR, "actuator"},
    {"sensor_", mjOBJ_SENSOR, "sensor"}, {"numeric_", mjOBJ_NUMERIC, "numeric"}, {"key_", mjOBJ_KEY, "keyframe"},
};

/// "joint 'shoulder'" for row `row` of the array `array` (a degree of freedom by its joint), or
/// "row 3" when the array's rows are not objects with names.
std::string row_owner(const mjModel* m, std::string_view array, long row) {
  const auto named = [&](mjtObj type, const char* word, int id) {
    const char* name = mj_id2name(m, type, id);
    return name != nullptr && *name != '\0' ? fmt::format("{} '{}'", word, name) : fmt::format("{} {}", word, id);
  };
  if (array.starts_with("dof_")) return named(mjOBJ_JOINT, "joint", m->dof_jntid[row]);
  for (const RowOwner& owner : kRowOwners)
    if (array.starts_with(owner.prefix)) return named(owner.type, owner.word, static_cast<int>(row));
  return fmt::format("row {}", row);
}

/// MuJoCo's constants computed at compile time from the file's numbers: the names ending in 0 (at
/// qpos0: body_invweight0, dof_invweight0, tendon_length0, actuator_acc0, cam_pos0, ...), the subtree
/// masses and the bounding radii.
bool computed_constant(std::string_view name) {
  return name.ends_with('0') || name == "body_subtreemass" || name == "geom_rbound";
}

constexpr const char* kMujocoReadsNan = "MuJoCo reads a NaN or an infinity in the file with a warning only";

}  // namespace

std::optional<std::string> model_number_problem(const mjModel* m) {
  // mjOption's real numbers (timestep, density, viscosity, tolerances, ...; gravity, wind, ...).
  std::optional<std::string> problem;
#define X(type, name)          \
  if (!problem && !std::isfinite(m->opt.name)) \
    problem = fmt::format("<option {}=\"{}\">; expected a finite number ({})", #name, m->opt.name, kMujocoReadsNan);
  MJOPTION_FLOATS
#undef X
#define X(name, n)                                              \
  for (int i = 0; !problem && i < (n); ++i)                     \
    if (!std::isfinite(m->opt.name[i]))                         \
      problem = fmt::format("<option {}>: entry {} is {}; expected finite numbers ({})", #name, i, m->opt.name[i], \
                            kMujocoReadsNan);
  MJOPTION_VECTORS
#undef X
  if (problem) return problem;
  // Every real array of mjModel (read only: real_arrays hands out the model's own pointers): first those
  // the file gives, then MuJoCo's constants computed from them (a NaN axis makes body_invweight0 NaN;
  // the axis is the one to name).
  const std::vector<RealArray> arrays = real_arrays(const_cast<mjModel*>(m));
  for (const bool computed : {false, true})
    for (const RealArray& array : arrays) {
      if (computed_constant(array.name) != computed) continue;
      for (long i = 0; i < array.size(); ++i)
        if (!std::isfinite(array.at(i))) {
        const long row = i / array.columns;
        std::vector<double> values;
        for (long c = 0; c < array.columns; ++c) values.push_back(array.at(row * array.columns + c));
          return fmt::format("{}: {} is ({}); expected finite numbers ({})", row_owner(m, array.name, row),
                             array.name, fmt::join(values, ", "),
                             computed ? "MuJoCo computed it from the model's numbers: a mass, an inertia or a distance "
                                        "too large or too small for double precision"
                                      : kMujocoReadsNan);
        }
    }
  // Passive joint forces that add energy: a negative damping, armature or friction loss.
  for (int i = 0; i < m->nv; ++i)
    for (const auto& [field, value] : {std::pair{"damping", m->dof_damping[i]}, std::pair{"armature", m->dof_armature[i]},
                                       std::pair{"frictionloss", m->dof_frictionloss[i]}})
      if (value < 0.0)
        return fmt::format("{}: {} is {}; expected a value >= 0 (a negative one adds energy: the joint would speed "
                           "itself up)",
                           row_owner(m, "dof_", i), field, value);
  return std::nullopt;
}

void copy_real_numbers(const mjModel* from, mjModel* to) {
  const std::vector<RealArray> source = real_arrays(const_cast<mjModel*>(from));  // read only
  const std::vector<RealArray> target = real_arrays(to);
  for (std::size_t a = 0; a < source.size(); ++a) {
    const RealArray& s = source[a];
    const RealArray& t = target[a];  // the same array: one list, one order
    if (s.rows != t.rows || s.columns != t.columns || s.size() == 0) continue;
    if (s.doubles != nullptr) std::memcpy(t.doubles, s.doubles, sizeof(double) * static_cast<std::size_t>(s.size()));
    else std::memcpy(t.floats, s.floats, sizeof(float) * static_cast<std::size_t>(s.size()));
  }
  mjData* d = mj_makeData(to);
  if (d == nullptr) return;  // mj_setConst needs data; the caller's own allocation will fail and say so
  mj_setConst(to, d);
  mj_deleteData(d);
}

}  // namespace gpilqg
