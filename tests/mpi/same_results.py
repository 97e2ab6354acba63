#!/usr/bin/python3
"""Exit 0 when two gpilqg result files hold the same numbers, else print the differences and exit 1.

usage: /usr/bin/python3 same_results.py A.h5[:GROUP] B.h5[:GROUP]

With GROUP, the comparison is of that group (a grid point of a sweep, "/point_3") against the other
file's group or root; the sweep's own attributes of a point (grid_values, label) are not compared.

Every group, dataset and attribute must be present in both, with the same shape and bit-identical
values, except what measures wall-clock time (the time_* datasets, iter_<k>/solve_time) and the
`created` attribute. Used by the MPI tests (mpi_tests.sh): a run spread over ranks must equal the
single-process run.
"""
import sys

import h5py
import numpy as np

WALL_CLOCK = ("time_fit", "time_solve", "time_rollouts", "time_evaluation", "solve_time")


def is_wall_clock(name):
    return name.rsplit("/", 1)[-1] in WALL_CLOCK


SWEEP_ONLY = ("created", "grid_values", "label")


def attributes(obj):
    return {k: v for k, v in obj.attrs.items() if k not in SWEEP_ONLY}


def same_value(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype.kind != b.dtype.kind:
        return False
    if a.dtype.kind == "f":
        return np.array_equal(a, b, equal_nan=True)
    return np.array_equal(a, b)


def compare(a, b):
    problems = []
    names_a, names_b = [], []
    a.visit(names_a.append)
    b.visit(names_b.append)
    if sorted(names_a) != sorted(names_b):
        problems.append(f"objects differ: only in A {sorted(set(names_a) - set(names_b))}, "
                        f"only in B {sorted(set(names_b) - set(names_a))}")
    for name in ["."] + sorted(set(names_a) & set(names_b)):
        x, y = a[name], b[name]
        ax, ay = attributes(x), attributes(y)
        if sorted(ax) != sorted(ay):
            problems.append(f"{name}: attributes {sorted(ax)} vs {sorted(ay)}")
        for key in set(ax) & set(ay):
            if not same_value(ax[key], ay[key]):
                problems.append(f"{name}: attribute {key} differs")
        if isinstance(x, h5py.Dataset) and not is_wall_clock(name):
            if not same_value(x[()], y[()]):
                problems.append(f"{name}: values differ")
    return problems


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    (file_a, _, group_a), (file_b, _, group_b) = (arg.partition(":") for arg in sys.argv[1:3])
    with h5py.File(file_a, "r") as a, h5py.File(file_b, "r") as b:
        problems = compare(a[group_a or "/"], b[group_b or "/"])
    for p in problems:
        print(p)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
