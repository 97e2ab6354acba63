"""gpilqg: GP-corrected simulators and Robust-iLQG, from Python.

The C++ library through pybind11, with NumPy arrays in and out (docs/python.md):

- systems: ``system(name)``, ``StepModel``, ``Dynamics`` (subclass it to write dynamics in Python),
  ``register_system``, ``load_plugin``;
- data: ``MeasurementSet`` (from arrays, ``from_dataframe``, ``read_measurements``);
- GP backends as estimators, and the residual model;
- workflows: ``diagnose``, ``solve``, ``plan`` (returns a ``Policy``), ``run`` (returns the result file).

Long calls release the GIL, pass progress lines to ``progress(line)`` when given, and stop on Ctrl-C
(KeyboardInterrupt) within one iteration.
"""

import os as _os

from ._gpilqg import *  # noqa: F401,F403
from ._gpilqg import __version__  # noqa: F401
from . import _gpilqg
from ._config import to_toml as _to_toml
from ._dataframes import install as _install_dataframes

_install_dataframes(_gpilqg.MeasurementSet)


def _config_source(config):
    """A config as the extension takes it: a file path, or TOML text (a dict is written as TOML)."""
    if config is None:
        return None
    if isinstance(config, dict):
        return _to_toml(config)
    if isinstance(config, (str, _os.PathLike)):
        return _os.fspath(config)
    raise TypeError("config: expected a file path or a dict of TOML tables, got %s" % type(config).__name__)


def solve(config, progress=None):
    """One trajectory-optimisation problem (the ``gpilqg solve`` schema, DESIGN.md section 8).

    config: a TOML file or a dict of its tables, e.g. ``{"system": {...}, "problem": {...}}``.
    Returns a dict: cost, expected_cost, termination, converged, iterations, gradient_norm,
    solve_time_s, x (T+1, n), u (T, m), and policy (a Policy).
    """
    return _gpilqg._solve(_config_source(config), progress)


def plan(config, data=(), previous=None, out=None, seed=1, progress=None):
    """One round of Algorithm 1 on measurement files, as ``gpilqg plan`` (docs/real-robot.md).

    config: the plan config (file or dict); data: measurement files, oldest first; previous: the
    previous round's policy file; out: where to write the policy file (optional); seed: the GP fit's.
    Returns a Policy that can act: ``policy(t, x)``.
    """
    files = [_os.fspath(f) for f in data]
    return _gpilqg._plan(_config_source(config), files, None if previous is None else _os.fspath(previous),
                         None if out is None else _os.fspath(out), seed, progress)


def run(system, config=None, seeds=1, first_seed=1, iterations=None, backends=(), out=None, progress=None):
    """The paper's experiment, as ``gpilqg run``: ilqg_real, ilqg_sim, gp_ilqg and pddp over seeds.

    config: overrides of the embedded defaults (file or dict); out: the result file (default
    out/run_<system>.h5). Returns the result file's path (layout: README, results file).
    """
    if out is None:
        out = _os.path.join("out", "run_%s.h5" % _os.path.basename(system))
    return _gpilqg._run(system, _config_source(config), seeds, first_seed, iterations, list(backends),
                        _os.fspath(out), progress)
