#!/usr/bin/env bash
# The main job: the paper's cart-pole experiment with the default settings (one seed), i.e.
# ilqg_real, ilqg_sim, gp_ilqg (Algorithm 1) and pddp (on gp_ilqg's data) on the swing-up from
# theta = pi/4 and the transfer task from theta = -pi/4. Results: out/run_cartpole.h5; figures: out/*.png.
# Interrupted (Ctrl-C) it keeps its progress in out/run_cartpole.h5.checkpoint/, and running it again
# continues from there (gpilqg run --resume).
set -euo pipefail
gpilqg="${1:-build/experiments/gpilqg}"
out="${GPILQG_OUT:-out}"
mkdir -p "$out"
resume=()
if [[ -d "$out/run_cartpole.h5.checkpoint" ]]; then
  echo "continuing the interrupted run in $out/run_cartpole.h5.checkpoint/" >&2
  resume=(--resume)
fi
"$gpilqg" run cartpole --out "$out/run_cartpole.h5" --plots "$out" "${resume[@]}"
