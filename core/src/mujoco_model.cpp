#include "mujoco_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <mutex>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <unistd.h>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "mujoco_actuator_units.hpp"
#include "mujoco_model_files.hpp"
#include "mujoco_model_numbers.hpp"
#include "urdf_actuators.hpp"

namespace gpilqg {
namespace {

/// MuJoCo's warnings printed so far, and how many are printed at most: a fit that tries parameters at
/// which the model is unstable makes MuJoCo warn at every step (60,000 lines in one diagnosis), and
/// the diagnosis already treats those predictions as diverged.
std::atomic<long> warnings_printed{0};
constexpr long kMaxWarningsPrinted = 5;

/// MuJoCo prints warnings on stdout by default, which would corrupt `--json` output: route them to
/// stderr, once per process, the first kMaxWarningsPrinted of them.
void route_warnings_to_stderr() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_warning = [](const char* message) {
      const long count = ++warnings_printed;
      if (count <= kMaxWarningsPrinted) std::fprintf(stderr, "warning: MuJoCo: %s\n", message);
      if (count == kMaxWarningsPrinted)
        std::fprintf(stderr, "warning: MuJoCo: further warnings of this process are not printed\n");
    };
  });
}

std::string object_name(const mjModel* m, mjtObj type, int id) {
  const char* name = mj_id2name(m, type, id);
  return name == nullptr ? std::string() : std::string(name);
}

/// MuJoCo's multi-line message on one line: "XML Error: ...; Element 'geom', line 5".
std::string one_line(const std::string& text) {
  std::string out;
  bool pending_break = false;
  for (const char c : text) {
    if (c == '\n' || c == '\r') {
      pending_break = !out.empty();
      continue;
    }
    if (pending_break) out += "; ";
    pending_break = false;
    out += c;
  }
  return out;
}

/// MuJoCo's "last loaded model" (mj_saveLastXML) is process-wide: loads take turns.
std::mutex& load_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// A URDF with the motors and mimic equalities of urdf_actuators.hpp: MuJoCo loads the URDF, writes it
/// back as MJCF, and loads that with the <actuator> and <equality> sections added, from memory (named after the URDF, in its folder, so
/// that mesh files resolve as they do for the URDF).
mjModel* load_urdf(const std::string& path, const std::string& text, char* error, int error_size) {
  const std::vector<urdf::Joint> joints = urdf::read_joints(text, path);
  mjModel* plain = mj_loadXML(path.c_str(), nullptr, error, error_size);
  if (plain == nullptr) return nullptr;
  std::vector<std::string> model_joints;
  for (int j = 0; j < plain->njnt; ++j) model_joints.push_back(object_name(plain, mjOBJ_JOINT, j));
  std::string additions;
  try {
    additions = urdf::actuator_section(joints, model_joints, path) + urdf::equality_section(joints);
  } catch (...) {
    mj_deleteModel(plain);
    throw;
  }
  if (additions.empty()) return plain;  // every joint passive (effort = 0) or fixed, none mimics

  static std::atomic<int> counter{0};
  std::error_code ec;
  const std::filesystem::path saved =
      std::filesystem::temp_directory_path(ec) / fmt::format("gpilqg_urdf_{}_{}.xml", ::getpid(), counter++);
  const int ok = mj_saveLastXML(saved.string().c_str(), plain, error, error_size);
  if (!ok) {
    mj_deleteModel(plain);
    std::filesystem::remove(saved, ec);
    throw std::runtime_error(fmt::format("{}: MuJoCo could not convert the URDF to MJCF: {}", path, one_line(error)));
  }
  std::string mjcf = model_file_text(saved.string());
  std::filesystem::remove(saved, ec);
  const std::size_t end = mjcf.rfind("</mujoco>");
  if (end == std::string::npos) {
    mj_deleteModel(plain);
    throw std::runtime_error(fmt::format("{}: MuJoCo's MJCF of the URDF has no </mujoco>", path));
  }
  mjcf.insert(end, additions);

  mjVFS vfs;
  mj_defaultVFS(&vfs);
  const std::string name = path + ".gpilqg.xml";
  if (mj_makeEmptyFileVFS(&vfs, name.c_str(), static_cast<int>(mjcf.size())) != 0) {
    mj_deleteModel(plain);
    throw std::runtime_error(fmt::format("{}: MuJoCo could not hold the converted model in memory", path));
  }
  std::memcpy(vfs.filedata[vfs.nfile - 1], mjcf.data(), mjcf.size());
  mjModel* m = mj_loadXML(name.c_str(), &vfs, error, error_size);
  mj_deleteVFS(&vfs);
  if (m == nullptr) {
    const std::string reason = one_line(error);
    std::snprintf(error, static_cast<std::size_t>(error_size), "with the motors gpilqg adds to its joints: %s",
                  reason.c_str());
  } else {
    copy_real_numbers(plain, m);  // the URDF's numbers, not the MJCF writer's 6 digits
  }
  mj_deleteModel(plain);
  return m;
}

/// The second moment S_k = (I_j + I_l - I_k) / 2 of principal moments `I` ({j, k, l} = {0, 1, 2}): the
/// spread of the mass along axis k, never below 0 (a body on the triangle inequality's boundary, a
/// plate, gives -1e-18 after its moments are scaled one by one).
double second_moment(const double* I, int k) { return std::max(0.0, 0.5 * (I[(k + 1) % 3] + I[(k + 2) % 3] - I[k])); }

/// True when body `b` can turn: a hinge, ball or free joint on it or on a body between it and the
/// world. A body that only slides (or is welded to the world) moves its whole mass alike, wherever its
/// centre is.
bool turns(const mjModel* m, int b) {
  for (; b > 0; b = m->body_parentid[b])
    for (int j = m->body_jntadr[b]; j >= 0 && j < m->body_jntadr[b] + m->body_jntnum[b]; ++j)
      if (m->jnt_type[j] != mjJNT_SLIDE) return true;
  return false;
}

}  // namespace

MujocoModel::MujocoModel(mjModel* m, std::string path) : m_(m), path_(std::move(path)) {}

MujocoModel::~MujocoModel() { mj_deleteModel(m_); }

std::shared_ptr<const MujocoModel> MujocoModel::load(const std::string& path) {
  route_warnings_to_stderr();
  check_input_file_as<std::invalid_argument>(path, kMaxConfigFileBytes, "a MuJoCo model (MJCF .xml or URDF)");
  char error[1024] = "";
  const std::string text = model_file_text(path);
  check_mujoco_model_files(path, text);  // included and asset files: MuJoCo opens them unchecked
  mjModel* m = nullptr;
  {
    std::lock_guard lock(load_mutex());
    m = urdf::is_urdf(text) ? load_urdf(path, text, error, sizeof error)
                            : mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  }
  if (m == nullptr)
    throw std::invalid_argument(fmt::format("{}: MuJoCo cannot load the model: {}", path, one_line(error)));
  // One extra userdata slot per mjData holds the passive-force context of the step (mujoco_system.cpp).
  m->nuserdata += 1;
  std::shared_ptr<MujocoModel> model(new MujocoModel(m, path));
  if (const std::optional<std::string> problem = model_number_problem(m))
    throw std::invalid_argument(fmt::format("{}: {}", path, *problem));
  // MuJoCo accepts timestep="0"; every step length derived from it would be NaN or infinite.
  if (!(std::isfinite(m->opt.timestep) && m->opt.timestep > 0.0))
    throw std::invalid_argument(fmt::format(
        "{}: <option timestep=\"{}\">: the model's timestep is {} s; expected a finite value > 0 (the length of one "
        "MuJoCo step)",
        path, m->opt.timestep, m->opt.timestep));
  for (int j = 0; j < m->njnt; ++j) {
    const std::string name = object_name(m, mjOBJ_JOINT, j);
    const int type = m->jnt_type[j];
    if (type == mjJNT_FREE || type == mjJNT_BALL)
      throw std::invalid_argument(fmt::format(
          "{}: joint {} ('{}') is a {} joint; gpilqg supports hinge and slide joints only (docs/own-system.md)", path,
          j, name.empty() ? "unnamed" : name, type == mjJNT_FREE ? "free" : "ball"));
    if (name.empty())
      throw std::invalid_argument(fmt::format(
          "{}: joint {} has no name; every joint needs one (it names the states in data files)", path, j));
  }
  for (int a = 0; a < m->nu; ++a)
    if (object_name(m, mjOBJ_ACTUATOR, a).empty())
      throw std::invalid_argument(fmt::format(
          "{}: actuator {} has no name; every actuator needs one (it names the controls in data files)", path, a));
  if (m->na > 0)
    throw std::invalid_argument(fmt::format(
        "{}: the model has {} actuator activation state(s); gpilqg supports actuators without activation dynamics",
        path, m->na));
  if (m->njnt == 0) throw std::invalid_argument(fmt::format("{}: the model has no joints; expected hinge or slide joints", path));
  // No actuators: a passive system (no controls), for free-swing and decay data.
  model->read_names();
  // The names become the columns of every measurement file of the system: refused here, before any
  // work, when a file could not hold them (a CSV written but not read back) or two would coincide.
  const auto refuse = [&](const std::string& element, int index, const std::string& name, const std::string& problem) {
    throw std::invalid_argument(fmt::format("{}: {} {} name '{}' {}; it names a column of the data files (docs/formats.md)",
                                            path, element, index, name, problem));
  };
  for (int j = 0; j < m->njnt; ++j)
    if (const auto problem = column_name_problem(object_name(m, mjOBJ_JOINT, j)))
      refuse("joint", j, object_name(m, mjOBJ_JOINT, j), *problem);
  for (int a = 0; a < m->nu; ++a)
    if (const auto problem = column_name_problem(object_name(m, mjOBJ_ACTUATOR, a)))
      refuse("actuator", a, object_name(m, mjOBJ_ACTUATOR, a), *problem);
  std::set<std::string> columns;
  for (const auto* quantities : {&model->states(), &model->controls()})
    for (const Quantity& q : *quantities)
      if (!columns.insert(q.name).second)
        throw std::invalid_argument(fmt::format(
            "{}: the state or control name '{}' occurs twice (a joint's velocity is named '<joint>_dot'); every column "
            "of the data files needs its own name",
            path, q.name));
  return model;
}

void MujocoModel::read_names() {
  name_ = std::string(m_->names);  // the model's name (<mujoco model="...">) comes first in names
  if (name_.empty() || name_ == "MuJoCo Model") name_ = std::filesystem::path(path_).stem().string();
  states_.clear();
  controls_.clear();
  forces_.clear();
  for (int j = 0; j < m_->njnt; ++j) {
    const bool slide = m_->jnt_type[j] == mjJNT_SLIDE;
    const std::string name = object_name(m_, mjOBJ_JOINT, j);
    states_.push_back({name, slide ? "m" : "rad"});
    forces_.push_back({"Q_" + name, slide ? "N" : "N m"});
  }
  for (int j = 0; j < m_->njnt; ++j)
    states_.push_back({object_name(m_, mjOBJ_JOINT, j) + "_dot", m_->jnt_type[j] == mjJNT_SLIDE ? "m/s" : "rad/s"});
  for (int a = 0; a < m_->nu; ++a) controls_.push_back({object_name(m_, mjOBJ_ACTUATOR, a), actuator_control_unit(m_, a)});
  if (gains_.size() != m_->nu) gains_ = Vector::Ones(m_->nu);
  read_second_moments();
}

void MujocoModel::read_second_moments() {
  second_moments_.resize(3 * m_->nbody);
  for (int b = 0; b < m_->nbody; ++b)
    for (int k = 0; k < 3; ++k) second_moments_(3 * b + k) = second_moment(m_->body_inertia + 3 * b, k);
}

std::vector<std::string> MujocoModel::body_names() const {
  std::vector<std::string> out;
  for (int b = 1; b < m_->nbody; ++b) out.push_back(object_name(m_, mjOBJ_BODY, b));
  return out;
}

std::vector<std::string> MujocoModel::joint_names() const {
  std::vector<std::string> out;
  for (int j = 0; j < m_->njnt; ++j) out.push_back(object_name(m_, mjOBJ_JOINT, j));
  return out;
}

std::vector<std::string> MujocoModel::actuator_names() const {
  std::vector<std::string> out;
  for (int a = 0; a < m_->nu; ++a) out.push_back(object_name(m_, mjOBJ_ACTUATOR, a));
  return out;
}

std::vector<MujocoModel::Field> MujocoModel::fields() const {
  std::vector<Field> out;
  constexpr double kZero = 0.0;
  for (int b = 1; b < m_->nbody; ++b) {
    const std::string name = object_name(m_, mjOBJ_BODY, b);
    if (name.empty()) continue;
    out.push_back({name + ".mass", "kg", &m_->body_mass[b], kZero, true});
    if (m_->body_mass[b] <= 0.0 || !turns(m_, b)) continue;  // a centre that cannot move anything
    // The centre of mass in the body's frame (MuJoCo's body_ipos): moving it keeps the mass and the
    // inertia about the centre, and changes the first moment m c that rigid-body dynamics is linear in.
    const char* axes[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
      out.push_back({fmt::format("{}.com_{}", name, axes[k]), "m", &m_->body_ipos[3 * b + k],
                     -std::numeric_limits<double>::infinity(), false});
    // The spread of the mass about the centre along each axis of the inertial frame (MuJoCo's
    // body_iquat; for a diaginertia, the body's axes): S_k = integral of r_k^2 dm >= 0, which is what
    // makes the moments I_1 = S_2 + S_3, ... those of a body (the triangle inequality). The inertia
    // about the body's origin, which rigid-body dynamics is linear in, is linear in each.
    for (int k = 0; k < 3; ++k)
      out.push_back({fmt::format("{}.second_moment_{}", name, k + 1), "kg m^2",
                     const_cast<double*>(&second_moments_(3 * b + k)), kZero, false});
  }
  for (int j = 0; j < m_->njnt; ++j) {
    const std::string name = object_name(m_, mjOBJ_JOINT, j);
    const int dof = m_->jnt_dofadr[j];
    const bool slide = m_->jnt_type[j] == mjJNT_SLIDE;
    out.push_back({name + ".damping", slide ? "N s/m" : "N m s/rad", &m_->dof_damping[dof], kZero, false});
    out.push_back({name + ".armature", slide ? "kg" : "kg m^2", &m_->dof_armature[dof], kZero, false});
    out.push_back({name + ".frictionloss", slide ? "N" : "N m", &m_->dof_frictionloss[dof], kZero, false});
    out.push_back({name + ".stiffness", slide ? "N/m" : "N m/rad", &m_->jnt_stiffness[j], kZero, false});
  }
  for (int a = 0; a < m_->nu; ++a) {
    const std::string name = object_name(m_, mjOBJ_ACTUATOR, a);
    out.push_back({name + ".gear", "-", &m_->actuator_gear[6 * a], -std::numeric_limits<double>::infinity(), false});
    out.push_back({name + ".gain", "-", const_cast<double*>(&gains_(a)), kZero, false});
  }
  return out;
}

std::vector<Parameter> MujocoModel::parameters() const {
  std::vector<Parameter> out;
  for (const Field& f : fields()) out.push_back({f.name, f.unit, *f.value});
  return out;
}

std::shared_ptr<const MujocoModel> MujocoModel::with_parameters(const std::map<std::string, double>& overrides) const {
  mjModel* copy = mj_copyModel(nullptr, m_);
  if (copy == nullptr) throw std::runtime_error(fmt::format("{}: MuJoCo could not copy the model", path_));
  std::shared_ptr<MujocoModel> out(new MujocoModel(copy, path_));
  out->gains_ = gains_;
  out->read_names();
  const std::vector<Field> fields = out->fields();
  std::vector<bool> spread_given(static_cast<std::size_t>(3 * copy->nbody), false);  // second moments overridden
  for (const auto& [key, value] : overrides) {
    const std::string& name = key;  // (clang 14 cannot capture a structured binding)
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const Field& f) { return f.name == name; });
    if (it == fields.end()) {
      std::string known;
      for (const Field& f : fields) known += (known.empty() ? "" : ", ") + f.name;
      throw std::invalid_argument(
          fmt::format("unknown parameter '{}' for MuJoCo model {}; expected one of: {}", key, path_, known));
    }
    if (!std::isfinite(value) || value < it->lower || (it->positive && value <= it->lower))
      throw std::invalid_argument(fmt::format("parameter '{}' of {} = {}; expected a finite value {} {}", key, path_,
                                              value, it->positive ? ">" : ">=", it->lower));
    if (const auto offset = it->value - copy->body_ipos; offset >= 0 && offset < 3 * copy->nbody) {
      // A centre of mass moved off the body's frame: the compiler's shortcuts for a centre in that frame
      // (the inertial frame taken as the body's; a diagonal mass-matrix block) no longer hold, and
      // mj_setConst does not recompute them.
      const auto body = static_cast<int>(offset / 3);
      copy->body_sameframe[body] = 0;
      copy->body_simple[body] = 0;
      for (int g = 0; g < copy->ngeom; ++g)
        if (copy->geom_bodyid[g] == body && copy->geom_sameframe[g] == 2) copy->geom_sameframe[g] = 0;
      for (int s = 0; s < copy->nsite; ++s)
        if (copy->site_bodyid[s] == body && copy->site_sameframe[s] == 2) copy->site_sameframe[s] = 0;
      for (int i = copy->nv - 1; i >= 0; --i)
        copy->dof_simplenum[i] =
            copy->body_simple[copy->dof_bodyid[i]] ? (i + 1 < copy->nv ? copy->dof_simplenum[i + 1] : 0) + 1 : 0;
    }
    if (key.ends_with(".mass")) {
      // The body's rotational inertia scales with its mass (a uniformly denser body).
      const auto body = static_cast<int>(it->value - copy->body_mass);
      const double ratio = value / *it->value;
      for (int k = 0; k < 3; ++k) copy->body_inertia[3 * body + k] *= ratio;
    }
    if (const auto spread = it->value - out->second_moments_.data(); spread >= 0 && spread < 3 * copy->nbody)
      spread_given[static_cast<std::size_t>(spread)] = true;
    *it->value = value;
  }
  // The principal moments of the bodies whose second moments were given (now in out->second_moments_),
  // from the second moments; those not given follow the body's mass, scaled above.
  for (int b = 1; b < copy->nbody; ++b) {
    const auto first = static_cast<std::size_t>(3 * b);
    if (!spread_given[first] && !spread_given[first + 1] && !spread_given[first + 2]) continue;
    double S[3];
    for (int k = 0; k < 3; ++k)
      S[k] = spread_given[first + k] ? out->second_moments_(3 * b + k) : second_moment(copy->body_inertia + 3 * b, k);
    for (int k = 0; k < 3; ++k) copy->body_inertia[3 * b + k] = S[(k + 1) % 3] + S[(k + 2) % 3];
  }
  if (!overrides.empty()) {
    // Derived constants (subtree masses, the constraint solver's inverse weights) follow the new fields.
    mjData* d = mj_makeData(copy);
    mj_setConst(copy, d);
    mj_deleteData(d);
    out->read_second_moments();
  }
  return out;
}

MujocoModel::DataPtr MujocoModel::make_data() const {
  DataPtr d(mj_makeData(m_));
  if (!d) throw std::runtime_error(fmt::format("{}: MuJoCo could not allocate its data", path_));
  return d;
}

void MujocoModel::prepare(mjData* d, const VectorCRef& x, const VectorCRef& u) const {
  const int nv = m_->nv;
  d->time = 0.0;
  for (int i = 0; i < nv; ++i) {
    d->qpos[i] = x(i);
    d->qvel[i] = x(nv + i);
    d->qacc_warmstart[i] = 0.0;
    d->qfrc_applied[i] = 0.0;
  }
  for (int b = 0; b < 6 * m_->nbody; ++b) d->xfrc_applied[b] = 0.0;
  for (int a = 0; a < m_->nu; ++a) d->ctrl[a] = gains_(a) * u(a);
  d->userdata[context_slot()] = 0.0;
  for (int w = 0; w < mjNWARNING; ++w) d->warning[w].number = 0;
}

}  // namespace gpilqg
