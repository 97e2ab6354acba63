"""How much slower dynamics written in Python are than C++, measured side by side in one run.

The cart-pole swing-up of examples/robot_loop (iLQR, horizon 60, RK4 with 10 sub-steps at 0.05 s)
solved on the C++ cart-pole and on the same equations in NumPy (python/tests/conftest.py), with the
Python system's Jacobians by central differences (the default) and analytic ones; plus one RK4 step.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_dynamics.py
"""

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python", "tests"))
import gpilqg  # noqa: E402
from conftest import PythonCartPole, build_python_cartpole  # noqa: E402


class AnalyticPythonCartPole(PythonCartPole):
    """PythonCartPole with Jacobians from the C++ cart-pole's formulas (no finite differences)."""

    def jacobians(self, x, u):
        mp, l, g = (self.p[k] for k in ("pole_mass", "pole_length", "gravity"))
        s, c = np.sin(x[2]), np.cos(x[2])
        M_inv, q_ddot = self.accelerations(x, u)
        dM = np.array([[0.0, -mp * l * s], [-mp * l * s, 0.0]])
        d_theta = M_inv @ (np.array([mp * l * c * x[3] ** 2, -mp * g * l * c]) - dM @ q_ddot)
        d_theta_dot = M_inv @ np.array([2.0 * mp * l * s * x[3], 0.0])
        fx = np.zeros((4, 4))
        fx[0, 1] = fx[2, 3] = 1.0
        fx[1, 2], fx[3, 2] = d_theta
        fx[1, 3], fx[3, 3] = d_theta_dot
        fu = np.zeros((4, 1))
        fu[1, 0], fu[3, 0] = M_inv[:, 0]
        return fx, fu


def problem(name):
    return {"system": {"name": name, "preset": "sim", "integrator": "rk4", "substeps": 10, "dt": 0.05},
            "problem": {"horizon": 60, "x0": [0.0, 0.0, 0.7853981633974483, 0.0],
                        "goal": [0.0, 0.0, np.pi, 0.0], "Q": [0.0] * 4, "R": [0.1], "Qf": [100.0, 100.0, 1000.0, 100.0],
                        "u_min": [-25.0], "u_max": [25.0]},
            "solver": {"algorithm": "ilqr", "max_iterations": 150, "tolerance": 1e-6, "gradient_tolerance": 1e-4}}


def best_of(repeats, call):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - start)
    return min(times), result


def main():
    gpilqg.register_system("bench_python_cartpole", build_python_cartpole)
    gpilqg.register_system("bench_python_cartpole_analytic", lambda preset, parameters: AnalyticPythonCartPole(
        **{**build_python_cartpole(preset, parameters).p}))
    rows = []
    reference = None
    for label, name in (("C++ cartpole", "cartpole"), ("Python, central differences", "bench_python_cartpole"),
                        ("Python, analytic Jacobians", "bench_python_cartpole_analytic")):
        seconds, result = best_of(3 if name == "cartpole" else 1, lambda: gpilqg.solve(problem(name)))
        reference = reference or seconds
        rows.append((label, seconds, result["iterations"], result["cost"], seconds / reference))
    print("iLQR swing-up, horizon 60, RK4 x 10 sub-steps (best of runs):")
    print("%-30s %10s %10s %12s %8s" % ("system", "time [s]", "iterations", "cost", "ratio"))
    for label, seconds, iterations, cost, ratio in rows:
        print("%-30s %10.3f %10d %12.6f %8.1f" % (label, seconds, iterations, cost, ratio))
    x, u = np.array([0.1, 0.2, 0.3, 0.4]), np.array([1.0])
    for label, system in (("C++", "cartpole"), ("Python", PythonCartPole())):
        model = gpilqg.StepModel(system, dt=0.05, integrator="rk4", substeps=10)
        seconds, _ = best_of(5, lambda: [model.step(x, u) for _ in range(200)])
        print("one RK4 step (10 sub-steps), %-6s: %8.1f us" % (label, 1e6 * seconds / 200))


if __name__ == "__main__":
    main()
