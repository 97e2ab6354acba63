#!/usr/bin/python3
"""Figures of a `gpilqg run` result, drawn from the HDF5 file alone (layout: README "Results file").

usage: /usr/bin/python3 plot_run.py RESULT.h5 OUT_DIR

Writes, per task: <task>_cost.png (normalised cost against iteration on a log axis, mean and a
min-max band over seeds: the paper's Figures 2a, 2b, 3a, 3b), <task>_controls.png (the final policies'
controls, Figure 2c), for the quadrotor <task>_trajectories.png (paths and height, Figure 3c), and for
every task with a learned model <task>_gp_slice.png (the GP with the simulator as its mean, Figure 1;
drawn by plot_slice.py). A diverged algorithm does not set the scale: costs above COST_CEILING and
controls beyond CONTROL_OFF_SCALE times the true model's policy's are named in the legend instead.
"""
import os
import sys

import h5py
import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from plot_slice import draw_slice  # noqa: E402  (beside this script)

STYLE = {
    "ilqg_real": dict(color="black", linestyle="--", label="iLQG, true model"),
    "ilqg_sim": dict(color="tab:red", label="iLQG, simulator"),
    "gp_ilqg": dict(color="tab:blue", label="GP-ILQG"),
    "pddp": dict(color="tab:green", label="PDDP (same data)"),
    "pddp_own": dict(color="tab:olive", linestyle=":", label="PDDP (own data)"),
}


def style(name):
    if name in STYLE:
        return dict(STYLE[name])
    return dict(label=name.replace("_", " "))


def algorithms(group):
    names = [n.decode() if isinstance(n, bytes) else str(n) for n in group.attrs["algorithms"]]
    if "gp_ilqg" in group and "gp_ilqg" not in names:
        names.append("gp_ilqg")
    return names


# Normalised costs above this are failures whose size tells nothing more (a diverged PDDP reaches
# 1e20): the cost axis stops here and such points are drawn on its top edge, marked and labelled.
COST_CEILING = 1e4


def cost_series(group, name):
    """Iterations, mean normalised cost over seeds, the band (min, max) over seeds, the number of seeds
    and the standard error of the mean from the evaluation rollouts, sqrt(sum_s se_s^2) / S (None when
    the file has no `normalised_cost_se` or a seed's could not be estimated, -1 with one rollout)."""
    cost = group[name]["normalised_cost"][()]  # iterations x seeds
    se = None
    if "normalised_cost_se" in group[name]:
        per_seed = group[name]["normalised_cost_se"][()]
        if (per_seed >= 0).all():
            se = np.sqrt((per_seed ** 2).sum(axis=1)) / cost.shape[1]
    return np.arange(cost.shape[0]), cost.mean(axis=1), cost.min(axis=1), cost.max(axis=1), cost.shape[1], se


def draw_off_scale(ax, it, values, ceiling, color):
    """Marks the points above `ceiling` on the axis' top edge with their values."""
    for i, v in zip(it, values):
        if v > ceiling:
            ax.plot([i], [ceiling], marker="^", color=color, markersize=6, clip_on=False, zorder=4)
            ax.annotate(f"{v:.0e}", (i, ceiling), textcoords="offset points", xytext=(0, -10), ha="center",
                        fontsize=6, color=color)


def plain_log_labels(ax):
    """Labels a log y axis with plain numbers (1, 2, 5, 10 rather than 10^0, 2x10^0); within about a
    decade the minor ticks are labelled too, otherwise only the powers of ten."""
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    ax.yaxis.set_major_formatter(plain)
    lo, hi = ax.get_ylim()
    if hi / lo < 30:
        ax.yaxis.set_minor_formatter(plain)
        ax.tick_params(axis="y", which="minor", labelsize=7)
    else:
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def draw_diagnosis(ax, alg, color):
    """The diagnosis inside the loop: a dashed line before the first iteration planned on the diagnosed
    model, labelled with what the diagnosis found (the first seed that adopted it at that iteration)."""
    if "diagnosed_from" not in alg:
        return
    starts = alg["diagnosed_from"][()]
    texts = [t.decode() if isinstance(t, bytes) else str(t) for t in alg["diagnosed_from"].attrs["diagnosis"]]
    for start in sorted(set(int(v) for v in starts if v >= 0)):
        seeds = [s for s, v in enumerate(starts) if int(v) == start]
        found = texts[seeds[0]].split(": ", 1)[-1]
        ax.axvline(start - 0.5, color=color, linestyle="--", linewidth=0.8)
        seed = int(alg.file["seeds"][seeds[0]]) if "seeds" in alg.file else seeds[0] + 1
        label = f"diagnosed ({len(seeds)}/{len(starts)} seeds; seed {seed}'s model): " + "\n".join(found.split("; "))
        ax.annotate(label, xy=(start - 0.45, 0.97), xycoords=("data", "axes fraction"), fontsize=5.5, va="top",
                    color=color)


def plot_cost(task, group, out):
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    seeds = 1
    off_scale = False
    bars = False
    for name in algorithms(group):
        it, mean, lo, hi, seeds, se = cost_series(group, name)
        s = style(name)
        above = mean > COST_CEILING
        if above.any():
            off_scale = True
            s["label"] += f" (above {COST_CEILING:.0e}: up to {mean.max():.0e})"
        line, = ax.plot(it, np.minimum(mean, COST_CEILING), marker="o", markersize=3, **s)
        draw_off_scale(ax, it, mean, COST_CEILING, line.get_color())
        if se is not None and (se > 0).any():
            on_scale = mean <= COST_CEILING
            ax.errorbar(it[on_scale], mean[on_scale], yerr=se[on_scale], fmt="none", ecolor=line.get_color(),
                        elinewidth=1.0, capsize=2.5)
            bars = True
        if seeds > 1:
            ax.fill_between(it, np.minimum(lo, COST_CEILING), np.minimum(hi, COST_CEILING), color=line.get_color(),
                            alpha=0.15, linewidth=0)
        draw_diagnosis(ax, group[name], line.get_color())
    ax.set_xlabel("iteration")
    ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
    ax.set_ylabel("cost / cost of iLQG on the true model")
    ax.set_yscale("log")
    if off_scale:
        ax.set_ylim(top=COST_CEILING)
    plain_log_labels(ax)
    band = f"mean, band: min-max over {seeds} seeds" if seeds > 1 else "1 seed"
    if bars:
        band += "; bars: ±1 standard error"
    ax.set_title(f"{task}\n({band}; log scale)", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="center right" if off_scale else "best")
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"{task}_cost.png"), dpi=130)
    plt.close(fig)


def last_iteration(alg):
    return max(int(k.split("_")[1]) for k in alg if k.startswith("iter_"))


# Axis labels of the controls of the built-in systems (others: u1, u2, ...).
CONTROL_LABELS = {
    "cartpole": ["force [N]"],
    "quadrotor": [f"rotor {j} thrust u{j} [N]" for j in range(1, 5)],
}
# A policy whose controls exceed this many times the largest of the true model's policy has diverged;
# the axis is scaled to the others and the diverged one is named in the legend with its peak.
CONTROL_OFF_SCALE = 10.0


def plot_controls(task, group, dt, system, out):
    names = [n for n in algorithms(group) if n != "gp_ilqg" or "gp_ilqg" in group.attrs["algorithms"].astype(str)]
    controls = {}
    for name in names:
        alg = group[name]
        controls[name] = alg[f"iter_{last_iteration(alg)}"]["eval_u"][0]  # first seed: m x T
    m = controls[names[0]].shape[0]
    reference = controls.get("ilqg_real", np.concatenate(list(controls.values()), axis=1))
    peak = np.maximum(np.abs(reference).max(axis=1), 1e-12)  # per control
    labels = CONTROL_LABELS.get(system, [])
    fig, axes = plt.subplots(m, 1, figsize=(5.5, 2.2 * m + 0.8), squeeze=False, sharex=True)
    for name, u in controls.items():
        t = np.arange(u.shape[1]) * dt
        s = style(name)
        diverged = np.abs(u).max(axis=1) > CONTROL_OFF_SCALE * peak
        if diverged.any():
            s["label"] += f" (off scale: |u| up to {np.abs(u).max():.0e})"
        for j in range(m):
            axes[j, 0].step(t, u[j], where="post", **s)
            s.pop("label", None)
    for j in range(m):
        within = [u[j] for u in controls.values() if np.abs(u[j]).max() <= CONTROL_OFF_SCALE * peak[j]]
        within = within or [u[j] for u in controls.values()]  # the reference itself all zero
        lo, hi = min(v.min() for v in within), max(v.max() for v in within)
        pad = 0.05 * max(hi - lo, 1e-12)
        axes[j, 0].set_ylim(lo - pad, hi + pad)
        axes[j, 0].set_ylabel(labels[j] if j < len(labels) else f"u{j + 1}", fontsize=8)
        axes[j, 0].grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].legend(fontsize=7)
    axes[0, 0].set_title(f"{task}: applied controls of the final policies (first seed)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"{task}_controls.png"), dpi=130)
    plt.close(fig)


def plot_quadrotor(task, group, dt, out):
    names = [n for n in algorithms(group) if n in ("ilqg_real", "ilqg_sim", "gp_ilqg")]
    fig, (top, side) = plt.subplots(1, 2, figsize=(10, 3.8))
    for name in names:
        alg = group[name]
        x = alg[f"iter_{last_iteration(alg)}"]["eval_x"][0]  # n x T+1
        t = np.arange(x.shape[1]) * dt
        s = style(name)
        top.plot(x[0], x[1], **s)
        side.plot(t, x[2], **s)
    top.set_xlabel("px [m]")
    top.set_ylabel("py [m]")
    top.set_title(f"{task}: paths (first seed)", fontsize=9)
    side.set_xlabel("time [s]")
    side.set_ylabel("height pz [m]")
    side.set_title("height", fontsize=9)
    for ax in (top, side):
        ax.grid(True, alpha=0.3)
    side.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"{task}_trajectories.png"), dpi=130)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_run.py RESULT.h5 OUT_DIR")
    path, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    with h5py.File(path, "r") as f:
        system = f.attrs["system"]
        system = system.decode() if isinstance(system, bytes) else str(system)
        for task in [k for k in f if isinstance(f[k], h5py.Group)]:
            group = f[task]
            dt = float(group.attrs["dt"])
            plot_cost(task, group, out)
            plot_controls(task, group, dt, system, out)
            if system == "quadrotor":
                plot_quadrotor(task, group, dt, out)
            if "figure1" in group:
                draw_slice(task, group, os.path.join(out, f"{task}_gp_slice.png"))
    print(f"figures written to {out}")


if __name__ == "__main__":
    main()
