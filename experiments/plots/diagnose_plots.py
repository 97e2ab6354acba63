#!/usr/bin/python3
"""Plots of a `gpilqg diagnose` report. Reads only the HDF5 report (layout in report_hdf5.hpp) and
writes PNG files into a folder:

  measured_vs_predicted.png  one held-out episode: measured states, one-step and k-step predictions
  residual_gp_band.png       residual of the worst states over time with the GP mean +- 2 std band
  ranking.png                explained fraction of every effect with its 95% interval (and the parameter)
  residual_vs_input.png      residual against its most relevant input, before and after the effect

Usage: /usr/bin/python3 diagnose_plots.py REPORT.h5 OUT_DIR
"""
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def names(attr):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in attr]


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def worst_states(f, count):
    s = f["compare/states"]
    ratio = s["heldout_rmse"][()] / np.maximum(s["noise_floor"][()], 1e-300)
    return list(np.argsort(-ratio)[:count])


def heldout_episode_figure(f, panels):
    """The first held-out episode (its index, rows and times) and a figure with one panel per state."""
    data = f["data"]
    held = np.flatnonzero(data["heldout"][()] == 1)
    episode = data["episode"][()][held[0]] if held.size else 0
    rows = np.flatnonzero(data["episode"][()] == episode)
    fig, axes = plt.subplots(panels, 1, figsize=(9, 2.4 * panels), sharex=True, squeeze=False)
    return episode, rows, data["t"][()][rows], fig, axes


def measured_vs_predicted(f, out, states, shown):
    data = f["data"]
    episode, rows, t, fig, axes = heldout_episode_figure(f, len(shown))
    ks = sorted((g for g in f["compare"] if g.startswith("k_")), key=lambda g: int(g[2:]))
    dt = float(json.loads(text(f.attrs["report"]))["dt"])
    for ax, i in zip(axes[:, 0], shown):
        ax.plot(t + dt, data["x_next"][()][rows, i], "k.", ms=3, label="measured")
        ax.plot(t + dt, f["compare/predicted"][()][rows, i], "-", lw=1, label="one-step prediction")
        if ks:
            g = f["compare"][ks[-1]]
            sel = np.flatnonzero(g["episode"][()] == episode)
            k = int(g.attrs["k"])
            times = (g["start"][()][sel] + k) * dt + t[0]
            ax.plot(times, g["predicted"][()][sel, i], "x", ms=4, label=f"{k}-step prediction")
        ax.set_ylabel(states[i])
    axes[0, 0].legend(loc="best", fontsize=8)
    axes[-1, 0].set_xlabel(f"t [s] (held-out episode {episode})")
    fig.suptitle("Measured vs predicted")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "measured_vs_predicted.png"), dpi=110)
    plt.close(fig)


def residual_band(f, out, states, shown):
    data = f["data"]
    episode, rows, t, fig, axes = heldout_episode_figure(f, len(shown))
    for ax, i in zip(axes[:, 0], shown):
        r = f["compare/residual"][()][rows, i]
        mu = f["compare/gp_mean"][()][rows, i]
        sd = f["compare/gp_std"][()][rows, i]
        ax.fill_between(t, mu - 2 * sd, mu + 2 * sd, alpha=0.3, label="GP mean +- 2 std")
        ax.plot(t, mu, lw=1, label="GP mean")
        ax.plot(t, r, "k.", ms=3, label="residual")
        ax.set_ylabel("r " + states[i])
    axes[0, 0].legend(loc="best", fontsize=8)
    axes[-1, 0].set_xlabel(f"t [s] (held-out episode {episode})")
    fig.suptitle("One-step residual with the GP band")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "residual_gp_band.png"), dpi=110)
    plt.close(fig)


def ranking(f, out):
    if "ranking" not in f or "effect" not in f["ranking"].attrs:
        return
    g = f["ranking"]
    effects = names(g.attrs["effect"])
    parameter, unit, alias_lists = names(g.attrs["parameter_name"]), names(g.attrs["unit"]), names(g.attrs["aliases"])
    explained = g["explained"][()]
    ci = g["explained_ci"][()]
    labels = []
    for k, e in enumerate(effects):
        label = f"{e}\n{parameter[k]} = {g['estimate'][k]:.3g} [{g['ci_low'][k]:.3g}, {g['ci_high'][k]:.3g}] {unit[k]}"
        aliases = alias_lists[k]
        if aliases:
            label += f"\naliases: {aliases}"
        labels.append(label)
    fig, ax = plt.subplots(figsize=(9, 0.75 * len(effects) + 1.5))
    y = np.arange(len(effects))[::-1]
    ax.barh(y, 100 * explained, xerr=100 * ci, capsize=3)
    ax.set_yticks(y)
    ax.set_yticklabels(labels, fontsize=7)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("held-out residual explained [%] (95% interval)")
    ax.set_title(f"Which effect is missing (verdict: {text(f.attrs['status'])})")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "ranking.png"), dpi=110)
    plt.close(fig)


def residual_vs_input(f, out, states, inputs, shown):
    has_add = "add" in f
    relevance = f["add/relevance_before"][()] if has_add else f["where/relevance"][()]
    z = np.hstack([f["data/x"][()], f["data/u"][()]])
    before = f["add/residual_before"][()] if has_add else f["compare/residual"][()]
    after = f["add/residual_after"][()] if has_add else None
    effect = text(f["add"].attrs["effect"]) if has_add else None
    fig, axes = plt.subplots(len(shown), 1, figsize=(8, 2.8 * len(shown)), squeeze=False)
    for ax, i in zip(axes[:, 0], shown):
        j = int(np.argmax(relevance[i]))
        ax.plot(z[:, j], before[:, i], ".", ms=2, alpha=0.6, label="before")
        if after is not None:
            ax.plot(z[:, j], after[:, i], ".", ms=2, alpha=0.6, label=f"after (+ {effect})")
        ax.set_xlabel(inputs[j] + " (most relevant input)")
        ax.set_ylabel("r " + states[i])
        ax.legend(loc="best", fontsize=8, markerscale=4)
    fig.suptitle("Residual against its most relevant input")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "residual_vs_input.png"), dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: diagnose_plots.py REPORT.h5 OUT_DIR")
    path, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    with h5py.File(path, "r") as f:
        states = names(f.attrs["state_names"])
        inputs = names(f.attrs["input_names"])
        shown = worst_states(f, min(3, len(states)))
        measured_vs_predicted(f, out, states, shown)
        residual_band(f, out, states, shown)
        ranking(f, out)
        if "add" in f:  # the states the added (or proposed) effect changed most
            rmse = f["add/heldout_rmse"][()]
            shown = list(np.argsort(-(rmse[0] / np.maximum(rmse[1], 1e-300)))[: min(3, len(states))])
        residual_vs_input(f, out, states, inputs, shown)
    print(f"wrote 4 plots to {out}")


if __name__ == "__main__":
    main()
