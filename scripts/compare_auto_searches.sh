#!/usr/bin/env bash
# `gpilqg diagnose --auto` with its two searches side by side, on the multi-effect sets of the tests
# (tests/experiments/effect_selection_test.cpp: the same worlds, values, episodes, steps and actuator
# noise; seed 5) and on the drive of tests/support/ball_drive.hpp (made by the test binary's case, see
# docs/diagnosis.md). Prints, per set and search, the effects of the final model with their values and
# the wall time of the call.
#
#   bash scripts/compare_auto_searches.sh build/experiments/gpilqg [extra diagnose options]
set -euo pipefail
gpilqg="${1:?usage: compare_auto_searches.sh GPILQG [diagnose options]}"
shift
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
arm="$source_dir/data/two_link_arm.xml"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# name | system | effects (EFFECT=VALUE, space-separated) | episodes | steps | actuator noise
cases=(
  "cartpole_two|cartpole|cart_coulomb_friction=1.5 pole_viscous_damping=0.3|8|150|0.02"
  "cartpole_three|cartpole|cart_coulomb_friction=1.5 pole_viscous_damping=0.3 external_force_x=0.8|8|150|0.02"
  "cartpole_delay_and_friction|cartpole|input_delay=1.5 cart_coulomb_friction=1.0|8|150|0.02"
  "quadrotor_two|quadrotor|quadratic_drag=0.3 external_force_z=-1.0|8|70|0.002"
  "quadrotor_three|quadrotor|quadratic_drag=0.3 external_force_z=-1.0 actuator_gain=0.9|8|70|0.002"
  "mujoco_arm_two|$arm|joint_viscous_damping:shoulder=0.2 joint_coulomb_friction:elbow=0.1|8|200|0.01"
  "mujoco_arm_three|$arm|joint_viscous_damping:shoulder=0.2 joint_coulomb_friction:elbow=0.1 actuator_gain:elbow_motor=0.8|8|200|0.01"
)

summary() {  # the final model's effects and first parameters from a --json report
  /usr/bin/python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
steps = (r.get("selection") or {}).get("steps") or []
if not steps:
    print("(nothing added)"); sys.exit()
last = steps[-1]
values = {last["effect"]: list(last["parameters"].values())[0]}
for v in last["refitted"]:
    values[v["effect"]] = list(v["parameters"].values())[0]
print(" ".join(f"{k}={v:.4g}" for k, v in values.items()), "|", r["verdict"]["status"])' "$1"
}

printf "%-28s %-8s %7s  %s\n" "set" "search" "time s" "final model | verdict"
for c in "${cases[@]}"; do
  IFS='|' read -r name system effects episodes steps noise <<< "$c"
  args=()
  for e in $effects; do args+=(--effect "$e"); done
  "$gpilqg" simulate --system "$system" --preset sim "${args[@]}" --episodes "$episodes" --steps "$steps" \
    --actuator-noise "$noise" --observation-noise 0.001 --seed 5 --out "$work/$name.csv" > /dev/null
  for search in subsets forward; do
    start=$(date +%s.%N)
    "$gpilqg" diagnose --system "$system" --data "$work/$name.csv" --auto --search "$search" --json "$@" \
      > "$work/$name.$search.json"
    end=$(date +%s.%N)
    printf "%-28s %-8s %7.1f  %s\n" "$name" "$search" "$(echo "$end - $start" | bc)" "$(summary "$work/$name.$search.json")"
  done
done
