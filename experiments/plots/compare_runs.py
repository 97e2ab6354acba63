"""Side-by-side table of two or more result files of `gpilqg run` on the same seeds: per task and
iteration, the mean normalised cost of an algorithm with its standard error over the seeds, and the
first iteration whose mean is at most a threshold (default 1.05).

    /usr/bin/python3 experiments/plots/compare_runs.py LABEL=A.h5 LABEL=B.h5 [--algorithm gp_ilqg]
        [--threshold 1.05] [--figures PREFIX]

Prints Markdown; with --figures also one PNG per task, PREFIX_<task>.png: the mean normalised cost per
iteration with its standard error as a band, one line per run, on a log axis. The standard error is the seeds' standard deviation over sqrt(S) (S seeds); the
files must hold the same seeds and tasks, which the script checks.
"""
import argparse
import sys

import h5py
import numpy as np


def read(path, algorithm):
    with h5py.File(path, "r") as f:
        seeds = f["seeds"][()].astype(int).tolist()
        tasks = {}
        for name, group in f.items():
            if not isinstance(group, h5py.Group) or algorithm not in group:
                continue
            alg = group[algorithm]
            diagnosis = None
            if "diagnosed_from" in alg:
                diagnosis = [int(v) for v in alg["diagnosed_from"][()]]
            tasks[name] = (alg["normalised_cost"][()], bool(group.attrs.get("transfer", 0)), diagnosis)
        return seeds, tasks


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", help="LABEL=FILE.h5")
    parser.add_argument("--algorithm", default="gp_ilqg")
    parser.add_argument("--threshold", type=float, default=1.05)
    parser.add_argument("--figures", help="write PREFIX_<task>.png per task")
    args = parser.parse_args()
    runs = []
    for item in args.runs:
        label, sep, path = item.partition("=")
        if not sep:
            sys.exit(f"compare_runs.py: '{item}': expected LABEL=FILE.h5")
        runs.append((label, path) + read(path, args.algorithm))
    seeds, tasks = runs[0][2], runs[0][3]
    for label, path, other_seeds, other_tasks in runs[1:]:
        if other_seeds != seeds or set(other_tasks) != set(tasks):
            sys.exit(f"compare_runs.py: {path} holds seeds {other_seeds} and tasks {sorted(other_tasks)}; "
                     f"expected those of {runs[0][1]}: {seeds}, {sorted(tasks)}")
    S = len(seeds)
    for task in sorted(tasks, key=lambda name: tasks[name][1]):  # the first task before the transfer task
        K = tasks[task][0].shape[0]
        transfer = " (transfer task)" if tasks[task][1] else ""
        print(f"\n{task}{transfer}: {args.algorithm}'s normalised cost, mean ± standard error over {S} seeds {seeds}\n")
        print("| run | " + " | ".join(f"iteration {k}" for k in range(K)) + f" | first iteration <= {args.threshold} | seeds <= {args.threshold} at the last |")
        print("|---" * (K + 3) + "|")
        for label, path, _, run_tasks in runs:
            cost, _, diagnosed = run_tasks[task]
            mean = cost.mean(axis=1)
            se = cost.std(axis=1, ddof=1) / np.sqrt(S) if S > 1 else np.zeros(K)
            cells = [f"{m:.3f} ± {e:.3f}" if m < 100 else f"{m:.0f} ± {e:.0f}" for m, e in zip(mean, se)]
            reached = [k for k in range(K) if mean[k] <= args.threshold]
            first = str(reached[0]) if reached else "never"
            last = int((cost[-1] <= args.threshold).sum())
            if diagnosed is not None:
                label += " (diagnosed from iteration " + ", ".join(str(d) for d in diagnosed) + ")"
            print(f"| {label} | " + " | ".join(cells) + f" | {first} | {last} of {S} |")
        if args.figures:
            figure(f"{args.figures}_{task}.png", f"{task}{transfer}", runs, task, S, args)


def figure(path, title, runs, task, S, args):
    """The mean normalised cost per iteration of every run, its standard error as a band."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for label, _, _, run_tasks in runs:
        cost = run_tasks[task][0]
        mean = cost.mean(axis=1)
        se = cost.std(axis=1, ddof=1) / np.sqrt(S) if S > 1 else np.zeros(len(mean))
        k = np.arange(len(mean))
        ax.plot(k, mean, marker="o", label=label)
        ax.fill_between(k, np.maximum(mean - se, 1e-3), mean + se, alpha=0.2)
    ax.axhline(args.threshold, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xticks(np.arange(runs[0][3][task][0].shape[0]))
    ax.set_yscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel(f"{args.algorithm}'s normalised cost (mean ± s.e., {S} seeds)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
