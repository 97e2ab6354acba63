"""The Markdown report of bench/peers/compare_peers.py: the settings line, the timing table with
the ratios peer time / gpilqg time (best of k against best of k), the fit tables (cases b and e) and
the checks."""


def seconds(t):
    """12.3 ms, 4.56 s."""
    return "%.3g ms" % (1e3 * t) if t < 1.0 else "%.3g s" % t


def timing(result):
    """'best (median)', or the reason a peer was skipped."""
    if result is None:
        return "-"
    if "skipped" in result:
        return "skipped: " + result["skipped"]
    return "%s (%s)" % (seconds(result["best_s"]), seconds(result["median_s"]))


def ratio(peer, ours):
    if peer is None or ours is None or "best_s" not in peer:
        return "-"
    return "%.3g" % (peer["best_s"] / ours["best_s"])


def markdown(report):
    s, m = report["settings"], report["machine"]
    lines = ["## gpilqg against its peers" + (" (--quick)" if s["quick"] else ""), ""]
    # The 1-minute load average before the run is other work; at the end it includes this run.
    lines.append("Commit %s, %s; %s, %d cores; load average %.2f before the run%s, %.2f at its end." % (
        report["commit"], report["date"], m["cpu"], m["cores"], m["load_start"],
        " (other work was running)" if m["load_start"] > 0.5 else "", m["load_end"]))
    lines.append("gpilqg: `%s`, timed in C++ (steady_clock). Peers timed in this process (perf_counter). "
                 "Every time is best of %d (median) after one untimed run; the fit %d run(s), no untimed run. "
                 "Ratios: peer best / gpilqg best." % (
                     s["program"], s["repeats"], s["fit_repeats"]))
    lines.append("Peer threads: %s; %s." % (
        ", ".join("%s=%s" % kv for kv in s["thread_variables"].items()), s["peer_libraries"]))
    blas = report.get("gpilqg", {}).get("2", {}).get("blas")
    if blas:
        lines.append("gpilqg's BLAS: %s." % blas)
    lines.append("")
    lines.append("| case | size | gpilqg, 1 thread | gpilqg, 2 threads | peer | peer | peer / gpilqg 1 thread "
                 "| peer / gpilqg 2 threads |")
    lines.append("|---|---|---|---|---|---|---|---|")
    for row in report["rows"]:
        ours1, ours2, peer = row["gpilqg_1"], row["gpilqg_2"], row["peer_result"]
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            row["case"], row["size"], timing(ours1), timing(ours2), row["peer"], timing(peer),
            ratio(peer, ours1), ratio(peer, ours2)))
    lines.append("")
    fit = report.get("fit_table")
    if fit:
        lines.append("Fit (case b): one start from gpilqg's data-driven initial values, in gpilqg's box; both "
                     "optima evaluated with scikit-learn's log_marginal_likelihood.")
        lines.append("")
        lines.append("| fit | time | evaluations | NLML at its optimum | stopped |")
        lines.append("|---|---|---|---|---|")
        for r in fit:
            lines.append("| %s | %s | %d | %.10g | %s |" % (r["who"], timing(r), r["evaluations"], r["nlml"], r["stopped"]))
        lines.append("")
    default_fits = report.get("default_fits")
    if default_fits:
        lines.append("Fit as a user calls it (case e): one start each from each library's own default, gpilqg on "
                     "%d threads, scikit-learn on %d; both optima scored with scikit-learn's log_marginal_likelihood "
                     "(alpha = 0). Ratio: scikit-learn best / gpilqg best." % (2, s["peer_threads"]))
        lines.append("")
        lines.append("| size | gpilqg | evaluations | NLML | scikit-learn | evaluations | NLML | ratio "
                     "| NLML gpilqg - scikit-learn |")
        lines.append("|---|---|---|---|---|---|---|---|---|")
        for e in default_fits:
            ours, peer = e["gpilqg"], e["peer"]
            if "skipped" in peer:
                lines.append("| %s | %s | %d | %.10g | %s | | | | |" % (e["size"], timing(ours), ours["evaluations"],
                                                                     ours["nlml"], timing(peer)))
                continue
            lines.append("| %s | %s | %d | %.10g | %s | %d | %.10g | %s | %.3g |" % (
                e["size"], timing(ours), ours["evaluations"], ours["nlml"], timing(peer), peer["evaluations"],
                peer["nlml"], ratio(peer, ours), ours["nlml"] - peer["nlml"]))
        lines.append("")
    lines.append("Checks (the peer, or a formula, as the oracle):")
    lines.append("")
    lines.append("| check | relative difference | tolerance | |")
    lines.append("|---|---|---|---|")
    for c in report["checks"]:
        lines.append("| %s | %.2e | %.0e | %s |" % (c["check"], c["difference"], c["tolerance"],
                                                     "ok" if c["ok"] else "**FAILED**"))
    for note in report["notes"]:
        lines.append("")
        lines.append(note)
    return "\n".join(lines) + "\n"
