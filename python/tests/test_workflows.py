"""diagnose, solve, plan and run from Python are the commands' own code: the same numbers as the
command line, progress lines, Ctrl-C within one iteration, and Python-defined systems in them."""

import _thread
import json
import threading
import time

import h5py
import numpy as np
import pytest

import gpilqg
from conftest import SOURCE_DIR, cli

PLAN = {
    "system": {"name": "cartpole", "preset": "sim", "integrator": "rk4", "substeps": 10, "dt": 0.05},
    "noise": {"actuator_multiplicative": [0.02]},
    "problem": {"horizon": 15, "x0": [0.0, 0.0, 0.3, 0.0], "goal": [0.0, 0.0, 0.0, 0.0],
                "Q": [1.0, 1.0, 1.0, 1.0], "R": [0.1], "Qf": [10.0, 10.0, 10.0, 10.0],
                "u_min": [-25.0], "u_max": [25.0]},
    "solver": {"max_iterations": 30},
    "gp": {"exact_points": 40, "restarts": 0, "max_evaluations": 40},
}


def write_toml(path, config):
    from gpilqg._config import to_toml
    path.write_text(to_toml(config))
    return path


def test_solve_equals_the_command_line(tmp_path):
    config = {k: PLAN[k] for k in ("system", "noise", "problem")}
    config["solver"] = {"algorithm": "ilqg", "max_iterations": 100}
    status, out, err = cli("solve", write_toml(tmp_path / "solve.toml", config), "--json")
    assert status == 0, err
    expected = json.loads(out)
    r = gpilqg.solve(config)
    assert r["cost"] == expected["cost"]
    assert r["iterations"] == expected["iterations"]
    assert r["termination"] == expected["termination"]
    np.testing.assert_array_equal(r["u"], np.array(expected["u"]))
    assert r["x"].shape == (16, 4) and r["u"].shape == (15, 1)
    p = r["policy"]
    assert p.K.shape == (15, 1, 4) and p.x_bar.shape == (16, 4)
    assert p(0, r["x"][0]) == pytest.approx(r["u"][0], abs=1e-12)


def test_solve_reports_progress_and_a_raising_callback_stops_it():
    lines = []
    gpilqg.solve({**PLAN, "solver": {"algorithm": "ilqg"}, "gp": None} if False else
                 {k: PLAN[k] for k in ("system", "noise", "problem")}, progress=lines.append)
    assert lines and lines[0].startswith("iteration 1: cost")

    def stop(line):
        if line.startswith("iteration 3"):
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        gpilqg.solve({k: PLAN[k] for k in ("system", "noise", "problem")}, progress=stop)


def test_plan_equals_the_command_line_and_its_policy_acts(tmp_path):
    config = write_toml(tmp_path / "plan.toml", PLAN)
    assert cli("plan", config, "--out", tmp_path / "p0.h5")[0] == 0
    status, _, err = cli("rollout", "--system", "cartpole", "--policy", tmp_path / "p0.h5", "--episodes", "2",
                         "--exploration", "2", "--observation-noise", "0.001", "--out", tmp_path / "d0.h5")
    assert status == 0, err
    status, _, err = cli("plan", config, "--data", tmp_path / "d0.h5", "--previous", tmp_path / "p0.h5",
                         "--seed", "3", "--out", tmp_path / "p1_cli.h5")
    assert status == 0, err
    policy = gpilqg.plan(PLAN, data=[tmp_path / "d0.h5"], previous=tmp_path / "p0.h5", seed=3,
                         out=tmp_path / "p1_python.h5")
    assert policy.round == 1 and policy.has_model
    with h5py.File(tmp_path / "p1_cli.h5") as a, h5py.File(tmp_path / "p1_python.h5") as b:
        for name in ("x_bar", "u_bar", "K"):
            np.testing.assert_array_equal(a["policy"][name][()], b["policy"][name][()])
        np.testing.assert_array_equal(a["policy"]["K"][()], policy.K)
        assert "model" in b
    rng = np.random.default_rng(1)
    for _ in range(100):
        t = int(rng.integers(0, 15))
        x = policy.x_bar[t] + rng.normal(size=4)
        u = np.clip(policy.u_bar[t] + policy.K[t] @ (x - policy.x_bar[t]), policy.u_min, policy.u_max)
        np.testing.assert_allclose(policy(t, x), u, rtol=1e-12, atol=1e-12)
    with pytest.raises(IndexError):
        policy(15, np.zeros(4))


WORLD = """[model]
system = "cartpole"
preset = "real"
[effects]
cart_coulomb_friction = { mu = 3.0, v0 = 0.05 }
"""


def test_plan_diagnose_equals_the_command_line_and_the_model_is_a_simulator(tmp_path):
    # A world with a longer pole and cart friction; plan --diagnose on its log, from the command line
    # and from Python: the same diagnosed model file and policy. Sixteen rollouts: the held-out test needs
    # about ten batches of ten rows to call a finding.
    (tmp_path / "world.toml").write_text(WORLD)
    config = write_toml(tmp_path / "plan.toml", PLAN)
    assert cli("plan", config, "--out", tmp_path / "p0.h5")[0] == 0
    status, _, err = cli("rollout", "--system", "cartpole", "--world-model", tmp_path / "world.toml", "--policy",
                         tmp_path / "p0.h5", "--episodes", "16", "--exploration", "8", "--observation-noise", "0.001",
                         "--seed", "3", "--out", tmp_path / "d0.h5")
    assert status == 0, err
    status, out, err = cli("plan", config, "--data", tmp_path / "d0.h5", "--diagnose", "--write-model",
                           tmp_path / "F_cli.toml", "--out", tmp_path / "p1_cli.h5")
    assert status == 0, err
    policy = gpilqg.plan(PLAN, data=[tmp_path / "d0.h5"], diagnose=True, write_model=tmp_path / "F.toml",
                         out=tmp_path / "p1.h5")
    assert policy.diagnosis["verdict"] == "explained" and policy.diagnosis["adopted"]
    assert any("cart_coulomb_friction" in change for change in policy.diagnosis["changes"])
    cli_model = (tmp_path / "F_cli.toml").read_text()
    assert cli_model.split("\n", 1)[1] == (tmp_path / "F.toml").read_text().split("\n", 1)[1]  # but the comment
    assert policy.simulator_model == policy.diagnosis["model"]
    with h5py.File(tmp_path / "p1_cli.h5") as a:
        np.testing.assert_array_equal(a["policy"]["K"][()], policy.K)
    # The model file as a system: its step is the diagnosed simulator's, not the bare preset's.
    diagnosed = gpilqg.system("cartpole", model=tmp_path / "F.toml")
    bare = gpilqg.system("cartpole")
    x, u = np.array([0.0, 0.5, 0.2, 0.0]), np.array([1.0])
    assert abs(diagnosed.xdot(x, u)[1] - bare.xdot(x, u)[1]) > 0.5  # the 3 N Coulomb friction on the cart
    with pytest.raises(gpilqg.InputError, match="model.system"):
        (tmp_path / "q.toml").write_text('[model]\nsystem = "quadrotor"\n')
        gpilqg.system("cartpole", model=tmp_path / "q.toml")


def test_plan_errors_are_input_errors_with_the_commands_messages(tmp_path):
    with pytest.raises(gpilqg.InputError, match="solver.algorithm"):
        gpilqg.plan({**PLAN, "solver": {"algorithm": "ilqr"}})
    with pytest.raises(gpilqg.InputError, match="gp.points"):
        gpilqg.plan({**PLAN, "gp": {"points": 3}})
    with pytest.raises(gpilqg.InputError, match="plan: diagnose is 'yes'; expected True or False"):
        gpilqg.plan(PLAN, diagnose="yes")
    with pytest.raises(gpilqg.InputError, match="diagnose: no measurement files to diagnose"):
        gpilqg.plan(PLAN, diagnose=True)
    # An output over an input is refused before any work: the config itself, the model file it names,
    # a data file; and a file of the wrong format, as the command line refuses them.
    (tmp_path / "sm.toml").write_text('[model]\nsystem = "cartpole"\npreset = "sim"\n')
    named = {**PLAN, "system": {k: v for k, v in PLAN["system"].items() if k != "preset"}}
    named["system"]["model"] = "sm.toml"
    config = write_toml(tmp_path / "plan.toml", named)
    before = {f: (tmp_path / f).read_bytes() for f in ("plan.toml", "sm.toml")}
    with pytest.raises(gpilqg.InputError, match="plan: write_model .*plan.toml: is the same file as config"):
        gpilqg.plan(config, diagnose=True, write_model=config, out=tmp_path / "p.h5")
    with pytest.raises(gpilqg.InputError, match="is the same file as the config's system.model"):
        gpilqg.plan(config, diagnose=True, write_model=tmp_path / "sm.toml", out=tmp_path / "p.h5")
    with pytest.raises(gpilqg.InputError, match="plan: out .*plan.toml: is the same file as config"):
        gpilqg.plan(config, out=config)
    with pytest.raises(gpilqg.InputError, match="expected a name ending in .h5 or .hdf5"):
        gpilqg.plan(config, out=tmp_path / "p.csv")
    assert before == {f: (tmp_path / f).read_bytes() for f in ("plan.toml", "sm.toml")}
    assert not (tmp_path / "p.h5").exists()


RUN = {
    "noise": {"actuator_multiplicative": [0.02], "observation": [0.001] * 4},
    "loop": {"iterations": 2, "rollouts": 1, "exploration": [2.0], "policy_tolerance": 0.0, "evaluation_rollouts": 1},
    "gp": {"exact_points": 40, "restarts": 0, "max_evaluations": 40},
    "solver": {"max_iterations": 30},
    "pddp": {"enabled": False},
    "tasks": [{"name": "first", "x0": [0.0, 0.0, 0.3, 0.0], "goal": [0.0, 0.0, 0.0, 0.0], "horizon": 15,
               "Q": [1.0] * 4, "R": [0.1], "Qf": [10.0] * 4, "track_line": False, "transfer": False}],
}


def test_run_writes_the_commands_result_file(tmp_path):
    status, _, err = cli("run", "cartpole", "--config", write_toml(tmp_path / "run.toml", RUN), "--seeds", "1",
                         "--out", tmp_path / "cli.h5", "--no-plots")
    assert status == 0, err
    lines = []
    path = gpilqg.run("cartpole", RUN, out=tmp_path / "python.h5", progress=lines.append)
    assert path == str(tmp_path / "python.h5")
    assert any("gp_ilqg iteration 2/2" in line for line in lines)
    with h5py.File(tmp_path / "cli.h5") as a, h5py.File(path) as b:
        for k in range(3):
            np.testing.assert_array_equal(a["first/gp_ilqg/iter_%d/u" % k][()], b["first/gp_ilqg/iter_%d/u" % k][()])
        np.testing.assert_array_equal(a["first/gp_ilqg/cost"][()], b["first/gp_ilqg/cost"][()])


def test_ctrl_c_stops_a_run_within_one_iteration(tmp_path):
    # Ctrl-C arrives from another thread while the run computes without the GIL (as a terminal's
    # SIGINT does), 0.2 s after the first iteration; the run has 40 iterations of ~0.1 s or more.
    lines, sent = [], {}

    def progress(line):
        lines.append((time.monotonic(), line))
        if len(lines) == 1:
            def fire():
                sent["at"] = time.monotonic()
                _thread.interrupt_main()
            threading.Timer(0.2, fire).start()

    long_run = {**RUN, "loop": {**RUN["loop"], "iterations": 40}}
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        gpilqg.run("cartpole", long_run, out=tmp_path / "stopped.h5", progress=progress)
    stopped = time.monotonic()
    assert "at" in sent, "the run ended before the interrupt"
    # Stopped at the first iteration boundary after the interrupt: at most one more line.
    after = [line for at, line in lines if at > sent["at"]]
    assert len(after) <= 1, after
    slowest = max(b - a for (a, _), (b, _) in zip([(started, "")] + lines, lines))
    assert stopped - sent["at"] <= 2 * slowest + 0.5, (stopped - sent["at"], slowest)
    assert not (tmp_path / "stopped.h5").exists()


def test_ctrl_c_stops_a_solve_at_the_next_iteration(python_cartpole):
    # Ctrl-C during iteration 3 of a solve on a Python system: the solve stops after that iteration.
    config = {"system": {"name": python_cartpole, "preset": "sim", "integrator": "rk4", "substeps": 10, "dt": 0.05},
              "problem": {"horizon": 60, "x0": [0.0, 0.0, 0.0, 0.0], "goal": [0.0, 0.0, np.pi, 0.0],
                          "Q": [0.0] * 4, "R": [0.1], "Qf": [100.0, 100.0, 1000.0, 100.0]},
              "solver": {"algorithm": "ilqr", "max_iterations": 200, "tolerance": 1e-12}}
    lines = []

    def progress(line):
        lines.append(line)
        if line.startswith("iteration 3:"):
            _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        gpilqg.solve(config, progress=progress)
    assert lines[-1].startswith("iteration 3:"), lines


def test_diagnose_equals_the_command_lines_json():
    data = SOURCE_DIR / "data" / "cartpole_hidden_friction.csv"
    status, out, err = cli("diagnose", "--system", "cartpole", "--data", data, "--json")
    assert status == 0, err
    expected = json.loads(out)
    report = gpilqg.diagnose("cartpole", data)
    assert report["verdict"] == expected["verdict"]
    assert set(report) == set(expected)
    from_set = gpilqg.diagnose("cartpole", gpilqg.read_measurements(data, "cartpole"), add=["cart_coulomb_friction"])
    assert from_set["verdict"]["status"] in ("consistent", "explained", "unexplained")
    with pytest.raises(gpilqg.InputError, match="--heldout"):
        gpilqg.diagnose("cartpole", data, heldout=1.5)


def test_diagnose_a_single_episode_record_holds_out_blocks(tmp_path):
    # One continuous record: cut into 10 blocks, 3 held out, a gap of the longest horizon around each.
    data = tmp_path / "record.csv"
    status, _, err = cli("simulate", "--system", "cartpole", "--preset", "sim", "--effect", "cart_coulomb_friction=1.5",
                         "--episodes", "1", "--steps", "600", "--out", data)
    assert status == 0, err
    report = gpilqg.diagnose("cartpole", data, horizons=[1, 10], gp_points=100, gp_restarts=0)
    blocks = report["heldout_blocks"]
    assert (blocks["count"], blocks["gap"], blocks["heldout"]) == (10, 10, [3, 6, 9])
    assert report["heldout_episodes"] == [3, 6, 9]
    assert report["verdict"]["effect"] == "cart_coulomb_friction"
    with pytest.raises(gpilqg.InputError, match="expected at least 1020 samples"):
        gpilqg.diagnose("cartpole", data)


def test_diagnose_auto_equals_the_command_lines_selection(tmp_path):
    data = tmp_path / "two.csv"
    status, _, err = cli("simulate", "--system", "cartpole", "--preset", "sim", "--effect", "cart_coulomb_friction=1.5",
                         "--effect", "external_force_x=0.8", "--out", data)
    assert status == 0, err
    status, out, err = cli("diagnose", "--system", "cartpole", "--data", data, "--auto", "--horizons", "1,5", "--json")
    assert status == 0, err
    expected = json.loads(out)
    report = gpilqg.diagnose("cartpole", data, auto=True, horizons=[1, 5])
    assert report["selection"] == expected["selection"]
    assert sorted(step["effect"] for step in report["selection"]["steps"]) == ["cart_coulomb_friction", "external_force_x"]
    assert [k["k"] for k in report["k_step"]] == [1, 5]


def test_diagnose_simulation_criterion_equals_the_command_lines(tmp_path):
    data = SOURCE_DIR / "data" / "cartpole_hidden_friction.csv"
    options = ["--criterion", "simulation", "--window", "20", "--horizons", "1", "--gp-points", "50", "--json"]
    status, out, err = cli("diagnose", "--system", "cartpole", "--data", data, *options)
    assert status == 0, err
    expected = json.loads(out)
    report = gpilqg.diagnose("cartpole", data, criterion="simulation", window=20, horizons=[1], gp_points=50)
    assert report["criterion"] == {"name": "simulation", "window": 20, "restarts": 0, "starts": "estimated", "instruments": None, "weights": None,
                                   "chosen_by": "user", "excluded": [], "reason": None} == expected["criterion"]
    assert report["ranking"] == expected["ranking"]
    # The default, --criterion auto: these data (held commands at 50 Hz) choose one step, and say why.
    chosen = gpilqg.diagnose("cartpole", data, horizons=[1], gp_points=50)["criterion"]
    assert chosen["name"] == "one-step" and chosen["chosen_by"] == "data" and "inverse-dynamics" in chosen["reason"]
    with pytest.raises(gpilqg.InputError, match="--criterion simulation: expected --window N"):
        gpilqg.diagnose("cartpole", data, criterion="simulation")
    with pytest.raises(gpilqg.InputError, match="--window 20: windows belong to --criterion simulation"):
        gpilqg.diagnose("cartpole", data, window=20)


def test_diagnose_a_python_system_finds_its_missing_parameter(tmp_path, python_cartpole):
    # Data of the C++ cart-pole's real preset (pole 1.3 m); the Python cart-pole's sim preset has 1 m.
    status, _, err = cli("simulate", "--system", "cartpole", "--preset", "real", "--episodes", "6", "--steps", "150",
                         "--actuator-noise", "0.05", "--seed", "3", "--out", tmp_path / "real.csv")
    assert status == 0, err
    python = gpilqg.diagnose(python_cartpole, tmp_path / "real.csv")
    cpp = gpilqg.diagnose("cartpole", tmp_path / "real.csv")
    assert python["verdict"]["effect"] == "param:pole_length" == cpp["verdict"]["effect"]
    assert python["verdict"]["parameters"]["pole_length"] == pytest.approx(1.3, rel=0.02)
    assert python["verdict"]["parameters"]["pole_length"] == pytest.approx(
        cpp["verdict"]["parameters"]["pole_length"], rel=1e-6)


def test_diagnose_reports_progress_and_ctrl_c_stops_it_between_effects():
    data = SOURCE_DIR / "data" / "cartpole_hidden_friction.csv"
    lines = []

    def progress(line):
        lines.append(line)
        if line.startswith("effect 2/"):
            _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        gpilqg.diagnose("cartpole", data, progress=progress)
    # Progress from the first moment: the samples, the criterion, the model's residual and its GP.
    assert lines[0] == "2000 samples in 10 episode(s); choosing the criterion by the data", lines
    assert "residual GP of the model fitted" in lines
    # Effects are fitted on several threads and Python handles the signal on the calling thread only: the
    # call stops after the calling thread's current effect, so after effect 2 and before all 13 were fitted.
    last, total = map(int, lines[-1].split()[1].split("/"))
    assert 2 <= last < total, lines


def test_diagnose_a_passive_pendulum_equals_the_command_line(tmp_path):
    # Free swings of the pendulum without actuators with a hidden joint damping: Python's diagnose gives the
    # command line's verdict, and it names the damping; solve refuses the passive system.
    pendulum = SOURCE_DIR / "data" / "pendulum_passive.xml"
    data = tmp_path / "swing.csv"
    status, _, err = cli("simulate", "--system", pendulum, "--param", "swing.damping=0.3", "--episodes", "6",
                         "--steps", "150", "--seed", "2", "--out", data)
    assert status == 0, err
    status, out, err = cli("diagnose", "--system", pendulum, "--data", data, "--gp-points", "100", "--json")
    assert status == 0, err
    expected = json.loads(out)
    report = gpilqg.diagnose(str(pendulum), data, gp_points=100)
    assert report["verdict"] == expected["verdict"]
    assert report["verdict"]["status"] == "explained"
    assert {report["verdict"]["effect"], *report["verdict"]["aliases"]} & {"param:swing.damping",
                                                                          "joint_viscous_damping:swing"}
    assert all(not e["effect"].startswith(("input_delay", "actuator_gain")) for e in report["ranking"])
    # The bob's second moments are candidates only on request: listed, not ranked; include= asks for them.
    assert report["on_request"] == ["param:bob.second_moment_%d" % k for k in (1, 2, 3)] == expected["on_request"]
    with pytest.raises(gpilqg.InputError, match="--include 'param:bob.mass': matches no candidate searched only"):
        gpilqg.diagnose(str(pendulum), data, gp_points=100, include=["param:bob.mass"])
    config = tmp_path / "solve.toml"
    config.write_text('[system]\nname = "%s"\ndt = 0.02\n[problem]\nhorizon = 10\nx0 = [0, 0]\ngoal = [0, 0]\n'
                      'Q = [1, 1]\nR = []\nQf = [1, 1]\n' % pendulum)
    with pytest.raises(gpilqg.InputError, match="no controls to optimise"):
        gpilqg.solve(config)


class PassivePendulum(gpilqg.Dynamics):
    """A pendulum without controls, q_ddot = -g sin q - b q_dot (no MuJoCo: the generic path of a plugin's system)."""

    def __init__(self, b):
        super().__init__("python_passive_pendulum", states=[("q", "rad"), ("q_dot", "rad/s")], controls=[])
        self.b = b

    def parameters(self):
        return {"b": self.b}

    def f(self, x, u):
        return np.array([x[1], -9.81 * np.sin(x[0]) - self.b * x[1]])


def test_diagnose_a_registered_passive_python_system():
    if "python_passive_pendulum" not in gpilqg.systems():
        gpilqg.register_system("python_passive_pendulum",
                               lambda preset, p: PassivePendulum(p.get("b", 0.0 if preset == "sim" else 0.5)))
    step = gpilqg.StepModel(PassivePendulum(0.5), dt=0.02)
    rng = np.random.default_rng(0)
    episodes = []
    for _ in range(5):
        xs = [np.array([rng.uniform(-1, 1), rng.uniform(-0.5, 0.5)])]
        for _ in range(99):
            xs.append(step.jacobians(xs[-1], np.zeros(0))[0])
        episodes.append((np.arange(100) * 0.02, np.array(xs) + 1e-3 * rng.normal(size=(100, 2))))
    report = gpilqg.diagnose("python_passive_pendulum", gpilqg.MeasurementSet("python_passive_pendulum", episodes),
                             gp_points=100)
    assert report["verdict"]["effect"] == "param:b"
    assert report["verdict"]["parameters"]["b"] == pytest.approx(0.5, rel=0.05)
    assert [e["effect"] for e in report["ranking"]] == ["param:b"]  # no input_delay without controls
