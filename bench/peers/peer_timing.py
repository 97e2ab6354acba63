"""Wall-clock time of a unit of work repeated k times (time.perf_counter, monotonic), in the form
gpilqg_peer_cases reports (bench/peers/peer_timing.hpp): every repetition, best of k and median."""

import statistics
import time


def time_repeated(repeats, work, warm_up=True):
    """Runs work() once untimed when warm_up, then `repeats` timed runs. Returns (timing dict, the
    last result of work())."""
    result = work() if warm_up else None
    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = work()
        seconds.append(time.perf_counter() - start)
    return {"best_s": min(seconds), "median_s": statistics.median(seconds), "times_s": seconds}, result
