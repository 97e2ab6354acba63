#!/usr/bin/python3
"""The summary figure of a `gpilqg sweep` result (layout: docs/cluster.md "The sweep's result file").

usage: /usr/bin/python3 plot_sweep.py SWEEP.h5 OUT_DIR

Writes sweep_cost.png: for each task one panel, for each grid point one line: GP-ILQG's normalised
cost (cost / the cost of iLQG on the true model, same seed) against the iteration, the mean over
seeds with error bars of one standard error of that mean (no bars with one seed). The legend names
each point by the values of its grid fields.
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
import numpy as np  # noqa: E402


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    with h5py.File(path, "r") as f:
        points = int(f.attrs["points"])
        fields = [text(v) for v in f.attrs["grid_fields"]]
        first = f["point_0"]
        tasks = [name for name in first if isinstance(first[name], h5py.Group) and "algorithms" in first[name].attrs]
        fig, axes = plt.subplots(1, len(tasks), figsize=(5.2 * len(tasks), 3.9), squeeze=False)
        colors = plt.cm.viridis(np.linspace(0.0, 0.9, max(points, 2)))
        spread = 1.0
        for t, task in enumerate(tasks):
            ax = axes[0][t]
            for p in range(points):
                group = f[f"point_{p}/{task}"]
                cost = group["gp_ilqg/normalised_cost"][()]  # iterations x seeds
                seeds = cost.shape[1]
                mean = cost.mean(axis=1)
                se = cost.std(axis=1, ddof=1) / np.sqrt(seeds) if seeds > 1 else None
                spread = max(spread, float(np.nanmax(mean) / max(np.nanmin(mean), 1e-12)))
                it = np.arange(cost.shape[0]) + (p - (points - 1) / 2) * 0.03  # keep bars apart
                label = ", ".join(f"{k}={text(v)}" for k, v in zip(fields, f[f"point_{p}"].attrs["grid_values"]))
                ax.errorbar(it, mean, yerr=se, marker="o", markersize=3, capsize=2, color=colors[p], label=label)
            ax.axhline(1.0, color="black", linestyle="--", linewidth=0.8, label="iLQG, true model")
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.set_xlabel("iteration")
            ax.set_ylabel("GP-ILQG cost / cost of iLQG on the true model")
            ax.set_title(f"{task}: mean over {seeds} seed(s)" + (", bars: 1 standard error" if seeds > 1 else ""), fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=6)
        if spread > 20:  # costs spanning decades read better on a log axis
            for ax in axes[0]:
                ax.set_yscale("log")
        fig.suptitle(f"sweep over {', '.join(fields)} ({points} grid points)", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "sweep_cost.png"), dpi=130)
    print(os.path.join(out, "sweep_cost.png"))


if __name__ == "__main__":
    main()
