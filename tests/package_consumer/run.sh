#!/usr/bin/env bash
# Installs the build tree into a temporary prefix, then configures, builds and runs the consumer;
# then builds the example plugin (examples/acrobot_plugin) against the installed package and uses it
# through the installed program: synthetic data with a hidden friction, a diagnosis that must name it
# within 15%, and the same plugin under a second path refused as a duplicate.
set -euo pipefail
build_dir="$1"; source_dir="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir/tests/package_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer"

gpilqg="$work/prefix/bin/gpilqg"
# The installed program runs on the installed libraries, not on the build tree's. (ldd's output is
# read whole: grep -q leaving a pipe early would fail the pipeline under pipefail.)
libraries="$(ldd "$gpilqg")"
if ! grep -q "libgpilqg_core.so => $work/prefix/" <<<"$libraries"; then
  echo "FAIL: the installed gpilqg does not load the installed libgpilqg_core.so:" >&2
  grep gpilqg <<<"$libraries" >&2
  exit 1
fi

cmake -S "$source_dir/examples/acrobot_plugin" -B "$work/acrobot" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/acrobot" >/dev/null
plugin="$work/acrobot/libacrobot.so"

"$gpilqg" simulate --plugin "$plugin" --system acrobot --preset sim \
  --effect joint_coulomb_friction:theta1=0.2 --out "$work/acrobot.csv"
"$gpilqg" diagnose --plugin "$plugin" --system acrobot --data "$work/acrobot.csv" --json >"$work/diagnosis.json"
/usr/bin/python3 - "$work/diagnosis.json" <<'EOF'
import json, sys
verdict = json.load(open(sys.argv[1]))["verdict"]
value = verdict["parameters"].get("tau") if verdict["effect"] == "joint_coulomb_friction:theta1" else None
ok = value is not None and abs(value - 0.2) <= 0.15 * 0.2
print("plugin: diagnosis verdict", json.dumps(verdict), "ok" if ok else "WRONG (expected joint_coulomb_friction:theta1, tau = 0.2 within 15%)")
sys.exit(0 if ok else 1)
EOF

cp "$plugin" "$work/libacrobot_copy.so"
status=0
"$gpilqg" data info "$work/acrobot.csv" --system acrobot --plugin "$plugin" --plugin "$work/libacrobot_copy.so" \
  2>"$work/duplicate.err" >/dev/null || status=$?
expected="error: plugin '$work/libacrobot_copy.so': system 'acrobot' is registered twice: by $plugin and by $work/libacrobot_copy.so"
if [ "$status" -ne 2 ] || [ "$(head -n 1 "$work/duplicate.err")" != "$expected" ]; then
  echo "FAIL: a second copy of the plugin gave exit $status and:" >&2
  cat "$work/duplicate.err" >&2
  exit 1
fi
echo "plugin: a second copy is refused (exit 2) ok"
