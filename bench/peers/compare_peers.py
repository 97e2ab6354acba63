#!/usr/bin/python3
"""gpilqg's GP against the peer a user would pick instead, side by side in one run, on the same data,
N, D and hyperparameters:

  a. exact GP NLML + gradient, SE-ARD + noise, D = 5, N = 1,000 and 4,000   vs scikit-learn
  b. a whole exact-GP fit at N = 1,000, one start from the same point        vs scikit-learn
  c. FITC NLML + gradient, N = 5,000, M = 100                                vs GPML under Octave
  d. batched exact prediction with variance, 1,750 points at N = 4,000       vs scikit-learn
  e. a whole exact-GP fit as a user calls it, N = 1,000 and 4,000: one start  vs scikit-learn
     each, from each library's own default (gpilqg: its data-driven start and box, fit.hpp;
     scikit-learn: GaussianProcessRegressor(ConstantKernel() * RBF(ones(D)) + WhiteKernel(),
     n_restarts_optimizer=0), every parameter and setting at its documented default), gpilqg on
     2 threads, the peer on --peer-threads; both optima scored with one function (scikit-learn's
     log_marginal_likelihood with alpha = 0, the model both fit)

Usage, from the repository root (Debian's /usr/bin/python3, which has NumPy, h5py and scikit-learn; build
the program first):

  cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DGPILQG_BUILD_BENCH=ON
  cmake --build build-bench -j2 --target gpilqg_peer_cases
  /usr/bin/python3 bench/peers/compare_peers.py --build build-bench --out peers.json

  --quick          small sizes (the ctest smoke test bench_peers_quick)
  --repeats K      timed repetitions of cases a, c, d (default 3; --quick 2); --fit-repeats (default 1)
                   for cases b and e
  --peer-threads T OMP_NUM_THREADS = OPENBLAS_NUM_THREADS = MKL_NUM_THREADS for the peers (default 2:
                   the peers on both cores, as gpilqg's 2-thread column)
  --fit-sizes N,.. case e at these N only (e.g. --fit-sizes 1000 --fit-repeats 3: the slow N = 4,000
                   scikit-learn fit, about 20 s per evaluation, left out)
  GPML_PATH=DIR    an unpacked GPML (not packaged in Debian); without it case c's peer is skipped

Both sides call the same OpenBLAS (libblas.so.3), which picks its kernels for the CPU model when it
loads; on a CPU model its build does not know it falls back to its Prescott (SSE3) kernels, on both
sides alike. The report names the kernels it chose (threadpoolctl's "architecture"); exporting
OPENBLAS_CORETYPE (e.g. SkylakeX on an AVX-512 CPU) before the run selects them for both sides.

The script writes the data to one HDF5 file (peer_data.py), runs gpilqg_peer_cases on it with 1 and
with 2 threads (it times itself and prints JSON; case e in the 2-thread run only; each run with the
thread variables set to its own thread count), times the peers in this process, and checks that
the two agree: the peer is also the oracle (NLML and gradient after the chain rule between the
parametrisations, peer_sklearn.py; predictions; FITC against GPML or a NumPy formula). It prints a
Markdown table of times and ratios peer time / gpilqg time to stdout (progress to stderr) and writes
everything to --out as JSON. Exit status: 0, or 1 when a check fails, 2 for bad usage or a missing
program; with --strict, 77 when scikit-learn is missing (a skip for ctest; otherwise a missing peer
is reported and skipped).
"""

import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
TOLERANCE = 1e-8
SKIP = 77
DEFAULT_FIT_THREADS = 2  # case e: gpilqg on both cores of the development machine


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default="build-bench", help="build folder with bench/gpilqg_peer_cases (default build-bench)")
    p.add_argument("--program", help="the gpilqg_peer_cases program (default BUILD/bench/gpilqg_peer_cases)")
    p.add_argument("--quick", action="store_true", help="small sizes for a smoke test")
    p.add_argument("--repeats", type=int, help="timed repetitions of cases a, c, d (default 3, --quick 2)")
    p.add_argument("--fit-repeats", type=int, default=1, help="timed repetitions of the fits (default 1)")
    p.add_argument("--peer-threads", type=int, default=2, help="BLAS/OpenMP threads of the peers (default 2)")
    p.add_argument("--fit-sizes", help="case e at these N, comma-separated (default 1000,4000; --quick 300,600)")
    p.add_argument("--out", help="write the whole report as JSON to this file")
    p.add_argument("--data", help="keep the HDF5 data file at this path (default a temporary file)")
    p.add_argument("--strict", action="store_true", help="exit 77 when scikit-learn is missing")
    args = p.parse_args(argv)
    if args.repeats is None:
        args.repeats = 2 if args.quick else 3
    for name in ("repeats", "fit_repeats", "peer_threads"):
        if getattr(args, name) < 1:
            p.error("--%s must be >= 1" % name.replace("_", "-"))
    if args.fit_sizes is not None:
        try:
            args.fit_sizes = [int(n) for n in args.fit_sizes.split(",")]
        except ValueError:
            p.error("--fit-sizes expects comma-separated whole numbers, got %r" % args.fit_sizes)
        if not args.fit_sizes or min(args.fit_sizes) < 10:
            p.error("--fit-sizes expects sizes of at least 10 points")
    if args.program is None:
        args.program = os.path.join(args.build, "bench", "gpilqg_peer_cases")
    if not os.access(args.program, os.X_OK):
        p.error("%s is not an executable; build it: cmake --build %s -j2 --target gpilqg_peer_cases "
                "(configured with -DGPILQG_BUILD_BENCH=ON)" % (args.program, args.build))
    return args


def thread_count(t):
    return "1 thread" if t == 1 else "%d threads" % t


def progress(text):
    print(text, file=sys.stderr, flush=True)


def commit_and_date():
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        head = subprocess.run(["git", "-C", here, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", here, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        commit = head + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    return commit, datetime.date.today().isoformat()


def machine():
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), cpu)
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count() or 0, "load_start": os.getloadavg()[0]}


def peer_libraries():
    """The numerical libraries the peers run on, and how many threads their BLAS uses."""
    import numpy
    text = "NumPy %s" % numpy.__version__
    try:
        import sklearn
        text = "scikit-learn %s, " % sklearn.__version__ + text
    except ImportError:
        pass
    try:
        from threadpoolctl import threadpool_info
        pools = ["%s %s (%s, %s kernels, %d thread%s)" % (
                     p.get("internal_api"), p.get("version") or "", p.get("filepath"), p.get("architecture") or "its",
                     p.get("num_threads"), "" if p.get("num_threads") == 1 else "s")
                 for p in threadpool_info()]
        if pools:
            text += "; BLAS: " + "; ".join(pools)
    except ImportError:
        pass
    return text


def run_gpilqg(args, data_file, threads):
    """gpilqg_peer_cases on `threads` threads, with the thread variables set to the same count (case e,
    the fits from the default start, in the run on DEFAULT_FIT_THREADS threads only)."""
    command = [args.program, data_file, "--threads", str(threads), "--repeats", str(args.repeats),
               "--fit-repeats", str(args.fit_repeats)]
    if threads == DEFAULT_FIT_THREADS:
        command.append("--default-fits")
    environment = dict(os.environ, **{name: str(threads) for name in THREAD_VARIABLES})
    progress("gpilqg, %s: %s" % (thread_count(threads), " ".join(command)))
    run = subprocess.run(command, stdout=subprocess.PIPE, text=True, env=environment)
    if run.returncode != 0:
        sys.exit("error: %s exited with %d" % (args.program, run.returncode))
    return json.loads(run.stdout)


def difference(ours, reference, scale=None):
    """max |ours - reference| / max(scale, 1e-300), scale = max |reference| (at least 1) by default."""
    import numpy as np
    ours, reference = np.atleast_1d(np.asarray(ours, float)), np.atleast_1d(np.asarray(reference, float))
    if ours.shape != reference.shape:
        return float("inf")
    if scale is None:
        scale = max(float(np.max(np.abs(reference))), 1.0)
    return float(np.max(np.abs(ours - reference))) / max(scale, 1e-300)


def add_check(checks, name, diff, tolerance=TOLERANCE):
    checks.append({"check": name, "difference": diff, "tolerance": tolerance, "ok": bool(diff <= tolerance)})


def compare(args, cases, ours, sk, checks, notes):
    """The table's rows (and the checks) from gpilqg's runs `ours` {1: json, 2: json} and the peers.
    `sk` is the module peer_sklearn, or a string: why scikit-learn is missing."""
    import numpy as np
    import fitc_reference
    import peer_gpml

    rows = []
    X, y, theta, d = cases["X"], cases["y"], cases["theta"], cases["X"].shape[1]
    sf, sn2 = np.exp(theta[d]), np.exp(2.0 * theta[d + 1])
    skipped = None if not isinstance(sk, str) else {"skipped": sk}

    for i, n in enumerate(cases["nlml_sizes"]):
        progress("scikit-learn, case a, N = %d" % n)
        peer = skipped or sk.nlml_case(X[:n], y[:n], theta, args.repeats)
        rows.append({"case": "a. exact NLML + gradient", "size": "N = %d, D = %d" % (n, d), "peer": "scikit-learn",
                     "gpilqg_1": ours[1]["nlml"][i], "gpilqg_2": ours[2]["nlml"][i], "peer_result": peer})
        if skipped is None:
            for t in (1, 2):
                g = ours[t]["nlml"][i]
                add_check(checks, "a. NLML, N = %d, %s, vs scikit-learn" % (n, thread_count(t)),
                          difference(g["nlml"], peer["nlml"]))
                add_check(checks, "a. NLML gradient, N = %d, %s, vs scikit-learn" % (n, thread_count(t)),
                          difference(g["gradient"], peer["gradient"]))

    n = cases["fit_size"]
    fit_table = []
    for t in (1, 2):
        f = ours[t]["fit"]
        fit_table.append({"who": "gpilqg, %s" % thread_count(t), "best_s": f["best_s"], "median_s": f["median_s"],
                          "evaluations": f["evaluations"], "nlml": f["nlml"], "stopped": f["termination"],
                          "theta": f["theta"]})
    if skipped is None:
        progress("scikit-learn, case b, N = %d" % n)
        f1 = ours[1]["fit"]
        peer = sk.fit_case(X[:n], y[:n], f1["initial"], f1["lower"], f1["upper"], args.fit_repeats)
        regressor = peer.pop("regressor")
        for r, t in zip(fit_table, (1, 2)):
            gpilqg_value = r["nlml"]
            r["nlml"] = sk.nlml_at(regressor, r["theta"])
            add_check(checks, "b. NLML at gpilqg's optimum (%s), vs scikit-learn" % thread_count(t),
                      difference(gpilqg_value, r["nlml"]))
        fit_table.append({"who": "scikit-learn", "best_s": peer["best_s"], "median_s": peer["median_s"],
                          "evaluations": peer["evaluations"], "nlml": peer["nlml"],
                          "stopped": "; ".join(peer["warnings"]) or "L-BFGS-B's tolerances", "theta": peer["theta"]})
        notes.append("Fit: gpilqg's NLopt L-BFGS stops at ftol_rel %g, xtol_rel %g or %d evaluations; scikit-learn's "
                     "L-BFGS-B at SciPy's defaults. NLML(gpilqg optimum) - NLML(scikit-learn optimum) = %.3g "
                     "(1 thread)." % (f1["relative_tolerance"], f1["parameter_tolerance"], f1["max_evaluations"],
                                      fit_table[0]["nlml"] - peer["nlml"]))
    else:
        peer = skipped
    rows.append({"case": "b. exact fit (one start)", "size": "N = %d, D = %d" % (n, d), "peer": "scikit-learn",
                 "gpilqg_1": ours[1]["fit"], "gpilqg_2": ours[2]["fit"], "peer_result": peer})

    Xf, yf, tf, m = cases["fitc_X"], cases["fitc_y"], cases["fitc_theta"], cases["fitc_inducing"]
    progress("GPML, case c, N = %d, M = %d" % (len(yf), m))
    peer = peer_gpml.fitc_case(Xf, yf, tf, m, args.repeats)
    rows.append({"case": "c. FITC NLML + gradient", "size": "N = %d, M = %d, D = %d" % (len(yf), m, d), "peer": "GPML",
                 "gpilqg_1": ours[1]["fitc"], "gpilqg_2": ours[2]["fitc"], "peer_result": peer})
    formula = fitc_reference.fitc_nlml(Xf, yf, tf, m)
    for t in (1, 2):
        add_check(checks, "c. FITC NLML, %s, vs the NumPy formula" % thread_count(t),
                  difference(ours[t]["fitc"]["nlml"], formula))
        if "skipped" not in peer:
            add_check(checks, "c. FITC NLML, %s, vs GPML" % thread_count(t), difference(ours[t]["fitc"]["nlml"], peer["nlml"]))
            gradient = ours[t]["fitc"]["gradient"]
            add_check(checks, "c. FITC gradient, %s, vs GPML" % thread_count(t),
                      difference(gradient[:len(peer["gradient"])], peer["gradient"]))
    if "skipped" not in peer:
        notes.append("GPML: %s; its times are Octave's tic/toc around gp(...)." % peer["version"])

    n = cases["predict_size"]
    progress("scikit-learn, case d, N = %d, %d points" % (n, len(cases["X_test"])))
    peer = skipped or sk.predict_case(X[:n], y[:n], theta, cases["X_test"], args.repeats)
    rows.append({"case": "d. exact prediction, mean + variance", "size": "N = %d, %d points, D = %d" % (
        n, len(cases["X_test"]), d), "peer": "scikit-learn", "gpilqg_1": ours[1]["predict"],
        "gpilqg_2": ours[2]["predict"], "peer_result": peer})
    if skipped is None:
        for t in (1, 2):
            p = ours[t]["predict"]
            add_check(checks, "d. mean / sf, %s, vs scikit-learn" % thread_count(t), difference(p["mean"], peer["mean"], sf))
            add_check(checks, "d. latent variance / sf^2, %s, vs scikit-learn (std^2 - sn^2)" % thread_count(t),
                      difference(p["variance"], peer["variance"], sf * sf))
        notes.append("Prediction: scikit-learn's std includes the noise sn^2 = %.3g (WhiteKernel); gpilqg's variance is "
                     "latent." % sn2)
    default_fits = []
    for i, n in enumerate(cases["fit_sizes"]):
        f = ours[DEFAULT_FIT_THREADS]["default_fits"][i]
        entry = {"size": "N = %d, D = %d" % (n, d), "gpilqg": f}
        if skipped is None:
            progress("scikit-learn, case e, N = %d" % n)
            peer = sk.default_fit_case(X[:n], y[:n], args.fit_repeats)
            gpilqg_value = f["nlml"]
            f["nlml_gpilqg"] = gpilqg_value
            f["nlml"] = sk.nlml_of(X[:n], y[:n], f["theta"])
            add_check(checks, "e. NLML at gpilqg's optimum, N = %d, vs scikit-learn" % n,
                      difference(gpilqg_value, f["nlml"]))
            entry["peer"] = peer
        else:
            entry["peer"] = skipped
        default_fits.append(entry)
        rows.append({"case": "e. exact fit, each from its own default start", "size": entry["size"],
                     "peer": "scikit-learn", "gpilqg_1": None, "gpilqg_2": f, "peer_result": entry["peer"]})
    return rows, fit_table, default_fits


def without_arrays(value):
    """The report without the prediction arrays and NumPy types, for JSON."""
    import numpy as np
    if isinstance(value, dict):
        return {k: without_arrays(v) for k, v in value.items() if k not in ("mean", "variance")}
    if isinstance(value, (list, tuple)):
        return [without_arrays(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def main(argv=None):
    args = parse_args(argv)
    for name in THREAD_VARIABLES:  # before NumPy is imported, and inherited by gpilqg_peer_cases
        os.environ[name] = str(args.peer_threads)
    import numpy  # noqa: F401  (after the thread variables)
    import peer_data
    try:
        import peer_sklearn as sk
    except ImportError as e:
        sk = "scikit-learn is not importable (%s; Debian package python3-sklearn)" % e
        if args.strict:
            print("skipped: " + sk, file=sys.stderr)
            return SKIP

    commit, date = commit_and_date()
    info = machine()
    sizes = dict(peer_data.QUICK if args.quick else peer_data.FULL)
    if args.fit_sizes is not None:
        sizes["fit_sizes"] = args.fit_sizes
    cases = peer_data.make_cases(sizes)
    with tempfile.TemporaryDirectory(prefix="gpilqg_peers_") as work:
        data_file = args.data or os.path.join(work, "peers.h5")
        peer_data.write_cases(data_file, cases)
        ours = {t: run_gpilqg(args, data_file, t) for t in (1, 2)}
    checks, notes = [], []
    if isinstance(sk, str):
        notes.append("scikit-learn skipped: " + sk)
    rows, fit_table, default_fits = compare(args, cases, ours, sk, checks, notes)
    info["load_end"] = os.getloadavg()[0]

    report = {"commit": commit, "date": date, "machine": info,
              "settings": {"quick": args.quick, "sizes": sizes, "repeats": args.repeats, "fit_repeats": args.fit_repeats,
                           "program": args.program, "peer_threads": args.peer_threads,
                           "thread_variables": {k: os.environ[k] for k in THREAD_VARIABLES},
                           "peer_libraries": peer_libraries(), "tolerance": TOLERANCE},
              "rows": rows, "fit_table": fit_table, "default_fits": default_fits, "checks": checks, "notes": notes,
              "gpilqg": {str(t): ours[t] for t in ours}, "ok": all(c["ok"] for c in checks)}
    import peer_report
    sys.stdout.write(peer_report.markdown(report))
    if args.out:
        with open(args.out, "w") as f:
            json.dump(without_arrays(report), f, indent=1)
            f.write("\n")
    if not report["ok"]:
        print("error: a check failed: gpilqg and its oracle disagree (see the checks table)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
