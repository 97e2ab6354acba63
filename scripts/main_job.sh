#!/usr/bin/env bash
# The main job until the experiments land:
#  1. make "real-world" measurements of both systems (the paper's 30% longer pole and 40% heavier
#     quadrotor, multiplicative actuator noise, observation noise) as CSV and HDF5, and summarise them
#     through the validating reader;
#  2. solve the reference cart-pole swing-up with iLQR (unconstrained and with |u| <= 2.5, compare
#     with shared/reference/ilqr_cartpole: 0.645046921446 and 0.677802315918) and under
#     control-multiplicative noise with iLQG.
set -euo pipefail
gpilqg="${1:-build/experiments/gpilqg}"
out="${GPILQG_OUT:-out}"
mkdir -p "$out"
"$gpilqg" simulate --system cartpole --preset real --episodes 8 --steps 250 --dt 0.02 \
  --multiplicative-noise 0.1 --observation-noise 0.001 --seed 7 --out "$out/cartpole_real.csv"
"$gpilqg" simulate --system quadrotor --preset real --episodes 4 --steps 100 --dt 0.02 \
  --multiplicative-noise 0.05 --seed 7 --out "$out/quadrotor_real.h5"
"$gpilqg" data info "$out/cartpole_real.csv" --system cartpole
"$gpilqg" data info "$out/quadrotor_real.h5" --system quadrotor
for problem in cartpole_swingup cartpole_swingup_box cartpole_swingup_ilqg; do
  echo "== gpilqg solve experiments/configs/$problem.toml"
  "$gpilqg" solve "experiments/configs/$problem.toml"
done
