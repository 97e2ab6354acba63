#!/usr/bin/python3
"""Figures of a `gpilqg run` result, drawn from the HDF5 file alone (layout: README "Results file").

usage: /usr/bin/python3 plot_run.py RESULT.h5 OUT_DIR

Writes, per task: <task>_cost.png (normalised cost against iteration, mean and a min-max band over
seeds: the paper's Figures 2a, 2b, 3a, 3b), <task>_controls.png (the final policies' controls,
Figure 2c), for the quadrotor <task>_trajectories.png (paths and height, Figure 3c), and for the
first task with a learned model <task>_gp_slice.png (the GP with the simulator as its mean, Figure 1).
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

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


def plot_cost(task, group, out):
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    for name in algorithms(group):
        cost = group[name]["normalised_cost"][()]  # iterations x seeds
        it = np.arange(cost.shape[0])
        mean = cost.mean(axis=1)
        s = style(name)
        ax.plot(it, mean, marker="o", markersize=3, **s)
        if cost.shape[1] > 1:
            ax.fill_between(it, cost.min(axis=1), cost.max(axis=1), color=s.get("color"), alpha=0.15, linewidth=0)
    ax.set_xlabel("iteration")
    ax.set_ylabel("cost / cost of iLQG on the true model")
    ax.set_yscale("log")
    ax.set_title(f"{task} (mean, band: min-max over {cost.shape[1]} seed(s))", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"{task}_cost.png"), dpi=130)
    plt.close(fig)


def last_iteration(alg):
    return max(int(k.split("_")[1]) for k in alg if k.startswith("iter_"))


def plot_controls(task, group, dt, out):
    names = [n for n in algorithms(group) if n != "gp_ilqg" or "gp_ilqg" in group.attrs["algorithms"].astype(str)]
    first = group[names[0]]
    m = first[f"iter_{last_iteration(first)}"]["eval_u"].shape[1]
    fig, axes = plt.subplots(m, 1, figsize=(5.5, 2.2 * m + 0.8), squeeze=False)
    for name in names:
        alg = group[name]
        u = alg[f"iter_{last_iteration(alg)}"]["eval_u"][0]  # first seed: m x T
        t = np.arange(u.shape[1]) * dt
        for j in range(m):
            axes[j, 0].step(t, u[j], where="post", **style(name))
    for j in range(m):
        axes[j, 0].set_ylabel(f"u{j + 1}" if m > 1 else "force [N]")
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


def plot_slice(task, group, out):
    s = group["figure1"]
    z, mean, std = s["grid"][()], s["mean"][()], s["std"][()]
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.fill_between(z, mean - 1.96 * std, mean + 1.96 * std, color="tab:blue", alpha=0.2, label="95% band")
    ax.plot(z, mean, color="tab:blue", label="simulator + GP")
    ax.plot(z, s["simulator"][()], color="tab:red", label="simulator (the GP's mean)")
    ax.plot(z, s["truth"][()], color="black", linestyle="--", label="real world")
    ax.scatter(s["data_z"][()], s["data_y"][()], s=6, color="tab:gray", label="measurements near the slice")
    ax.set_xlabel(str(s.attrs["input"]))
    ax.set_ylabel(f"next {s.attrs['output']}")
    ax.set_title("corrected near the data, the simulator far from it", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"{task}_gp_slice.png"), dpi=130)
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
            plot_controls(task, group, dt, out)
            if system == "quadrotor":
                plot_quadrotor(task, group, dt, out)
            if "figure1" in group:
                plot_slice(task, group, out)
    print(f"figures written to {out}")


if __name__ == "__main__":
    main()
