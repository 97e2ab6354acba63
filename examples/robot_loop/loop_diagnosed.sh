#!/usr/bin/env bash
# The loop log -> diagnose -> model -> plan -> robot -> log, one round at a time as on hardware, with
# `gpilqg rollout` standing in for the robot (robot_with_friction.toml: a longer pole and Coulomb
# friction on the cart, neither in the simulator):
#
#   round 0: plan on the simulator alone -> robot -> log_0
#   round 1: plan --diagnose on log_0: the diagnosis names the missing physics, writes it as a model
#            file and the round plans on it, the GP learning only what it still misses -> robot -> log_1
#   round 2, 3: plan with [system] model = the diagnosed model file on every log so far
#
# Each round runs its policy 5 times without exploration and prints the task cost; the last lines plan
# on the robot's own model (the optimum a perfect model would give) and check it the same way.
# Usage: bash examples/robot_loop/loop_diagnosed.sh [OUT_DIR]   (GPILQG=path/to/gpilqg to override)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
gpilqg="${GPILQG:-$here/../../build/experiments/gpilqg}"
out="${1:-out/robot_loop_diagnosed}"
config="$here/cartpole_swingup.toml"
mkdir -p "$out"

robot=(--system cartpole --world-model "$here/robot_with_friction.toml" --multiplicative-noise 0.02
       --observation-noise 0.002)
check() {  # 5 episodes without exploration, with the task's cost
  "$gpilqg" rollout "${robot[@]}" --policy "$1" --cost "$config" --episodes 5 --seed 1000 --out "$2"
}
log() {  # 5 episodes with exploration: the next round's data
  "$gpilqg" rollout "${robot[@]}" --policy "$1" --episodes 5 --exploration 8 --seed 1 --out "$2"
}

echo "== round 0"
"$gpilqg" plan "$config" --seed 1 --out "$out/policy_0.h5"
check "$out/policy_0.h5" "$out/check_0.csv"
log "$out/policy_0.h5" "$out/log_0.h5"

echo "== round 1"
"$gpilqg" plan "$config" --data "$out/log_0.h5" --previous "$out/policy_0.h5" --seed 1 \
  --diagnose --write-model "$out/diagnosed.toml" --out "$out/policy_1.h5"
check "$out/policy_1.h5" "$out/check_1.csv"
log "$out/policy_1.h5" "$out/log_1.h5"

# The next rounds' config: the same problem with the diagnosed model as the simulator.
sed 's|^preset = "sim".*$|model = "diagnosed.toml"   # written by plan --diagnose|' "$config" > "$out/cartpole_diagnosed.toml"
data=(--data "$out/log_0.h5" --data "$out/log_1.h5")
for round in 2 3; do
  echo "== round $round"
  "$gpilqg" plan "$out/cartpole_diagnosed.toml" "${data[@]}" --previous "$out/policy_$((round - 1)).h5" --seed 1 \
    --out "$out/policy_$round.h5"
  check "$out/policy_$round.h5" "$out/check_$round.csv"
  [ "$round" = 3 ] && break
  log "$out/policy_$round.h5" "$out/log_$round.h5"
  data+=(--data "$out/log_$round.h5")
done

echo "== the robot's own model (reference)"
sed "s|^preset = \"sim\".*\$|model = \"$here/robot_with_friction.toml\"|" "$config" > "$out/cartpole_robot.toml"
"$gpilqg" plan "$out/cartpole_robot.toml" --seed 1 --out "$out/policy_robot.h5"
check "$out/policy_robot.h5" "$out/check_robot.csv"
