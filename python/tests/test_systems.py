"""Systems from Python: the library's, and dynamics written in Python, which must agree with the C++
cart-pole and work in the library's solvers and diagnosis."""

import numpy as np
import pytest

import gpilqg
from conftest import PythonCartPole

RNG = np.random.default_rng(4)


def random_points(count):
    return [(RNG.normal(size=4) * [1, 2, 3, 4], RNG.normal(size=1) * 10) for _ in range(count)]


def test_builtin_system_names_shapes_and_parameters():
    s = gpilqg.system("cartpole", preset="real", parameters={"cart_mass": 2.0})
    assert s.state_names == ["x", "x_dot", "theta", "theta_dot"]
    assert s.control_names == ["force"]
    assert (s.state_dim, s.control_dim) == (4, 1)
    assert s.parameter_values == {"cart_mass": 2.0, "gravity": 9.81, "pole_length": 1.3, "pole_mass": 1.0}
    xdot, fx, fu = s.derivatives(np.zeros(4), np.ones(1))
    assert xdot.shape == (4,) and fx.shape == (4, 4) and fu.shape == (4, 1)
    assert xdot.dtype == np.float64
    with pytest.raises(ValueError, match="pole_lenght"):
        gpilqg.system("cartpole", parameters={"pole_lenght": 1.0})
    with pytest.raises(ValueError, match="unknown system|no_such_system"):
        gpilqg.system("no_such_system")


def test_python_cartpole_equals_the_cpp_cartpole_to_1e_12():
    cpp, python = gpilqg.system("cartpole"), PythonCartPole()
    for x, u in random_points(200):
        np.testing.assert_allclose(python.xdot(x, u), cpp.xdot(x, u), rtol=1e-12, atol=1e-12)


def test_python_dynamics_jacobians_by_central_differences():
    cpp, python = gpilqg.system("cartpole"), PythonCartPole()
    for x, u in random_points(50):
        _, fx, fu = python.derivatives(x, u)
        _, fx_ref, fu_ref = cpp.derivatives(x, u)
        np.testing.assert_allclose(fx, fx_ref, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(fu, fu_ref, rtol=1e-6, atol=1e-6)


def test_python_dynamics_analytic_jacobians_are_used_when_defined():
    class Linear(gpilqg.Dynamics):
        def __init__(self):
            super().__init__("linear", states=["p", "v"], controls=["a"])

        def f(self, x, u):
            return np.array([x[1], u[0] - 0.5 * x[1]])

        def jacobians(self, x, u):
            return np.array([[0.0, 1.0], [0.0, -0.5]]), np.array([[0.0], [1.0]])

    xdot, fx, fu = Linear().derivatives(np.array([1.0, 2.0]), np.array([3.0]))
    np.testing.assert_array_equal(xdot, [2.0, 2.0])
    np.testing.assert_array_equal(fx, [[0.0, 1.0], [0.0, -0.5]])
    np.testing.assert_array_equal(fu, [[0.0], [1.0]])


def test_system_parameters_and_model_files_are_checked_where_read():
    # Each parameter within a million times its model's own value; an empty model path names no file.
    with pytest.raises(gpilqg.InputError, match=r"pole_length = 1e\+300; expected a finite value in \[1e-06, 1e\+06\] m"):
        gpilqg.system("cartpole", parameters={"pole_length": 1e300})
    with pytest.raises(gpilqg.InputError, match=r"'' \(an empty path\): names no file"):
        gpilqg.system("cartpole", model="")


def test_python_dynamics_errors_are_python_exceptions():
    class WrongShape(gpilqg.Dynamics):
        def __init__(self):
            super().__init__("wrong", states=["p", "v"], controls=["a"])

        def f(self, x, u):
            return np.zeros(3)

    with pytest.raises(gpilqg.InputError, match=r"Dynamics 'wrong': f\(x, u\) has 3 entries; expected 2"):
        WrongShape().xdot(np.zeros(2), np.zeros(1))

    class Raises(gpilqg.Dynamics):
        def __init__(self):
            super().__init__("raises", states=["p"], controls=["a"])

        def f(self, x, u):
            raise ZeroDivisionError("inside f")

    with pytest.raises(ZeroDivisionError, match="inside f"):
        Raises().xdot(np.zeros(1), np.zeros(1))


def test_step_model_of_a_python_system_equals_the_cpp_one():
    cpp = gpilqg.StepModel("cartpole", dt=0.05, integrator="rk4", substeps=10)
    python = gpilqg.StepModel(PythonCartPole(), dt=0.05, integrator="rk4", substeps=10)
    for x, u in random_points(20):
        np.testing.assert_allclose(python.step(x, u), cpp.step(x, u), rtol=1e-12, atol=1e-12)
        _, A, B = python.jacobians(x, u)
        _, A_ref, B_ref = cpp.jacobians(x, u)
        np.testing.assert_allclose(A, A_ref, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(B, B_ref, rtol=1e-6, atol=1e-6)


SWING_UP = {
    "system": {"name": "cartpole", "preset": "sim", "integrator": "rk4", "dt": 0.05},
    "problem": {"horizon": 40, "x0": [0.0, 0.0, 0.0, 0.0], "goal": [0.0, 0.0, np.pi, 0.0],
                "Q": [0.0, 0.0, 0.0, 0.0], "R": [0.1], "Qf": [100.0, 100.0, 1000.0, 100.0]},
    "solver": {"algorithm": "ilqr", "max_iterations": 200, "tolerance": 1e-10},
}


def test_a_registered_python_system_solves_like_the_cpp_one(python_cartpole):
    cpp = gpilqg.solve(SWING_UP)
    config = {**SWING_UP, "system": {**SWING_UP["system"], "name": python_cartpole}}
    python = gpilqg.solve(config)
    assert cpp["converged"] and python["converged"]
    # Central-difference Jacobians steer the Python solve; the optimum is the same.
    assert abs(python["cost"] - cpp["cost"]) <= 1e-6 * cpp["cost"]
    np.testing.assert_allclose(python["x"][-1], cpp["x"][-1], atol=1e-3)
    assert python["policy"].system == python_cartpole


def test_register_system_refuses_a_second_registration(python_cartpole):
    with pytest.raises(ValueError, match="python_cartpole"):
        gpilqg.register_system(python_cartpole, lambda preset, parameters: PythonCartPole())


def test_a_plugins_systems_are_systems_of_the_package():
    import os
    plugin = os.environ.get("GPILQG_ACROBOT_PLUGIN")
    if not plugin:
        pytest.skip("GPILQG_ACROBOT_PLUGIN is set by ctest (the example plugin built with the tests)")
    if "acrobot" not in gpilqg.systems():
        assert gpilqg.load_plugin(plugin) == ["acrobot"]
    acrobot = gpilqg.system("acrobot")
    assert acrobot.state_dim == 4 and acrobot.control_dim == 1
    assert acrobot.xdot(np.zeros(4), np.zeros(1)).shape == (4,)


def test_a_mujoco_model_file_is_a_system():
    from conftest import SOURCE_DIR
    arm = gpilqg.system(str(SOURCE_DIR / "data" / "two_link_arm.xml"))
    assert arm.state_names == ["shoulder", "elbow", "shoulder_dot", "elbow_dot"]
    step = gpilqg.StepModel(arm, dt=0.05)
    x_next, A, B = step.jacobians(np.zeros(4), np.ones(2))
    assert x_next.shape == (4,) and A.shape == (4, 4) and B.shape == (4, 2)


def test_a_passive_system_has_no_controls():
    from conftest import SOURCE_DIR
    pendulum = gpilqg.system(str(SOURCE_DIR / "data" / "pendulum_passive.xml"))
    assert pendulum.control_dim == 0 and pendulum.control_names == []
    x_next, A, B = gpilqg.StepModel(pendulum, dt=0.02).jacobians(np.array([0.5, 0.0]), np.zeros(0))
    assert x_next[1] < 0.0 and B.shape == (2, 0)

    class Decay(gpilqg.Dynamics):  # a Python system without controls
        def __init__(self):
            super().__init__("python_decay", states=[("v", "m/s")], controls=[])

        def f(self, x, u):
            return -0.5 * x

    decay = Decay()
    assert decay.control_dim == 0
    np.testing.assert_allclose(decay.xdot(np.array([2.0]), np.zeros(0)), [-1.0])


def test_a_urdf_robot_gets_one_motor_per_joint():
    from conftest import SOURCE_DIR
    arm = gpilqg.system(str(SOURCE_DIR / "data" / "two_link_arm.urdf"))
    assert arm.control_names == ["shoulder_motor", "elbow_motor"]
