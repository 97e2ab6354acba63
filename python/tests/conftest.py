"""Shared fixtures of the Python tests: the repository, the command-line program, the C++ cart-pole
written again in Python."""

import ctypes
import os
import pathlib
import subprocess

import numpy as np
import pytest

import gpilqg

SOURCE_DIR = pathlib.Path(os.environ.get("GPILQG_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CLI = os.environ.get("GPILQG_CLI", str(SOURCE_DIR / "build" / "experiments" / "gpilqg"))


def this_process_openblas_core():
    """The OpenBLAS kernels the gpilqg module runs on in this process (openblas_get_corename of the
    libblas.so.3 it loaded), or None when the BLAS is not OpenBLAS."""
    try:
        name = ctypes.CDLL("libblas.so.3").openblas_get_corename
    except (OSError, AttributeError):
        return None
    name.restype = ctypes.c_char_p
    return name().decode()


def cli(*arguments):
    """Runs the gpilqg program; returns (exit status, stdout, stderr). The program runs on the OpenBLAS
    kernels of this process (OPENBLAS_CORETYPE): the tests compare its results with the module's bit for
    bit, and another kernel set rounds differently (the program chooses wider kernels than OpenBLAS's
    own choice where that is a fallback, docs/building.md#blas, which a running Python cannot)."""
    env = dict(os.environ)
    core = this_process_openblas_core()
    if core and "OPENBLAS_CORETYPE" not in env:
        env["OPENBLAS_CORETYPE"] = core
    r = subprocess.run([CLI, *map(str, arguments)], capture_output=True, text=True, env=env)
    return r.returncode, r.stdout, r.stderr


class PythonCartPole(gpilqg.Dynamics):
    """The cart-pole of core/src/cartpole.cpp (docs/formats.md#systems-and-their-names), in NumPy:
    M(q) q_ddot = h(q, q_dot, u) with M = [[mc + mp, mp l cos], [mp l cos, mp l^2]],
    h = (u + mp l sin theta_dot^2, -mp g l sin)."""

    def __init__(self, name="python_cartpole", cart_mass=1.0, pole_mass=1.0, pole_length=1.0, gravity=9.81):
        super().__init__(name, states=[("x", "m"), ("x_dot", "m/s"), ("theta", "rad"), ("theta_dot", "rad/s")],
                         controls=[("force", "N")])
        self.p = dict(cart_mass=cart_mass, pole_mass=pole_mass, pole_length=pole_length, gravity=gravity)

    def parameters(self):
        return dict(self.p)

    def accelerations(self, x, u):
        """(M^-1 (2, 2), q_ddot (2,)) at (x, u)."""
        mc, mp, l, g = (self.p[k] for k in ("cart_mass", "pole_mass", "pole_length", "gravity"))
        s, c = np.sin(x[2]), np.cos(x[2])
        det = mp * l * l * (mc + mp * s * s)
        M_inv = np.array([[mp * l * l, -mp * l * c], [-mp * l * c, mc + mp]]) / det
        h = np.array([u[0] + mp * l * s * x[3] ** 2, -mp * g * l * s])
        return M_inv, M_inv @ h

    def f(self, x, u):
        _, q_ddot = self.accelerations(x, u)
        return np.array([x[1], q_ddot[0], x[3], q_ddot[1]])


def build_python_cartpole(preset, parameters):
    """The registry builder of PythonCartPole: the C++ cart-pole's presets and parameter names."""
    values = dict(cart_mass=1.0, pole_mass=1.0, pole_length=1.0, gravity=9.81)
    if preset == "real":
        values["pole_length"] = 1.3
    for name, value in parameters.items():
        if name not in values:
            raise ValueError("unknown parameter '%s'" % name)
        values[name] = value
    return PythonCartPole(**values)


@pytest.fixture(scope="session")
def python_cartpole():
    """PythonCartPole registered as "python_cartpole" (once per process)."""
    if "python_cartpole" not in gpilqg.systems():
        gpilqg.register_system("python_cartpole", build_python_cartpole, "the cart-pole in NumPy")
    return "python_cartpole"
