#!/usr/bin/python3
"""Plots of a `gpilqg diagnose` report. Reads only the HDF5 report (layout in report_hdf5.hpp) and
writes PNG files into a folder:

  measured_vs_predicted.png  one held-out episode: measured states, one-step and k-step predictions
  residual_gp_band.png       residual of the worst states over time with the GP mean +- 2 std band
  ranking.png                explained fraction of every effect with its 95% interval (and the parameter)
  residual_vs_input.png      residual against its most relevant input, before and after the effect
  residual_whiteness.png     autocorrelation of the held-out residual per state with the 95% band
  selection_path.png         --auto: held-out RMSE / noise floor per state after each added effect
  free_run.png               measured states against the free-run simulations (sim, sim+effect,
                             sim+GP) of the first held-out episodes, fit % in the legend (MATLAB `compare`)

Usage: /usr/bin/python3 diagnose_plots.py REPORT.h5 OUT_DIR
"""
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
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
    title = f"Which effect is missing (verdict: {text(f.attrs['status'])})"
    if text(g.attrs.get("criterion", "one-step")) == "simulation":
        ax.set_xlabel("held-out simulation error explained [%] (95% interval)")
        title += f"\nsimulation error over windows of {int(g.attrs['window'])} samples"
    else:
        ax.set_xlabel("held-out residual explained [%] (95% interval)")
    ax.set_title(title)
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


def residual_whiteness(f, out, states):
    """Stem plot of rho(k), k = 0..L, per state with the +-band shaded, the Ljung-Box verdict in the title."""
    g = f["whiteness"]
    lags = g["lags"][()]
    rho = g["autocorrelation"][()]
    band = float(g.attrs["band"])
    white = g["white"][()]
    q, p = g["ljung_box_q"][()], g["p_value"][()]
    critical = float(g.attrs["critical_value"])
    dt = float(json.loads(text(f.attrs["report"]))["dt"])
    n = len(states)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 2.6 * rows + 0.6), sharex=True, squeeze=False)
    for i in range(rows * cols):
        ax = axes[i // cols, i % cols]
        if i >= n:
            ax.axis("off")
            continue
        ax.axhspan(-band, band, color="tab:blue", alpha=0.15, label=f"95% band +-{band:.3f}")
        ax.axhline(0.0, color="k", lw=0.5)
        outside = np.abs(rho[i]) > band
        outside[0] = False
        ax.vlines(lags, 0.0, rho[i], color="0.3", lw=1.2)
        ax.plot(lags[~outside], rho[i][~outside], "o", color="0.3", ms=3.5)
        ax.plot(lags[outside], rho[i][outside], "o", color="tab:red", ms=4, label="outside the band")
        verdict = "white" if white[i] else "not white"
        p_text = "p < 0.001" if p[i] < 0.001 else f"p = {p[i]:.3f}"
        ax.set_title(f"{states[i]}: {verdict} (Q = {q[i]:.3g}, {p_text})", fontsize=9,
                     color="k" if white[i] else "tab:red")
        ax.set_ylabel("autocorrelation")
        ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
        ax.set_xlim(-0.5, lags[-1] + 0.5)
        ax.set_ylim(min(-1.05, rho[i].min() - 0.05), 1.05)
        if i // cols == rows - 1 or i + cols >= n:
            ax.set_xlabel(f"lag [samples of {dt:g} s]")
            ax.xaxis.set_tick_params(labelbottom=True)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper right", fontsize=8)
    dof = int(g.attrs["degrees_of_freedom"])
    fig.suptitle(f"Whiteness of the held-out one-step residual (N = {int(g.attrs['samples'])}; "
                 f"white when Ljung-Box Q <= chi2_0.95({dof}) = {critical:.1f})", fontsize=10, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(os.path.join(out, "residual_whiteness.png"), dpi=110)
    plt.close(fig)


FREE_RUN_STYLE = {"sim": dict(color="tab:red", ls="--"), "sim+effect": dict(color="tab:green", ls="-"),
                  "sim+GP": dict(color="tab:blue", ls="-.")}


def free_run(f, out, states, shown, episodes=3):
    """Measured states and the free-run simulations of the first held-out episodes, fit % in the legend."""
    g = f["free_run"]
    groups = sorted(g, key=int)[:episodes]
    models = names(g.attrs["models"])
    units = names(f.attrs["state_units"]) if "state_units" in f.attrs else [""] * len(states)
    fig, axes = plt.subplots(len(shown), len(groups), figsize=(4.8 * len(groups) + 0.4, 2.5 * len(shown) + 1.0),
                             sharex="col", squeeze=False)
    for c, key in enumerate(groups):
        e = g[key]
        t = e["t"][()]
        measured = e["measured"][()]
        fit = e["fit_percent"][()]
        steps, diverged = e["steps"][()], e["diverged"][()]
        for r, i in enumerate(shown):
            ax = axes[r, c]
            ax.plot(t, measured[:, i], "k-", lw=1.8, label="measured")
            values = [measured[:, i]]
            for k, name in enumerate(models):
                predicted = e["predicted"][name][()]
                label = f"{name} {fit[k, i]:.1f}%"
                if diverged[k] and steps[k] == 0:
                    label = f"{name}: diverged at the first step"
                elif diverged[k]:
                    label += f" until it diverged at {t[int(steps[k]) + 1]:.2f} s"
                ax.plot(t[: predicted.shape[0]], predicted[:, i], lw=1.2, label=label, **FREE_RUN_STYLE.get(name, {}))
                values.append(predicted[:, i])
            # Headroom above the curves for the legend of the fits, so that it hides none of them; a
            # simulation that drifts far away leaves the axes beyond 3 measured spans (its fit says how far).
            m_low, m_high = measured[:, i].min(), measured[:, i].max()
            m_span = max(m_high - m_low, 1e-12)
            low = max(min(v.min() for v in values), m_low - 3 * m_span)
            high = min(max(v.max() for v in values), m_high + 3 * m_span)
            span = max(high - low, 1e-12)
            ax.set_ylim(low - 0.05 * span, high + 0.45 * span)
            handles, labels = ax.get_legend_handles_labels()
            ax.legend(handles[1:], labels[1:], loc="upper center", fontsize=7, ncol=1 if diverged.any() else len(models),
                      handlelength=1.8, columnspacing=1.0, framealpha=0.9)
            if c == 0:
                ax.set_ylabel(f"{states[i]} [{units[i]}]" if units[i] else states[i])
            if r == 0:
                ax.set_title(f"held-out episode {int(e.attrs['id'])}", fontsize=10)
            if r == len(shown) - 1:
                ax.set_xlabel("t [s]")
    fig.legend(handles[:1], labels[:1], loc="upper right", fontsize=8)
    controls = "with the measured controls" if len(names(f.attrs["control_names"])) else "(no controls: a passive system)"
    fig.suptitle(f"Free-run simulation (k = inf) from the measured initial state {controls}; "
                 "fit = 100 (1 - |y - y^| / |y - mean y|)", fontsize=10, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(os.path.join(out, "free_run.png"), dpi=110)
    plt.close(fig)


def selection_path(f, out, states):
    """--auto: what each step of the forward selection bought, in units of the noise floor."""
    g = f["selection"]
    effects = names(g.attrs["effect"])
    rmse = g["heldout_rmse"][()]  # (steps + 1) x channels: the states, or the force components
    floor = np.maximum(f["compare/states"]["noise_floor"][()], 1e-300)
    if "channels" in g.attrs and rmse.shape[1] != len(states):
        # Inverse dynamics: the force components' RMSE, relative to the model as given.
        states = names(g.attrs["channels"])
        floor = np.maximum(rmse[0], 1e-300)
    ratio = rmse / floor
    moved = [i for i in range(len(states)) if ratio[0, i] > 1.05 or ratio[-1, i] > 1.05] or list(range(len(states)))
    fig, ax = plt.subplots(figsize=(max(6, 1.9 * len(effects) + 3), 4.2))
    steps = np.arange(len(effects) + 1)
    for i in moved:
        ax.plot(steps, ratio[:, i], marker="o", label=states[i])
    ax.axhline(1.0, color="k", lw=1, ls="--", label="noise floor")
    labels = ["as given"]
    for k, effect in enumerate(effects):
        step = g[f"step_{k + 1}"]
        value = step["estimate"][0]
        label = f"+ {effect}\n{names(step.attrs['parameter_name'])[0].split('.')[-1]} = {value:.3g}"
        label += f"\n{100 * g['explained'][k]:.0f}% of the rest, z = {g['z_score'][k]:.0f}"
        if "removed" in step.attrs:
            label += "\n- " + ", ".join(names(step.attrs["removed"]))
        labels.append(label)
    ax.set_xticks(steps)
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("held-out RMSE / noise floor")
    final = g[f"step_{len(effects)}"] if effects else None
    title = "Effects added one at a time, all refitted jointly (--auto)"
    if final is not None:
        values = ", ".join(f"{n} = {v:.3g}" for n, v in zip(names(final.attrs["parameter_name"]), final["estimate"][()]))
        title += f"\nfinal joint values: {values}"
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    fig.text(0.01, 0.01, "stop: " + text(g.attrs["stop_reason"]), fontsize=6.5, wrap=True)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(os.path.join(out, "selection_path.png"), dpi=110)
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
        count = 4
        if "whiteness" in f:
            residual_whiteness(f, out, states)
            count += 1
        if "selection" in f and "effect" in f["selection"].attrs:
            selection_path(f, out, states)
            count += 1
        if "free_run" in f:  # every state up to 6 (the worst ones first beyond that)
            free_run(f, out, states, sorted(worst_states(f, min(6, len(states)))))
            count += 1
    print(f"wrote {count} plots to {out}")


if __name__ == "__main__":
    main()
