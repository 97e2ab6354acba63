#!/usr/bin/python3
"""The paper's Figure 1 from a `<group>/figure1` slice (layout: model_slice_io.hpp, docs/formats.md).

usage: /usr/bin/python3 plot_slice.py FILE.h5 OUT_DIR

Draws every group of the file that holds a figure1 slice to OUT_DIR/<group>_gp_slice.png: a result of
`gpilqg run` (one per task) or of the one-dimensional example (examples/gp_1d). plot_run.py calls
draw_slice for its tasks.

Two panels share the slice's input z_j (the other inputs held at a measured point z*):
  top     the next state x'_i: the simulator, the real world, simulator + GP mean and its 95% band;
  bottom  the same relative to the simulator, x'_i - phi_sim(z)_i: the real world's error, the GP's
          correction mu and band, around 0 (the simulator).
The measurements drawn are those within one length-scale of the slice in the other inputs. Each is
drawn at its measured residual r = x'_i - phi_sim(z)_i (bottom) and at phi_sim(z on the slice) + r (top):
its other inputs differ a little from z*'s, and the residual, not x'_i, is what the GP learned from the
measurement and carries along the slice.
"""
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def text(attrs, name, default=""):
    if name not in attrs:
        return default
    value = attrs[name]
    return value.decode() if isinstance(value, bytes) else str(value)


def with_unit(name, unit):
    return f"{name} [{unit}]" if unit else name


def draw_slice(title, group, path):
    """Draws group["figure1"] to `path`."""
    s = group["figure1"]
    z, sim, mean, std, truth = (s[k][()] for k in ("grid", "simulator", "mean", "std", "truth"))
    output, inp = text(s.attrs, "output"), text(s.attrs, "input")
    out_unit, in_unit = text(s.attrs, "output_unit"), text(s.attrs, "input_unit")
    data_z = s["data_z"][()]
    has_residual = "data_residual" in s
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.0, 6.2), sharex=True, gridspec_kw=dict(height_ratios=[3, 2]))
    n_data = len(data_z)
    near = f"{n_data} measurements within one length-scale of the slice"
    if not has_residual:
        near = f"{n_data} measurements (their own x', other inputs differ)"
    marker = dict(s=8 if n_data < 200 else 3, color="tab:gray", alpha=0.9 if n_data < 200 else 0.5, zorder=3)

    top.fill_between(z, mean - 1.96 * std, mean + 1.96 * std, color="tab:blue", alpha=0.2, linewidth=0,
                     label="95% band of the GP")
    top.plot(z, sim, color="tab:red", label="simulator (the GP's prior mean)")
    top.plot(z, truth, color="black", linestyle="--", label="real world")
    top.plot(z, mean, color="tab:blue", label="simulator + GP mean")
    if has_residual:
        residual = s["data_residual"][()]
        top.scatter(data_z, np.interp(data_z, z, sim) + residual, label=near, **marker)
    else:
        top.scatter(data_z, s["data_y"][()], label=near, **marker)
    top.set_ylabel(with_unit(f"next {output}", out_unit))

    bottom.fill_between(z, mean - sim - 1.96 * std, mean - sim + 1.96 * std, color="tab:blue", alpha=0.2, linewidth=0)
    bottom.axhline(0.0, color="tab:red")
    bottom.plot(z, truth - sim, color="black", linestyle="--")
    bottom.plot(z, mean - sim, color="tab:blue")
    if has_residual:
        bottom.scatter(data_z, residual, **marker)
    bottom.set_ylabel(with_unit(f"next {output} - simulator", out_unit), fontsize=8)
    bottom.set_xlabel(with_unit(inp, in_unit))

    top.set_title(f"{title}: next {output} against {inp}, other inputs at a measured point\n"
                  "corrected near the data, the simulator with the prior's band far from it", fontsize=8)
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    # Below the panels, where it hides neither the curves nor the measurements.
    fig.legend(*top.get_legend_handles_labels(), loc="lower center", ncol=2, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.09, 1, 1))
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main():
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        sys.exit("usage: plot_slice.py FILE.h5 OUT_DIR")
    path, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    drawn = 0
    with h5py.File(path, "r") as f:
        for name in [k for k in f if isinstance(f[k], h5py.Group) and "figure1" in f[k]]:
            draw_slice(name, f[name], os.path.join(out, f"{name}_gp_slice.png"))
            drawn += 1
    if drawn == 0:
        sys.exit(f"plot_slice.py: {path} holds no <group>/figure1 slice")
    print(f"{drawn} slice(s) written to {out}")


if __name__ == "__main__":
    main()
