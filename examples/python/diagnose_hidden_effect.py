"""Diagnose a hidden effect from Python, and draw what the diagnosis found.

The data (data/cartpole_hidden_friction.csv) come from the cart-pole simulator with a Coulomb
friction on the cart that the model does not have. gpilqg.diagnose ranks the physical effects of the
library by how much of the held-out one-step error each removes; then the named effect is added and
the error falls. The figure: the ranking, and the held-out error per state before and after.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/diagnose_hidden_effect.py [OUT.png]
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gpilqg  # noqa: E402

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
data = gpilqg.read_measurements(os.path.join(root, "data", "cartpole_hidden_friction.csv"), "cartpole")
report = gpilqg.diagnose("cartpole", data)
verdict = report["verdict"]
print("verdict: %s, %s %s" % (verdict["status"], verdict["effect"], verdict["parameters"]))

fixed = gpilqg.diagnose("cartpole", data, add=[verdict["effect"]])
print("with %s added: %s" % (verdict["effect"], fixed["verdict"]["status"]))

ranking = report["ranking"][:6]
figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
left.barh([r["effect"] for r in ranking][::-1], [100 * r["explained"] for r in ranking][::-1], color="tab:blue")
left.axvline(100 * report["gp_explained"], color="k", linestyle="--", label="what a GP explains")
left.set_xlabel("held-out one-step error removed [%]")
left.set_title("which effect is missing?")
left.legend(loc="lower right")

states = [s["name"] for s in report["states"]]
before = [s["heldout_rmse"] for s in report["states"]]
after = [s["heldout_rmse"] for s in fixed["states"]]
positions = range(len(states))
right.bar([p - 0.2 for p in positions], before, width=0.4, label="simulator")
right.bar([p + 0.2 for p in positions], after, width=0.4, label="simulator + %s" % verdict["effect"])
right.set_xticks(list(positions), states)
right.set_yscale("log")
right.set_ylabel("held-out one-step RMSE [state units]")
right.set_title("the error falls when it is added")
right.legend(loc="upper center", fontsize="small")
figure.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "diagnose_hidden_effect.png"
figure.savefig(out, dpi=120)
print("figure:", out)
