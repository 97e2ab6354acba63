#!/usr/bin/env bash
# The main job: the paper's cart-pole experiment with the default settings (one seed), i.e.
# ilqg_real, ilqg_sim, gp_ilqg (Algorithm 1), pddp and pddp_own on the swing-up from theta = pi/4 and
# the transfer task from theta = -pi/4. Results: out/run_cartpole.h5; figures: out/*.png.
set -euo pipefail
gpilqg="${1:-build/experiments/gpilqg}"
out="${GPILQG_OUT:-out}"
mkdir -p "$out"
"$gpilqg" run cartpole --out "$out/run_cartpole.h5" --plots "$out"
