#!/usr/bin/env bash
# Algorithm 1 one round at a time, as on hardware, with `gpilqg rollout` standing in for the robot
# (the cart-pole's real preset) and its logger:
#
#   plan (round 0: the simulator alone) -> run the policy on the robot -> log -> plan again on all logs
#
# Each round also runs the policy 5 times without exploration and prints its task cost, to watch the
# cost fall. Usage: bash examples/robot_loop/loop.sh [OUT_DIR]   (GPILQG=path/to/gpilqg to override)
set -euo pipefail
here="$(dirname "$0")"
gpilqg="${GPILQG:-$here/../../build/experiments/gpilqg}"
out="${1:-out/robot_loop}"
config="$here/cartpole_swingup.toml"
mkdir -p "$out"

robot=(--system cartpole --preset real --multiplicative-noise 0.02 --observation-noise 0.002)
data=()
previous=()
for round in 0 1 2 3; do
  echo "== round $round"
  "$gpilqg" plan "$config" "${data[@]}" "${previous[@]}" --seed 1 --out "$out/policy_$round.h5"
  "$gpilqg" rollout "${robot[@]}" --policy "$out/policy_$round.h5" --cost "$config" --episodes 5 --seed 1000 \
    --out "$out/check_$round.csv"
  [ "$round" = 3 ] && break
  "$gpilqg" rollout "${robot[@]}" --policy "$out/policy_$round.h5" --episodes 5 --exploration 8 --seed 1 \
    --out "$out/log_$round.h5"
  data+=(--data "$out/log_$round.h5")
  previous=(--previous "$out/policy_$round.h5")
done
