"""Hostile input at the package's boundary: every argument that crosses from Python (states, controls,
systems, files, callbacks' results) is checked for its type, its shape against the system and finite
values, and raises gpilqg.InputError naming the function, the argument and what was expected. A result
computed from finite arguments is never returned with NaN or inf in it. All cases are fast."""

import numpy as np
import pytest

import gpilqg

CARTPOLE_SWING_UP = {
    "system": {"name": "cartpole", "preset": "sim", "integrator": "rk4", "dt": 0.05},
    "problem": {"horizon": 10, "x0": [0.0, 0.0, 0.0, 0.0], "goal": [0.0, 0.0, np.pi, 0.0],
                "Q": [0.0, 0.0, 0.0, 0.0], "R": [0.1], "Qf": [100.0, 100.0, 1000.0, 100.0]},
    "solver": {"algorithm": "ilqr", "max_iterations": 3},
}


class Small(gpilqg.Dynamics):
    """Two states, one control; f and parameters() give what the test puts in."""

    def __init__(self, name="small", f=None, jacobians=None, parameters=None):
        super().__init__(name, states=["p", "v"], controls=["a"])
        self._f, self._jacobians, self._parameters = f, jacobians, parameters

    def f(self, x, u):
        return self._f(x, u) if self._f else np.array([x[1], u[0]])

    def parameters(self):
        return {} if self._parameters is None else self._parameters


class WithJacobians(Small):
    def jacobians(self, x, u):
        return self._jacobians(x, u)


@pytest.fixture(scope="module")
def policy():
    return gpilqg.solve(CARTPOLE_SWING_UP)["policy"]


@pytest.fixture(scope="module")
def measurements():
    return gpilqg.read_measurements(gpilqg_source("data/cartpole_hidden_friction.csv"), "cartpole")


def gpilqg_source(path):
    from conftest import SOURCE_DIR
    return str(SOURCE_DIR / path)


CARTPOLE = gpilqg.system("cartpole")
STEP = gpilqg.StepModel("cartpole", dt=0.05)
X4, U1 = np.zeros(4), np.ones(1)

# (case, call, message): every state or control argument of the bound functions, against the system.
ARRAY_ARGUMENTS = [
    ("derivatives: x too short", lambda: CARTPOLE.derivatives(np.array([1.0, 2.0, 3.0]), U1),
     r"Dynamics.derivatives: x has 3 entries; expected 4 \(the states of system 'cartpole'\)"),
    ("derivatives: x far too long", lambda: CARTPOLE.derivatives(np.ones(10**7), U1),
     r"Dynamics.derivatives: x has 10000000 entries; expected 4"),
    ("derivatives: u too long", lambda: CARTPOLE.derivatives(X4, np.ones(2)),
     r"Dynamics.derivatives: u has 2 entries; expected 1 \(the controls of system 'cartpole'\)"),
    ("xdot: x a str", lambda: CARTPOLE.xdot("abcd", U1), r"Dynamics.xdot: x is str; expected shape \(4,\)"),
    ("xdot: x None", lambda: CARTPOLE.xdot(None, U1), r"Dynamics.xdot: x is NoneType"),
    ("xdot: x 2-D", lambda: CARTPOLE.xdot(np.zeros((4, 1)), U1), r"Dynamics.xdot: x has shape \(4, 1\); expected"),
    ("xdot: x NaN", lambda: CARTPOLE.xdot(np.array([0.0, np.nan, 0.0, 0.0]), U1),
     r"Dynamics.xdot: x\[1\] = nan is not finite"),
    ("step: x too short", lambda: STEP.step(np.zeros(3), U1),
     r"StepModel.step: x has 3 entries; expected 4 \(the states of system 'cartpole'\)"),
    ("step: u inf", lambda: STEP.step(X4, np.array([np.inf])), r"StepModel.step: u\[0\] = inf is not finite"),
    ("jacobians: u empty", lambda: STEP.jacobians(X4, np.zeros(0)),
     r"StepModel.jacobians: u has 0 entries; expected 1 \(the controls of system 'cartpole'\)"),
    ("jacobians: x huge", lambda: STEP.jacobians(np.full(4, 1e308), U1),
     r"StepModel.jacobians: the result .* is not finite at these finite x and u \(the step of system 'cartpole'"),
    ("system: noise of the wrong size", lambda: gpilqg.system("cartpole", noise={"state": [0.1]}),
     r"system: noise\['state'\] has 1 entries; expected 4"),
    ("system: noise a str", lambda: gpilqg.system("cartpole", noise={"actuator_additive": "a"}),
     r"system: noise\['actuator_additive'\] is str"),
    ("system: a NaN parameter", lambda: gpilqg.system("cartpole", parameters={"cart_mass": np.nan}),
     r"system: parameters\['cart_mass'\] = nan is not finite"),
    ("StepModel: dt negative", lambda: gpilqg.StepModel("cartpole", dt=-1.0), r"StepModel: step length dt"),
]

# (case, call, message): systems, files and other arguments of the wrong type.
WRONG_TYPES = [
    ("StepModel: system None", lambda: gpilqg.StepModel(None, dt=0.05),
     r"StepModel: system is NoneType; expected a system name \(str\) or a gpilqg.Dynamics"),
    ("StepModel: system a number", lambda: gpilqg.StepModel(123, dt=0.05), r"StepModel: system is int"),
    ("MeasurementSet: system None", lambda: gpilqg.MeasurementSet(None, []), r"MeasurementSet: system is NoneType"),
    ("read_measurements: system None", lambda: gpilqg.read_measurements("x.csv", None),
     r"read_measurements: system is NoneType"),
    ("MeasurementSet: x a str", lambda: gpilqg.MeasurementSet("cartpole", [(np.arange(3.0), "x", np.zeros((3, 1)))]),
     r"MeasurementSet: episode 0: x must be an array of real numbers"),
    ("diagnose: data a number", lambda: gpilqg.diagnose("cartpole", 123),
     r"diagnose: data is int; expected a gpilqg.MeasurementSet or a measurement file path"),
    ("diagnose: system a number", lambda: gpilqg.diagnose(123, "data.csv"), r"diagnose: system is int"),
    ("solve: config a number", lambda: gpilqg.solve(123), r"solve: config is int; expected a file path or a dict"),
    ("solve: progress a number", lambda: gpilqg.solve(CARTPOLE_SWING_UP, progress=3),
     r"progress is int; expected a callable"),
    ("plan: data one path", lambda: gpilqg.plan(CARTPOLE_SWING_UP, data="log.h5"),
     r"plan: data is str; expected a list of file paths"),
    ("plan: a data entry a number", lambda: gpilqg.plan(CARTPOLE_SWING_UP, data=[1]), r"plan: data\[0\] is int"),
    ("plan: out a number", lambda: gpilqg.plan(CARTPOLE_SWING_UP, out=5), r"plan: out is int"),
    ("run: system a number", lambda: gpilqg.run(5), r"run: system is int; expected a system name"),
    ("run: backends a str", lambda: gpilqg.run("cartpole", backends="exact"), r"run: backends is str"),
    ("ResidualModel.fit: simulator None", lambda: gpilqg.ResidualModel.fit(None, gpilqg.MeasurementSet("cartpole", [])),
     r"ResidualModel.fit: simulator is None"),
    ("Dynamics: a unit not a str", lambda: gpilqg.Dynamics("d", states=[("x", 1)], controls=[]),
     r"Dynamics: states entry \('x', 1\) is not a name"),
]


@pytest.mark.parametrize("call,message", [c[1:] for c in ARRAY_ARGUMENTS + WRONG_TYPES],
                         ids=[c[0] for c in ARRAY_ARGUMENTS + WRONG_TYPES])
def test_a_bad_argument_raises_input_error_naming_it(call, message):
    with pytest.raises(gpilqg.InputError, match=message):
        call()


@pytest.mark.parametrize("x,message", [
    (np.array([0.0, 0.0, np.nan, 0.0]), r"Policy: x\[2\] = nan is not finite"),
    (np.zeros(3), r"Policy: x has 3 entries; expected 4 \(the states of the policy's system 'cartpole'\)"),
    ("x", r"Policy: x is str"),
], ids=["NaN state", "short state", "a str"])
def test_a_policy_refuses_a_bad_state(policy, x, message):
    with pytest.raises(gpilqg.InputError, match=message):
        policy(0, x)
    assert np.isfinite(policy(0, np.zeros(4))).all()


def test_the_residual_model_checks_its_arrays(measurements):
    simulator = gpilqg.StepModel("cartpole", dt=0.02, integrator="rk4", substeps=2)
    small = gpilqg.MeasurementSet("cartpole", [(e.t[:40], e.x[:40], e.u[:40]) for e in measurements.episodes[:1]])
    model = gpilqg.ResidualModel.fit(simulator, small, exact_points=30, restarts=0, max_evaluations=3)
    x, u = np.zeros((2, 4)), np.zeros((2, 1))
    for call, message in [
        (lambda: model.predict(x[:, :3], u), r"ResidualModel.predict: x has 3 columns; expected 4 \(the states of system 'cartpole'\)"),
        (lambda: model.predict(x, u[:1]), r"ResidualModel.predict: x has 2 rows and u 1"),
        (lambda: model.predict(np.full((2, 4), np.nan), u), r"ResidualModel.predict: x\[0, 0\] = nan is not finite"),
        (lambda: model.step(np.zeros(5), u[0]), r"StepModel.step: x has 5 entries; expected 4 \(the states of system 'cartpole'\)"),
        (lambda: gpilqg.ResidualModel.fit(simulator, small, observation_std=np.full(4, np.nan)),
         r"ResidualModel.fit: observation_std\[0\] = nan is not finite"),
        (lambda: gpilqg.ResidualModel.fit(gpilqg.StepModel("cartpole", dt=0.5), small),
         r"ResidualModel.fit: make_residual_data: episode 0 has dt = 0.02 s"),
    ]:
        with pytest.raises(gpilqg.InputError, match=message):
            call()


# (case, builder, message): what register_system's builder returns must be a gpilqg.Dynamics whose
# parameters() is a dict of names to finite numbers.
BUILDERS = [
    ("None", "hostile_none", lambda preset, parameters: None,
     r"register_system\('hostile_none'\): the builder returned NoneType; expected a new gpilqg.Dynamics"),
    ("a dict", "hostile_dict", lambda preset, parameters: {"f": 1},
     r"register_system\('hostile_dict'\): the builder returned dict"),
    ("NaN parameter", "hostile_nan", lambda preset, parameters: Small("p", parameters={"k": float("nan")}),
     r"Dynamics 'p': parameters\(\): 'k' = nan; expected a finite number"),
    ("parameters not a dict", "hostile_list", lambda preset, parameters: Small("p", parameters=[1.0]),
     r"Dynamics 'p': parameters\(\) returned list; expected a dict"),
    ("a key not a str", "hostile_key", lambda preset, parameters: Small("p", parameters={1: 1.0}),
     r"Dynamics 'p': parameters\(\): the key 1 is not a name"),
]


@pytest.mark.parametrize("name,builder,message", [b[1:] for b in BUILDERS], ids=[b[0] for b in BUILDERS])
def test_register_system_refuses_what_is_not_a_system(name, builder, message):
    with pytest.raises(gpilqg.InputError, match=message):
        gpilqg.register_system(name, builder)
    assert name not in gpilqg.systems()
    with pytest.raises(ValueError, match="unknown system '%s'" % name):
        gpilqg.StepModel(name, dt=0.05)


# (case, Python system, message): what f(x, u) and jacobians(x, u) return is checked like an argument.
CALLBACKS = [
    ("f returns a str", Small(f=lambda x, u: "ab"), r"Dynamics 'small': f\(x, u\) is str; expected shape \(2,\)"),
    ("f returns None", Small(f=lambda x, u: None), r"Dynamics 'small': f\(x, u\) is NoneType"),
    ("f too long", Small(f=lambda x, u: np.zeros(3)), r"Dynamics 'small': f\(x, u\) has 3 entries; expected 2"),
    ("f NaN", Small(f=lambda x, u: np.array([np.nan, 0.0])), r"Dynamics 'small': f\(x, u\)\[0\] = nan is not finite"),
    ("jacobians not a pair", WithJacobians(jacobians=lambda x, u: np.eye(2)),
     r"Dynamics 'small': jacobians\(x, u\) returned ndarray; expected a tuple \(fx, fu\)"),
    ("fu of the wrong shape", WithJacobians(jacobians=lambda x, u: (np.eye(2), np.zeros((1, 2)))),
     r"jacobians\(x, u\)\[1\] \(fu\) has shape \(1, 2\); expected shape \(2, 1\)"),
    ("fx a str", WithJacobians(jacobians=lambda x, u: ("fx", np.zeros((2, 1)))), r"jacobians\(x, u\)\[0\] \(fx\) is str"),
    ("fx inf", WithJacobians(jacobians=lambda x, u: (np.full((2, 2), np.inf), np.zeros((2, 1)))),
     r"jacobians\(x, u\)\[0\] \(fx\)\[0, 0\] = inf is not finite"),
]


@pytest.mark.parametrize("system,message", [c[1:] for c in CALLBACKS], ids=[c[0] for c in CALLBACKS])
def test_a_python_systems_results_are_checked(system, message):
    with pytest.raises(gpilqg.InputError, match=message):
        system.derivatives(np.zeros(2), np.zeros(1))
    with pytest.raises(gpilqg.InputError, match=message):
        gpilqg.StepModel(system, dt=0.05).jacobians(np.zeros(2), np.zeros(1))


def test_a_registered_python_system_that_returns_a_str_fails_in_solve_with_input_error():
    if "hostile_str" not in gpilqg.systems():
        gpilqg.register_system("hostile_str", lambda preset, parameters: Small("hostile_str", f=lambda x, u: "ab"))
    config = {"system": {"name": "hostile_str", "dt": 0.05},
              "problem": {"horizon": 5, "x0": [0.0, 0.0], "goal": [1.0, 0.0], "Q": [0.0, 0.0], "R": [0.1],
                          "Qf": [1.0, 1.0]}}
    with pytest.raises(gpilqg.InputError, match=r"Dynamics 'hostile_str': f\(x, u\) is str"):
        gpilqg.solve(config)
