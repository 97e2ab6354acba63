#!/usr/bin/env bash
# The main job until the experiments land: make "real-world" cart-pole measurements (the paper's
# 30% longer pole, multiplicative actuator noise, observation noise), store them as CSV and HDF5,
# and summarise both through the measurement reader that validates every row.
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
