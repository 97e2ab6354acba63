"""gpilqg: GP-corrected simulators and Robust-iLQG, from Python.

The C++ library through pybind11, with NumPy arrays in and out (docs/python.md):

- systems: ``system(name)``, ``StepModel``, ``Dynamics`` (subclass it to write dynamics in Python),
  ``register_system``, ``load_plugin``;
- data: ``MeasurementSet`` (from arrays, ``from_dataframe``, ``read_measurements``);
- GP backends as estimators, and the residual model;
- workflows: ``diagnose``, ``solve``, ``plan`` (returns a ``Policy``), ``run`` (returns the result file).

Long calls release the GIL, pass progress lines to ``progress(line)`` when given, and stop on Ctrl-C
(KeyboardInterrupt) within one iteration. Arguments are checked where they enter: a wrong type, a
shape that does not fit the system, or a non-finite value raises ``InputError`` naming the argument.
"""

import os as _os

from ._gpilqg import *  # noqa: F401,F403
from ._gpilqg import __version__  # noqa: F401
from . import _gpilqg
from ._config import to_toml as _to_toml
from ._dataframes import install as _install_dataframes

_install_dataframes(_gpilqg.MeasurementSet)


def _config_source(who, config):
    """A config as the extension takes it: a file path, or TOML text (a dict is written as TOML)."""
    if config is None:
        return None
    if isinstance(config, dict):
        return _to_toml(config)
    if isinstance(config, (str, _os.PathLike)):
        return _os.fspath(config)
    raise InputError("%s: config is %s; expected a file path or a dict of TOML tables" % (who, type(config).__name__))


def _path(who, name, value, optional=False):
    """A file path argument (str or os.PathLike) as str; None only when `optional`."""
    if optional and value is None:
        return None
    if isinstance(value, (str, _os.PathLike)):
        return _os.fspath(value)
    raise InputError("%s: %s is %s; expected a file path (str or os.PathLike)%s"
                     % (who, name, type(value).__name__, " or None" if optional else ""))


def _flag(who, name, value):
    """A yes/no argument: True or False (a NumPy bool too), never a string or a number taken for one."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise InputError("%s: %s is %r; expected True or False" % (who, name, value))


def _paths(who, name, values):
    """A list of file paths; one path alone is not taken for the list of its characters."""
    if isinstance(values, (str, bytes, _os.PathLike)) or not hasattr(values, "__iter__"):
        raise InputError("%s: %s is %s; expected a list of file paths" % (who, name, type(values).__name__))
    return [_path(who, "%s[%d]" % (name, i), v) for i, v in enumerate(values)]


def solve(config, progress=None):
    """One trajectory-optimisation problem (the ``gpilqg solve`` schema, docs/formats.md).

    config: a TOML file or a dict of its tables, e.g. ``{"system": {...}, "problem": {...}}``.
    Returns a dict: cost, expected_cost, termination, converged, iterations, gradient_norm,
    solve_time_s, x (T+1, n), u (T, m), policy (a Policy), and start: "the usual start", or the
    plan on the system's preset when [system] model is a richer model and the solve from that
    plan cost less (docs/solvers.md, "Plans that never lose").
    """
    return _gpilqg._solve(_config_source("solve", config), progress)


def plan(config, data=(), previous=None, out=None, seed=1, diagnose=False, write_model=None, progress=None):
    """One round of Algorithm 1 on measurement files, as ``gpilqg plan`` (docs/real-robot.md).

    config: the plan config (file or dict; ``[system] model`` names a model file of ``diagnose`` as the
    simulator); data: measurement files, oldest first; previous: the previous round's policy file
    (its controls and its policy replayed with its feedback are starts of the solve, its GP the fit's);
    out: where to write the policy file (optional); seed: the GP fit's; diagnose: diagnose the data
    first and, when the verdict is "explained", plan on the diagnosed model (``plan --diagnose``);
    write_model: with diagnose, where to write the diagnosed model file.
    Returns a Policy that can act: ``policy(t, x)``; ``policy.diagnosis`` is the diagnosis's verdict,
    reason and model (None without diagnose).
    """
    if config is None:
        raise InputError("plan: config is None; expected a file path or a dict of TOML tables")
    return _gpilqg._plan(_config_source("plan", config), _paths("plan", "data", data),
                         _path("plan", "previous", previous, optional=True), _path("plan", "out", out, optional=True),
                         seed, _flag("plan", "diagnose", diagnose), _path("plan", "write_model", write_model, optional=True),
                         progress)


def run(system, config=None, seeds=1, first_seed=1, iterations=None, backends=(), out=None, progress=None):
    """The paper's experiment, as ``gpilqg run``: ilqg_real, ilqg_sim, gp_ilqg and pddp over seeds.

    config: overrides of the embedded defaults (file or dict); out: the result file (default
    out/run_<system>.h5). Returns the result file's path (layout: README, results file).
    """
    if not isinstance(system, str):
        raise InputError("run: system is %s; expected a system name (str)" % type(system).__name__)
    if out is None:
        out = _os.path.join("out", "run_%s.h5" % _os.path.basename(system))
    if isinstance(backends, str) or not hasattr(backends, "__iter__"):
        raise InputError("run: backends is %s; expected a list of GP backend names" % type(backends).__name__)
    return _gpilqg._run(system, _config_source("run", config), seeds, first_seed, iterations, list(backends),
                        _path("run", "out", out), progress)
