#!/usr/bin/env bash
# Builds the libFuzzer programs with clang (ASan + UBSan, assertions on) in build-fuzz/ and runs each
# for a bounded time, then prints the executions and time per target.
#
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]     default 60 seconds per target, all targets
#
# Targets: measurements_csv measurements_hdf5_structured toml_configs (the default list), and
# measurements_hdf5 (raw bytes of HDF5 files; asked for by name). The raw-bytes target mostly finds
# crashes inside libhdf5 itself (tests/fuzz/upstream_crashes/README.md), so it runs in fork mode,
# continues past them, and lists what it found for triage instead of failing.
# Each run starts from the committed seeds (tests/fuzz/corpus/<target>/) plus what earlier runs found
# (build-fuzz/corpus/<target>/). A finding (crash, leak, UB, broken invariant, undocumented
# exception) is saved under build-fuzz/findings/<target>/ and the script exits with status 1; replay
# it with build-fuzz/tests/fuzz/gpilqg_fuzz_<target> FILE, fix the bug, and copy FILE to
# tests/fuzz/regressions/<target>/ so that the normal test suite replays it from then on.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
if ((${#targets[@]} == 0)); then
  targets=(measurements_csv measurements_hdf5_structured toml_configs)
fi
case "$seconds" in ''|*[!0-9]*) echo "usage: bash scripts/fuzz.sh [SECONDS] [TARGET...]" >&2; exit 2 ;; esac
command -v clang++ >/dev/null || { echo "error: clang++ not found; the fuzzers need clang with libFuzzer" >&2; exit 2; }

jobs="$(nproc)"
echo "== configuring and building the fuzzers (build-fuzz/, clang, -O1, ASan + UBSan + libFuzzer)"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DGPILQG_BUILD_FUZZERS=ON -DGPILQG_BUILD_TESTS=OFF -DGPILQG_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target "${targets[@]/#/gpilqg_fuzz_}"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:symbolize=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
summary=()
status=0
for target in "${targets[@]}"; do
  corpus="build-fuzz/corpus/$target"
  findings="build-fuzz/findings/$target"
  mkdir -p "$corpus" "$findings"
  cp -n tests/fuzz/corpus/"$target"/* "$corpus"/ 2>/dev/null || true
  dict=()
  if [ -f "tests/fuzz/$target.dict" ]; then dict=(-dict="tests/fuzz/$target.dict"); fi
  log="build-fuzz/$target.log"
  echo "== fuzzing $target for ${seconds} s (log: $log)"
  upstream=()
  if [ "$target" = measurements_hdf5 ]; then
    upstream=(-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1)
  fi
  before="$(ls "$findings" | wc -l)"
  set +e
  "build-fuzz/tests/fuzz/gpilqg_fuzz_$target" "$corpus" "${dict[@]}" "${upstream[@]}" -max_total_time="$seconds" \
    -timeout=20 -rss_limit_mb=4096 -max_len=16384 -print_final_stats=1 -artifact_prefix="$findings/" >"$log" 2>&1
  code=$?
  set -e
  # (|| true: a log without the line leaves the field empty instead of ending the script)
  runs="$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' | tail -1 || true)"
  time="$(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "$log" | grep -oE 'in [0-9]+' | grep -oE '[0-9]+' | tail -1 || true)"
  if [ -n "${upstream[*]}" ]; then  # fork mode: "#RUNS: ... time: Ss" and "INFO: exiting: N time: Ss"
    runs="$(grep -oE '^#[0-9]+:' "$log" | tr -d '#:' | tail -1 || true)"
    time="$(grep -oE 'time: [0-9]+s' "$log" | grep -oE '[0-9]+' | tail -1 || true)"
  fi
  units="$(ls "$corpus" | wc -l)"
  found=$(( $(ls "$findings" | wc -l) - before ))
  result="ok"
  if [ -n "${upstream[*]}" ]; then
    result="$found new inputs in $findings/ to triage (libhdf5 frames on top: upstream)"
  elif [ "$code" -ne 0 ]; then
    result="FINDING (exit $code, see $log and $findings/)"; status=1
  fi
  summary+=("$(printf '%-30s %12s executions in %6s s, corpus %5s files: %s' "$target" "${runs:-?}" "${time:-$seconds}" "$units" "$result")")
done
echo "== summary"
printf '%s\n' "${summary[@]}"
exit "$status"
