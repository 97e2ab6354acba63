#!/usr/bin/env python3
"""Prepare the benchmark recordings for `gpilqg data import` (Python 3 standard library only).

gpilqg's import maps columns and units; it does not select rows, subtract means or combine columns.
This script does the three things these recordings need, and nothing else:

  silverbox  SNLS80mV.csv -> silverbox_multisine.csv
             rows 40650 .. 127399 (0-based; the multisine part, as the benchmark's loader slices it),
             optionally shorter (--samples N), with the means of u and y over the kept rows removed
             (the benchmark advises removing them: offsets of the acquisition).
  pendulum   double_pendulum_freeswing_1kHz.csv -> double_pendulum_relative.csv
             adds q2 = phi2 - phi1 and q2_dot = phi2_dot - phi1_dot (the model's second joint is
             relative to the first); every other column is kept as it is.
  tx40       tx40_mdh_modified.urdf MESHES -> tx40.urdf
             the Staubli TX40's URDF with a <mujoco> element after <robot>: the mesh folder MESHES
             (an absolute path), visual meshes discarded, boundinertia 1e-6 (link 6 has zero inertia,
             which MuJoCo refuses for a moving body), the recording's step of 0.2 ms and contacts off
             (the arm's links touch at its joints); nothing else is changed.

usage: prepare.py silverbox SNLS80mV.csv OUT.csv [--samples N]
       prepare.py pendulum double_pendulum_freeswing_1kHz.csv OUT.csv
       prepare.py tx40 tx40_mdh_modified.urdf MESHES OUT.urdf
"""
import os
import re
import csv
import sys


def silverbox(src, dst, samples=None):
    first, end = 40650, 127400
    if samples is not None:
        end = min(end, first + samples)
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))[first:end]
    u = [float(r["u_V1"]) for r in rows]
    y = [float(r["y_V2"]) for r in rows]
    mu, my = sum(u) / len(u), sum(y) / len(y)
    with open(dst, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "sample", "u", "y"])
        for r, ui, yi in zip(rows, u, y):
            # the benchmark's own time stamps, as written (sample / fs to 9 decimals)
            w.writerow([r["t"], r["sample"], repr(ui - mu), repr(yi - my)])
    print(f"{dst}: samples {first}..{end - 1} ({len(rows)} rows), removed means u {mu:.6e} V, y {my:.6e} V")


def pendulum(src, dst):
    with open(src, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        names = reader.fieldnames
    with open(dst, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names + ["q2", "q2_dot"])
        for r in rows:
            q2 = float(r["phi2"]) - float(r["phi1"])
            q2d = float(r["phi2_dot"]) - float(r["phi1_dot"])
            w.writerow([r[n] for n in names] + [repr(q2), repr(q2d)])
    print(f"{dst}: {len(rows)} rows, added q2 = phi2 - phi1, q2_dot = phi2_dot - phi1_dot")


def tx40(src, meshes, dst):
    with open(src) as f:
        text = f.read()
    robot = re.search(r"<robot\b[^>]*>", text)
    if robot is None:
        sys.exit(f"{src}: no <robot> element")
    element = (f'<mujoco><compiler meshdir="{os.path.abspath(meshes)}" discardvisual="true" boundinertia="1e-6"/>'
               '<option timestep="0.0002"><flag contact="disable"/></option></mujoco>')
    with open(dst, "w") as f:
        f.write(text[:robot.end()] + element + text[robot.end():])
    print(f"{dst}: {src} with {element}")


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) >= 3 and args[0] == "silverbox":
        n = int(args[4]) if len(args) == 5 and args[3] == "--samples" else None
        silverbox(args[1], args[2], n)
    elif len(args) == 3 and args[0] == "pendulum":
        pendulum(args[1], args[2])
    elif len(args) == 4 and args[0] == "tx40":
        tx40(args[1], args[2], args[3])
    else:
        sys.exit(__doc__)
