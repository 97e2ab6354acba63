#!/usr/bin/python3
"""Accuracy against time for `gpilqg profile` (reads only the HDF5 file it wrote).

Usage: /usr/bin/python3 plot_profile.py PROFILE.h5 OUT_DIR

Writes OUT_DIR/profile_pareto.png: two panels, SMSE and MSLL (lower is better) against the fit time
(log scale), one line per backend through its training-set sizes (labelled with N); the Pareto front
over all rows (no other row is both faster and more accurate) is drawn as a grey step line. The exact
GP under the reference hyperparameters ("exact_reference", conditioned, not fitted) is plotted at its
conditioning time as the baseline. Skipped or failed rows are left out.
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    with h5py.File(path, "r") as f:
        rows = f["rows"]
        text = lambda name: [s.decode() if isinstance(s, bytes) else str(s) for s in rows[name][()]]
        data = {
            "backend": text("backend"),
            "status": text("status"),
            "size": rows["size"][()].astype(int),
            "fit_s": rows["fit_s"][()],
            "smse": rows["smse"][()],
            "msll": rows["msll"][()],
        }
        title = "{} ({}, {} test points)".format(
            f.attrs.get("data_name", "?"), f.attrs.get("target", "?"), f.attrs.get("test_points", "?"))
    return data, title


def pareto(times, scores):
    order = np.argsort(times)
    front_t, front_s, best = [], [], np.inf
    for i in order:
        if scores[i] < best:
            best = scores[i]
            front_t.append(times[i])
            front_s.append(scores[i])
    return front_t, front_s


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_profile.py PROFILE.h5 OUT_DIR")
    data, title = read(sys.argv[1])
    ok = np.array([s == "ok" for s in data["status"]])
    backends = list(dict.fromkeys(b for b, good in zip(data["backend"], ok) if good))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for axis, metric, label in zip(axes, ["smse", "msll"], ["SMSE", "MSLL"]):
        for backend in backends:
            pick = np.array([b == backend for b in data["backend"]]) & ok
            order = np.argsort(data["size"][pick])
            t = data["fit_s"][pick][order]
            s = data[metric][pick][order]
            style = "k--o" if backend == "exact_reference" else "-o"
            axis.plot(t, s, style, label=backend)
            for ti, si, n in zip(t, s, data["size"][pick][order]):
                axis.annotate(str(n), (ti, si), textcoords="offset points", xytext=(4, 4), fontsize=7)
        if ok.any():
            ft, fs = pareto(data["fit_s"][ok], data[metric][ok])
            axis.step(ft, fs, where="post", color="0.6", linewidth=3, alpha=0.5, label="Pareto front", zorder=0)
        axis.set_xscale("log")
        axis.set_xlabel("fit time [s] (conditioning time for exact_reference)")
        axis.set_ylabel(label + " (lower is better)")
        axis.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    os.makedirs(sys.argv[2], exist_ok=True)
    out = os.path.join(sys.argv[2], "profile_pareto.png")
    fig.savefig(out, dpi=120)
    print("wrote " + out, file=sys.stderr)


if __name__ == "__main__":
    main()
