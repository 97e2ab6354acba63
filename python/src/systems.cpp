/// Systems from Python: the registry's systems (built-in, MuJoCo model files, plugins), their
/// discrete-time step models, and dynamics written in Python (a subclass of gpilqg.Dynamics) that
/// every command of the library can use once registered.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>

#include <fmt/format.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "gpilqg/core/effect_builders.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/plugin.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"

namespace gpilqg::python {
namespace {

std::vector<Quantity> quantities(const std::vector<py::object>& items, const char* what) {
  std::vector<Quantity> out;
  for (const py::object& item : items) {
    if (py::isinstance<py::str>(item)) {
      out.push_back({item.cast<std::string>(), ""});
      continue;
    }
    if (py::isinstance<py::tuple>(item) && py::len(item) == 2) {
      const py::tuple pair = item.cast<py::tuple>();
      if (py::isinstance<py::str>(pair[0]) && py::isinstance<py::str>(pair[1])) {
        out.push_back({pair[0].cast<std::string>(), pair[1].cast<std::string>()});
        continue;
      }
    }
    raise_input_error(fmt::format("Dynamics: {} entry {} is not a name (str) or a (name, unit) pair of str", what,
                                  std::string(py::repr(item))));
  }
  return out;
}

/// A Dynamics whose f (and optionally Jacobians) are the methods of a Python subclass. Every call
/// takes the GIL, so a solve that runs without it (LongCall) still calls back safely.
class PythonDynamics : public Dynamics {
 public:
  PythonDynamics(std::string name, std::vector<Quantity> states, std::vector<Quantity> controls)
      : name_(std::move(name)), states_(std::move(states)), controls_(std::move(controls)) {
    if (name_.empty()) throw py::value_error("Dynamics: the name is empty");
    // No controls (m = 0) is a passive system: simulate, data and diagnose take it; solve and plan refuse it.
    if (states_.empty()) throw py::value_error("Dynamics: needs at least one state");
  }
  const std::string& name() const override { return name_; }
  const std::vector<Quantity>& states() const override { return states_; }
  const std::vector<Quantity>& controls() const override { return controls_; }

  /// parameters() of the subclass: a dict of names (str) to finite real numbers.
  std::vector<Parameter> parameters() const override {
    py::gil_scoped_acquire gil;
    const py::function method = py::get_override(this, "parameters");
    if (!method) return {};
    const py::object values = method();
    const std::string who = fmt::format("Dynamics '{}': parameters()", name_);
    if (!py::isinstance<py::dict>(values))
      raise_input_error(fmt::format("{} returned {}; expected a dict of names (str) to finite numbers", who,
                                    std::string(py::str(py::type::handle_of(values).attr("__name__")))));
    std::vector<Parameter> out;
    for (const auto& [key, value] : values.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key))
        raise_input_error(fmt::format("{}: the key {} is not a name (str)", who, std::string(py::repr(key))));
      const std::string name = key.cast<std::string>();
      const bool number = (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value) ||
                           py::hasattr(value, "__float__")) && !py::isinstance<py::bool_>(value);
      const double v = number ? py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>() : 0.0;
      if (!number || !std::isfinite(v))
        raise_input_error(fmt::format("{}: '{}' = {}; expected a finite number", who, name, std::string(py::repr(value))));
      out.push_back({name, "", v});
    }
    return out;
  }

  /// f from the Python method f(x, u); Jacobians from jacobians(x, u) when the subclass defines it,
  /// else central differences of f with the step 1e-6 (1 + |x_i|) per coordinate.
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians) const override {
    py::gil_scoped_acquire gil;
    const py::function f = py::get_override(this, "f");
    if (!f) throw py::type_error(fmt::format("Dynamics '{}': the subclass does not define f(x, u)", name_));
    xdot = call_f(f, x, u);
    if (jacobians == nullptr) return;
    jacobians->resize(state_dim(), control_dim());
    if (const py::function analytic = py::get_override(this, "jacobians")) {
      const py::object pair = analytic(Vector(x), Vector(u));
      if (!py::isinstance<py::tuple>(pair) || py::len(pair) != 2)
        raise_input_error(fmt::format("{}: jacobians(x, u) returned {}; expected a tuple (fx, fu)", who(),
                                      std::string(py::str(py::type::handle_of(pair).attr("__name__")))));
      const Finite finite = must_be_finite(x, u);
      const int n = state_dim(), m = control_dim();
      jacobians->fx = matrix_argument(pair.cast<py::tuple>()[0], n, n, "df/dx: states x states of system '" + name_ + "'",
                                      who(), "jacobians(x, u)[0] (fx)", finite);
      jacobians->fu = matrix_argument(pair.cast<py::tuple>()[1], n, m, "df/du: states x controls of system '" + name_ + "'",
                                      who(), "jacobians(x, u)[1] (fu)", finite);
      return;
    }
    Vector z(x.size() + u.size());
    z << x, u;
    for (Eigen::Index j = 0; j < z.size(); ++j) {
      const double h = 1e-6 * (1.0 + std::abs(z(j)));
      Vector plus = z, minus = z;
      plus(j) += h;
      minus(j) -= h;
      const Vector column = (call_f(f, plus.head(x.size()), plus.tail(u.size())) -
                             call_f(f, minus.head(x.size()), minus.tail(u.size()))) / (2.0 * h);
      if (j < x.size()) jacobians->fx.col(j) = column;
      else jacobians->fu.col(j - x.size()) = column;
    }
  }

 private:
  /// f(x, u) of the subclass: shape (n,), finite where must_be_finite says so.
  Vector call_f(const py::function& f, const VectorCRef& x, const VectorCRef& u) const {
    return vector_argument(f(Vector(x), Vector(u)), states_of(*this), who(), "f(x, u)", must_be_finite(x, u));
  }
  std::string who() const { return fmt::format("Dynamics '{}'", name_); }
  /// A non-finite result at a state within the library's divergence bound is a defect of the Python
  /// method; beyond the bound (or at a non-finite point), the state has diverged by the library's
  /// own rule and the non-finite result becomes the rollout's status, as for any system.
  static Finite must_be_finite(const VectorCRef& x, const VectorCRef& u) {
    const bool inside = x.allFinite() && u.allFinite() && (x.size() == 0 || x.cwiseAbs().maxCoeff() <= kDivergedStateMagnitude);
    return inside ? Finite::Required : Finite::Unchecked;
  }
  std::string name_;
  std::vector<Quantity> states_, controls_;
};

/// A Python Dynamics object (checked by the caller to be one) as a DynamicsPtr that keeps the Python
/// object alive (and releases it with the GIL held).
DynamicsPtr hold(py::object object) {
  Dynamics* raw = object.cast<Dynamics*>();
  return std::shared_ptr<const Dynamics>(raw, [object](const Dynamics*) mutable {
    py::gil_scoped_acquire gil;
    object = py::object();
  });
}

/// The noise dict of gpilqg.system(): its keys and its vectors' sizes against the system `name`.
ActuatorNoise noise_of(const std::string& name, const py::object& noise) {
  ActuatorNoise out;
  if (noise.is_none()) return out;
  if (!py::isinstance<py::dict>(noise))
    raise_input_error(fmt::format("system: noise is {}; expected a dict with actuator_additive, "
                                  "actuator_multiplicative or state", std::string(py::str(py::type::handle_of(noise).attr("__name__")))));
  const SystemSignature signature = system_signature(name);
  const Quantities states{static_cast<Eigen::Index>(signature.states.size()), fmt::format("the states of system '{}'", name)};
  const Quantities controls{static_cast<Eigen::Index>(signature.controls.size()), fmt::format("the controls of system '{}'", name)};
  for (const auto& [key, value] : noise.cast<py::dict>()) {
    const std::string k = py::str(key);
    if (k == "actuator_additive") out.additive_std = vector_argument(value, controls, "system", "noise['actuator_additive']");
    else if (k == "actuator_multiplicative")
      out.multiplicative_std = vector_argument(value, controls, "system", "noise['actuator_multiplicative']");
    else if (k == "state") out.state_std = vector_argument(value, states, "system", "noise['state']");
    else raise_input_error(fmt::format("system: noise has the unknown key '{}'; expected actuator_additive, "
                                       "actuator_multiplicative or state", k));
  }
  return out;
}

/// Where a non-finite result came from: finite arguments at which `what` is not finite.
std::string at_finite_point(const std::string& what) {
  return fmt::format("these finite x and u ({} is not finite there)", what);
}
std::string at_finite_point(const Dynamics& system) { return at_finite_point(fmt::format("f of system '{}'", system.name())); }
std::string at_finite_point(const StepModel& model) { return at_finite_point("the step of " + step_model_label(model)); }

Preset preset_of(const std::string& preset) {
  if (const auto p = parse_preset(preset)) return *p;
  throw InputError(fmt::format("preset '{}': expected 'sim' or 'real'", preset));
}

}  // namespace

DynamicsPtr system_from_python(const py::object& system, const std::string& who, const std::string& name) {
  if (py::isinstance<py::str>(system)) return make_system(system.cast<std::string>());
  if (!py::isinstance<Dynamics>(system))
    raise_input_error(fmt::format("{}: {} is {}; expected a system name (str) or a gpilqg.Dynamics", who, name,
                                  std::string(py::str(py::type::handle_of(system).attr("__name__")))));
  return hold(system);  // keeps a Python subclass's Python part alive as long as the library holds it
}

void bind_systems(py::module_& m) {
  py::class_<Dynamics, PythonDynamics, std::shared_ptr<Dynamics>>(m, "Dynamics", R"(
Continuous-time controlled dynamics xdot = f(x, u) with named states and controls.

Systems of the library come from gpilqg.system(name, ...). Subclass it to write dynamics in Python:

    class Pendulum(gpilqg.Dynamics):
        def __init__(self):
            super().__init__("pendulum", states=[("theta", "rad"), ("theta_dot", "rad/s")],
                             controls=[("tau", "N m")])
        def f(self, x, u):                 # x: (n,), u: (m,) -> xdot: (n,)
            return np.array([x[1], -9.81 * np.sin(x[0]) + u[0]])
        def jacobians(self, x, u):         # optional: (fx (n, n), fu (n, m)); else central differences
            ...

and gpilqg.register_system(...) to use it by name in configs, solve, diagnose and plan.)")
      .def(py::init([](std::string name, std::vector<py::object> states, std::vector<py::object> controls) {
             return new PythonDynamics(std::move(name), quantities(states, "states"), quantities(controls, "controls"));
           }),
           py::arg("name"), py::arg("states"), py::arg("controls"),
           "name: the registry name; states, controls: names or (name, unit) pairs, in order")
      .def_property_readonly("name", &Dynamics::name)
      .def_property_readonly("state_names", [](const Dynamics& d) { return names_of(d.states()); })
      .def_property_readonly("control_names", [](const Dynamics& d) { return names_of(d.controls()); })
      .def_property_readonly("state_units", [](const Dynamics& d) {
        std::vector<std::string> units;
        for (const auto& q : d.states()) units.push_back(q.unit);
        return units;
      })
      .def_property_readonly("state_dim", &Dynamics::state_dim)
      .def_property_readonly("control_dim", &Dynamics::control_dim)
      .def_property_readonly("parameter_values", [](const Dynamics& d) {
        std::map<std::string, double> out;
        for (const Parameter& p : d.parameters()) out[p.name] = p.value;
        return out;
      }, "dict: the physical parameters and their values")
      .def("xdot", [](const Dynamics& d, const py::object& x_in, const py::object& u_in) {
             const std::string who = "Dynamics.xdot";
             const Vector x = vector_argument(x_in, states_of(d), who, "x");
             const Vector u = vector_argument(u_in, controls_of(d), who, "u");
             const Vector xdot = d.f(x, u);
             require_finite_result(xdot, who, "xdot", at_finite_point(d));
             return xdot;
           }, py::arg("x"), py::arg("u"), "xdot = f(x, u), shape (n,)")
      .def("derivatives", [](const Dynamics& d, const py::object& x_in, const py::object& u_in) {
             const std::string who = "Dynamics.derivatives";
             const Vector x = vector_argument(x_in, states_of(d), who, "x");
             const Vector u = vector_argument(u_in, controls_of(d), who, "u");
             Vector xdot(d.state_dim());
             DynamicsJacobians j;
             d.evaluate(x, u, xdot, &j);
             require_finite_result(xdot, who, "xdot", at_finite_point(d));
             require_finite_result(j.fx, who, "fx", at_finite_point(d));
             require_finite_result(j.fu, who, "fu", at_finite_point(d));
             return py::make_tuple(xdot, j.fx, j.fu);
           }, py::arg("x"), py::arg("u"), "(xdot (n,), fx = df/dx (n, n), fu = df/du (n, m))");

  m.def("system", [](const std::string& name, const std::string& preset, const std::map<std::string, double>& parameters,
                     const py::object& noise, const std::optional<std::filesystem::path>& model) {
          for (const auto& [parameter, value] : parameters)
            if (!std::isfinite(value))
              raise_input_error(fmt::format("system: parameters['{}'] = {} is not finite", parameter, value));
          if (model && preset != "sim")
            raise_input_error("system: preset and model are both given; the model file names its own preset");
          try {
            const ActuatorNoise noise_model = noise_of(name, noise);
            ModelSpec spec;
            spec.system = name;
            spec.preset = preset_of(preset);
            if (model) spec = diagnosis::read_model_file(*model, name, "system's name");
            // Each override within its parameter's range, as a model file's or a --param.
            for (const auto& [parameter, value] : parameters) spec = with_parameter(spec, parameter, value);
            if (spec.input_delay != 0.0)
              throw InputError(fmt::format("system: {} has an input delay of {} control periods; a Dynamics maps the "
                                           "applied input to xdot and cannot hold it (gpilqg.simulate applies delays)",
                                           model->string(), spec.input_delay));
            return std::const_pointer_cast<Dynamics>(spec.build(noise_model));
          } catch (const std::invalid_argument& e) {  // an unknown name or parameter, a value out of range
            throw InputError(e.what());
          }
        },
        py::arg("name"), py::arg("preset") = "sim", py::arg("parameters") = std::map<std::string, double>{},
        py::arg("noise") = py::none(), py::arg("model") = py::none(), R"(
A system of the registry: "cartpole", "quadrotor", a MuJoCo model file (.xml, .urdf), a plugin's
system or one registered from Python. preset: "sim" or "real"; parameters: overrides by name;
noise: dict with actuator_additive (m,), actuator_multiplicative (m,), state (n,) standard deviations;
model: a model file of `gpilqg diagnose` (--write-model) for this system, with its preset, parameters
and effects (parameters then override its parameters): e.g. the simulator of a StepModel.)");

  m.def("systems", [] { return SystemRegistry::instance().names(); }, "The registered system names.");

  m.def("register_system", [](const std::string& name, const py::function& builder, const std::string& description) {
          // The registry lives until the process ends, after the interpreter: it keeps the builder
          // with a reference that is never released (a Python object must not be freed then).
          if (name.empty()) raise_input_error("register_system: the name is empty; expected a system name");
          PyObject* function = builder.inc_ref().ptr();
          SystemEntry entry;
          entry.name = name;
          entry.description = description.empty() ? "defined in Python" : description;
          entry.origin = "Python";
          entry.build = [function, name](Preset preset, const std::map<std::string, double>& overrides,
                                   const ActuatorNoise& noise) -> DynamicsPtr {
            py::gil_scoped_acquire gil;
            py::object made = py::reinterpret_borrow<py::function>(function)(std::string(to_string(preset)), overrides);
            if (!py::isinstance<Dynamics>(made))
              raise_input_error(fmt::format("register_system('{}'): the builder returned {}; expected a new gpilqg.Dynamics",
                                            name, std::string(py::str(py::type::handle_of(made).attr("__name__")))));
            auto* dynamics = made.cast<Dynamics*>();
            (void)dynamics->parameters();  // a Python subclass's parameters(): names to finite numbers
            dynamics->set_noise_model(noise);
            return hold(made);
          };
          try {
            complete_system_entry(entry);
          } catch (const std::invalid_argument& e) {  // the builder's error, with the system's name
            throw InputError(e.what());
          }
          // What diagnosis can fit on any system: its parameters recalibrated, and the actuator gain.
          for (const Parameter& parameter : entry.parameters)
            entry.effects.push_back(recalibration_entry("param:" + parameter.name, parameter, false, false));
          entry.effects.push_back(actuator_gain_entry());
          SystemRegistry::instance().add(std::move(entry));
        },
        py::arg("name"), py::arg("builder"), py::arg("description") = "", R"(
Registers a system by name so that configs, solve, diagnose, plan and run can use it. Diagnosis can
fit its parameters (effects "param:<name>", from parameters()) and an actuator gain.
builder(preset: str, parameters: dict) -> a new gpilqg.Dynamics (a Python subclass, or any system);
it must raise for a parameter name it does not know. A name can be registered once per process.)");

  m.def("load_plugin", [](const std::string& path) { return load_plugin(path).systems; }, py::arg("path"),
        "Loads a plugin (a shared library built against gpilqg) and returns the names of the systems it registered.");

  py::class_<StepModel, std::shared_ptr<StepModel>>(m, "StepModel", R"(
A discrete-time model x' = phi(x, u) of a system at step dt: the integrator of the library (explicit
Euler or RK4 with sub-steps) or, for a MuJoCo model, MuJoCo's own.)")
      .def(py::init([](const py::object& system, double dt, const std::string& integrator, int substeps) {
             const auto parsed = parse_integrator(integrator);
             if (!parsed) throw InputError(fmt::format("integrator '{}': expected 'euler' or 'rk4'", integrator));
             DynamicsPtr dynamics = system_from_python(system, "StepModel");
             try {
               return std::const_pointer_cast<StepModel>(make_step_model(std::move(dynamics), *parsed, dt, substeps));
             } catch (const std::invalid_argument& e) {  // dt or substeps out of range
               throw InputError(fmt::format("StepModel: {}", e.what()));
             }
           }),
           py::arg("system"), py::arg("dt"), py::arg("integrator") = "rk4", py::arg("substeps") = 1,
           "system: a gpilqg.Dynamics or a registry name")
      .def_property_readonly("dt", &StepModel::dt)
      .def_property_readonly("state_dim", &StepModel::state_dim)
      .def_property_readonly("control_dim", &StepModel::control_dim)
      .def("step", [](const StepModel& s, const py::object& x_in, const py::object& u_in) {
             const Vector x = vector_argument(x_in, states_of(s), "StepModel.step", "x");
             const Vector u = vector_argument(u_in, controls_of(s), "StepModel.step", "u");
             Vector next(s.state_dim());
             {
               py::gil_scoped_release release;  // Python dynamics take it back per call
               s.step(x, u, next);
             }
             require_finite_result(next, "StepModel.step", "x'", at_finite_point(s));
             return next;
           }, py::arg("x"), py::arg("u"), "x' = phi(x, u), shape (n,)")
      .def("jacobians", [](const StepModel& s, const py::object& x_in, const py::object& u_in) {
             const std::string who = "StepModel.jacobians";
             const Vector x = vector_argument(x_in, states_of(s), who, "x");
             const Vector u = vector_argument(u_in, controls_of(s), who, "u");
             Vector next(s.state_dim());
             StepJacobians j;
             j.resize(s.state_dim(), s.control_dim());
             {
               py::gil_scoped_release release;
               s.step(x, u, next, &j);
             }
             require_finite_result(next, who, "x'", at_finite_point(s));
             require_finite_result(j.A, who, "A", at_finite_point(s));
             require_finite_result(j.B, who, "B", at_finite_point(s));
             return py::make_tuple(next, j.A, j.B);
           }, py::arg("x"), py::arg("u"), "(x' (n,), A = dphi/dx (n, n), B = dphi/du (n, m))");
}

}  // namespace gpilqg::python
