#!/usr/bin/env bash
# The MPI tests (issue "Beyond one machine"): `mpirun -np 2` on this machine against one process.
#
#   bash mpi_tests.sh GPILQG MPIEXEC CASE
#
# CASE is one of
#   equal    a run spread over 2 and 3 ranks writes the single-process result (same_results.py)
#   resume   rank 1 is killed (SIGKILL) mid-run; the checkpoint keeps every finished iteration; a
#            resume in which one unit's file is damaged fails naming the rank and the unit, keeping
#            the other ranks' work; after removing that file, a resume over 2 ranks completes and
#            equals the single-process result
#   sweep    a 2 x 2 sweep (gp.backend x loop.rollouts, 2 seeds) over 2 ranks equals the single-process
#            sweep; a grid point equals `gpilqg run` with that point's config; the summary figure is
#            written; a grid field the run config does not have is refused naming it
#   profile  `gpilqg profile` over 2 ranks reports the single process's rows (every number but the times)
# Each case works in its own temporary folder.
set -euo pipefail
gpilqg="$1"; mpiexec="$2"; case_name="$3"
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/gpilqg_mpi_${case_name}.XXXXXX")"
trap '[ -n "${GPILQG_TEST_KEEP:-}" ] && echo "kept $work" || rm -rf "$work"' EXIT
cd "$work"
python=/usr/bin/python3

# Open MPI refuses root unless told; --oversubscribe lets 3 ranks share 2 cores.
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none  # containers often forbid the ptrace it needs
# Under ASan (the sanitizer suite), Open MPI's own allocations that live until exit are not gpilqg's
# leaks. Its libraries have no frame pointers, so only the slow unwinder names them in a leak's stack.
export OMPI_MCA_mca_base_component_disable_dlclose=1
export LSAN_OPTIONS="suppressions=$here/lsan_openmpi.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0"
mpi() { local np="$1"; shift; "$mpiexec" -np "$np" --oversubscribe "$@"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

# The tiny run of the C++ tests (tests/experiments/tiny_run_config.hpp): two tasks (the second a
# transfer task), every algorithm, in about a second.
sed -n '/kTinyRun = R"(/,/^)";/p' "$here/../experiments/tiny_run_config.hpp" | sed '1d;$d' > tiny.toml
[ -s tiny.toml ] || fail "could not extract the tiny run config"

single() { "$gpilqg" run cartpole --config tiny.toml --seeds "$1" --out single.h5 --no-plots > single.log 2>&1; }

case "$case_name" in
equal)
  single 3
  for np in 2 3; do
    mpi "$np" "$gpilqg" run cartpole --config tiny.toml --seeds 3 --out "mpi$np.h5" --no-plots > "mpi$np.log" 2>&1 \
      || { status=$?; cat "mpi$np.log"; fail "mpirun -np $np exited $status"; }
    grep -q "^rank 1: [1-9][0-9]* units" "mpi$np.log" || { cat "mpi$np.log"; fail "rank 1 ran no unit with -np $np"; }
    $python "$here/same_results.py" single.h5 "mpi$np.h5" || fail "-np $np differs from the single-process result"
    [ ! -e "mpi$np.h5.checkpoint" ] || fail "the checkpoint of a finished run was left behind"
  done
  # Bad input stops every rank before any work, reported once, exit 2 (no rank waits for another).
  set +e
  mpi 2 "$gpilqg" run cartpole --config missing.toml --out bad.h5 --no-plots > bad.log 2>&1
  status=$?
  set -e
  [ "$status" -ne 0 ] || fail "a missing config exited 0"
  [ "$(grep -c '^error: .*missing.toml' bad.log)" -eq 1 ] || { cat bad.log; fail "the error was not reported exactly once"; }
  [ ! -e bad.h5.checkpoint ] || fail "bad input left a checkpoint"
  ;;
resume)
  cat tiny.toml > slow.toml
  sed -i 's/^iterations = 2/iterations = 4/; s/^exact_points = 40/exact_points = 120/' slow.toml
  "$gpilqg" run cartpole --config slow.toml --seeds 4 --out single.h5 --no-plots > single.log 2>&1
  # Unit files in the checkpoint (not the temporaries of writes in progress, "<file>.tmp-<pid>-<n>").
  units_kept() { ls mpi.h5.checkpoint 2>/dev/null | grep -c '^seed-.*\.h5$' || true; }
  mpi 2 "$gpilqg" run cartpole --config slow.toml --seeds 4 --out mpi.h5 --no-plots > killed.log 2>&1 &
  launcher=$!
  # Rank 1 dies as soon as some units have finished, in the middle of the run.
  victim=""
  for _ in $(seq 1 3000); do
    if [ "$(units_kept)" -ge 6 ]; then
      for pid in $(pgrep -f "run cartpole --config slow.toml" || true); do
        if tr '\0' '\n' < "/proc/$pid/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1"; then victim=$pid; fi
      done
      [ -n "$victim" ] && break
    fi
    sleep 0.01
  done
  [ -n "$victim" ] || { wait "$launcher" || true; cat killed.log; fail "found no rank 1 to kill"; }
  kill -9 "$victim"
  if wait "$launcher"; then fail "mpirun exited 0 although rank 1 was killed"; fi
  [ ! -e mpi.h5 ] || fail "a killed run wrote a result file"
  kept=$(units_kept)
  [ "$kept" -ge 6 ] || fail "the checkpoint keeps $kept unit files"
  [ -e mpi.h5.checkpoint/manifest.h5 ] || fail "the checkpoint lost its manifest"

  # A damaged unit file: the resume fails on the rank that meets it, naming rank and unit.
  damaged=$(ls mpi.h5.checkpoint | grep '^seed-1_task-0_ilqg_real.h5$' || ls mpi.h5.checkpoint | grep '^seed-.*\.h5$' | head -1)
  echo "not HDF5" > "mpi.h5.checkpoint/$damaged"
  set +e
  mpi 2 "$gpilqg" run cartpole --config slow.toml --seeds 4 --out mpi.h5 --no-plots --resume > damaged.log 2>&1
  status=$?
  set -e
  [ "$status" -ne 0 ] || fail "a resume over a damaged unit file exited 0"
  grep -q "^error: rank [01] of 2 failed on seed [0-9], task [a-z]*, [a-z_]*: " damaged.log \
    || { cat damaged.log; fail "no message naming the rank and the unit"; }
  grep -q "continue with --resume" damaged.log || { cat damaged.log; fail "the message does not say how to continue"; }
  [ "$(grep -c '^error: ' damaged.log)" -eq 1 ] || { cat damaged.log; fail "the error was reported more than once"; }
  [ -e mpi.h5.checkpoint/manifest.h5 ] || fail "the failed resume lost the checkpoint"

  rm "mpi.h5.checkpoint/$damaged"
  mpi 2 "$gpilqg" run cartpole --config slow.toml --seeds 4 --out mpi.h5 --no-plots --resume > resumed.log 2>&1 \
    || { cat resumed.log; fail "the resume exited $?"; }
  grep -q "resumed after iteration" resumed.log || { cat resumed.log; fail "nothing was resumed"; }
  $python "$here/same_results.py" single.h5 mpi.h5 || fail "the resumed run differs from the single-process result"
  ;;
sweep)
  printf 'system = "cartpole"\nconfig = "tiny.toml"\nseeds = 2\n[grid]\n"gp.backend" = ["exact", "fitc"]\n"loop.rollouts" = [1, 2]\n' > sweep.toml
  "$gpilqg" sweep sweep.toml --out single.h5 --no-plots > single.log 2>&1 || { cat single.log; fail "the single-process sweep failed"; }
  mpi 2 "$gpilqg" sweep sweep.toml --out mpi.h5 --plots figures > mpi.log 2>&1 || { cat mpi.log; fail "mpirun sweep exited $?"; }
  $python "$here/same_results.py" single.h5 mpi.h5 || fail "the sweep over 2 ranks differs from the single-process sweep"
  [ -s figures/sweep_cost.png ] || fail "no summary figure"
  # Point 3 (fitc, 2 rollouts): the run config with those two fields, run directly.
  sed 's/^\[gp\]$/[gp]\nbackend = "fitc"/; s/^rollouts = 1$/rollouts = 2/' tiny.toml > point3.toml
  "$gpilqg" run cartpole --config point3.toml --seeds 2 --out point3.h5 --no-plots > point3.log 2>&1
  $python "$here/same_results.py" mpi.h5:/point_3 point3.h5 || fail "grid point 3 differs from gpilqg run with its config"
  printf 'system = "cartpole"\n[grid]\n"gp.bakend" = ["exact"]\n' > typo.toml
  set +e
  "$gpilqg" sweep typo.toml --no-plots > typo.log 2>&1
  status=$?
  set -e
  [ "$status" -eq 2 ] && grep -q "^error: .*typo.toml.*gp.bakend" typo.log || { cat typo.log; fail "an unknown grid field was not refused by name"; }
  ;;
profile)
  data="$here/../../data/cartpole_hidden_friction.csv"
  args=(profile "$data" --system cartpole --backends exact,fitc,ssgp --sizes 100,300 --json)
  "$gpilqg" "${args[@]}" > single.json 2> single.log || { cat single.log; fail "the single-process profile failed"; }
  mpi 2 "$gpilqg" "${args[@]}" > mpi.json 2> mpi.log || { cat mpi.log; fail "mpirun profile exited $?"; }
  grep -q '^\[rank 1\] profile: ' mpi.log || { cat mpi.log; fail "rank 1 profiled nothing"; }
  $python - single.json mpi.json <<'PY' || fail "the profile over 2 ranks differs from the single process's"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
untimed = lambda rows: [{k: v for k, v in r.items() if not k.endswith("_s")} for r in rows]
assert len(a["rows"]) == 6, len(a["rows"])
assert untimed(a["rows"]) == untimed(b["rows"]), "rows differ"
assert {k: v for k, v in a.items() if k != "rows"} == {k: v for k, v in b.items() if k != "rows"}, "header differs"
PY
  ;;
*)
  fail "unknown case '$case_name'"
  ;;
esac
echo "PASS: $case_name"
