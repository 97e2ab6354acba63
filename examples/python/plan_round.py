"""One round of Algorithm 1 from Python on a simulated robot, and the swing-ups before and after.

The robot is the cart-pole's real preset (a 30% longer pole than the simulator) with actuator and
sensor noise, stepped in Python; the controller is the Policy that gpilqg.plan returns, acting on the
measured state at every step, exactly as a robot's controller would run the policy file. Round 0
plans on the simulator alone; five logged episodes later, round 1 plans on simulator + GP.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/plan_round.py [OUT.png] [WORK_DIR]
"""

import os
import sys
import tempfile

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gpilqg  # noqa: E402

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
config = os.path.join(root, "examples", "robot_loop", "cartpole_swingup.toml")
work = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="plan_round_")
rng = np.random.default_rng(1)

# The robot: the real pole; its sensors add noise (std 0.002) to every state they report.
robot = gpilqg.StepModel(gpilqg.system("cartpole", preset="real"), dt=0.05, integrator="rk4", substeps=10)


def run_on_robot(policy, exploration=0.0):
    """One episode: measure, act, step; returns the log (t, measured x, applied u) and the true states."""
    x = policy.x_bar[0].copy()
    measured, applied, true = [], [], [x]
    for t in range(policy.horizon):
        y = x + rng.normal(scale=0.002, size=4)  # what the sensors report
        u = policy(t, y) + rng.normal(scale=exploration, size=1)
        u = np.clip(u, policy.u_min, policy.u_max)
        measured.append(y)
        applied.append(u)
        x = robot.step(x, u)
        true.append(x)
    measured.append(x + rng.normal(scale=0.002, size=4))
    applied.append(applied[-1])  # the last row's control starts no transition
    t = np.arange(policy.horizon + 1) * policy.dt
    return (t, np.array(measured), np.array(applied)), np.array(true)


round0 = gpilqg.plan(config, out=os.path.join(work, "policy_0.h5"))
episodes = [run_on_robot(round0, exploration=8.0)[0] for _ in range(5)]
log = os.path.join(work, "log_0.h5")
gpilqg.MeasurementSet("cartpole", episodes).write(log)
round1 = gpilqg.plan(config, data=[log], previous=os.path.join(work, "policy_0.h5"),
                     out=os.path.join(work, "policy_1.h5"), progress=lambda line: None)
print("round 0: predicted cost %.3f; round 1 (GP on %d transitions): predicted cost %.3f"
      % (round0.predicted_cost, 5 * round0.horizon, round1.predicted_cost))

figure, axes = plt.subplots(1, 2, figsize=(11, 4), sharex=True)
for policy, label, color in ((round0, "round 0: simulator only", "tab:red"), (round1, "round 1: simulator + GP", "tab:blue")):
    _, true = run_on_robot(policy)
    t = np.arange(len(true)) * policy.dt
    axes[0].plot(t, true[:, 2], color=color, label=label)
    axes[0].plot(t, policy.x_bar[:, 2], color=color, linestyle=":", alpha=0.7)
    axes[1].plot(t[:-1], policy.u_bar[:, 0], color=color, linestyle=":", alpha=0.7)
axes[0].axhline(np.pi, color="k", linewidth=0.8)
axes[0].set_ylabel("pole angle theta [rad]")
axes[0].set_xlabel("t [s]")
axes[0].legend()
axes[0].set_title("swing-up (solid: on the robot, dotted: the plan)")
axes[1].set_ylabel("planned force u_bar [N]")
axes[1].set_xlabel("t [s]")
axes[1].set_title("the plans")
figure.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "plan_round.png"
figure.savefig(out, dpi=120)
print("figure:", out)
