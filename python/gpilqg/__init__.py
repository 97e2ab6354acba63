"""gpilqg: GP-corrected simulators and Robust-iLQG, from Python.

The C++ library (systems, measurement data, GP backends, DDP solvers, model diagnosis, Algorithm 1)
through pybind11, with NumPy arrays in and out. See docs/python.md.
"""

from ._gpilqg import *  # noqa: F401,F403
from ._gpilqg import __version__  # noqa: F401
