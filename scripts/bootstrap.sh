#!/usr/bin/env bash
# Set up a fresh Debian machine, build gpilqg, and run either the main job or the whole test suite.
#
#   bash scripts/bootstrap.sh run    install what is missing, build, run the main job
#   bash scripts/bootstrap.sh test   install what is missing, build, run every test, then the whole
#                                    suite again under AddressSanitizer + UndefinedBehaviorSanitizer
#
# Packages come from Debian only; apt-get runs as root or through sudo, and
# only when something is missing. The build goes to build/ (Release, tests on).
set -euo pipefail
mode="${1:-}"
case "$mode" in run|test) ;; *) echo "usage: bash scripts/bootstrap.sh run|test" >&2; exit 2 ;; esac
cd "$(dirname "$0")/.."

packages=(
  cmake make g++ pkg-config
  libeigen3-dev libsuitesparse-dev libnlopt-cxx-dev libhdf5-dev libbenchmark-dev libgtest-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libfmt-dev python3-h5py python3-matplotlib
  libmujoco-dev libtinyxml2-dev libboost-dev
  pybind11-dev python3-pybind11 python3-pytest python3-sklearn python3-pandas libmatio-dev
  openmpi-bin libopenmpi-dev
  libopenblas-pthread-dev
)
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "== installing: ${missing[*]}"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

jobs="$(nproc)"
echo "== configuring and building (build/, Release, $jobs jobs)"
# Unity builds (8 sources per compile unit) for compile time on the 2-core machine; developers build non-unity.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DGPILQG_BUILD_TESTS=ON -DGPILQG_BUILD_BENCH=ON \
  -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8
cmake --build build -j"$jobs"

# The Python package (and the program and libraries) into /usr/local, where Debian's /usr/bin/python3
# finds `import gpilqg` (docs/python.md).
echo "== installing into /usr/local (the gpilqg program, libraries and Python package)"
$sudo_cmd cmake --install build > /dev/null

if [ "$mode" = run ]; then
  exec bash scripts/main_job.sh build/experiments/gpilqg
fi
echo "== running the test suite"
ctest --test-dir build --output-on-failure -j"$jobs" --timeout 600

# The tests labelled unit (tests/CMakeLists.txt) again under AddressSanitizer and UndefinedBehaviorSanitizer,
# in their own build folder: every test that calls the libraries in its own process. The tests that run
# the gpilqg program, mpirun, the Python package and the installed package re-check the command line's
# plumbing around the same library code, so they run in the Release build only (docs/testing.md).
# -O1, the level the AddressSanitizer documentation recommends for reasonable speed, compiles in two
# thirds of the time of -O2 (one of the largest test sources: 160 s against 250 s); the instrumented tests
# are a smaller share of the stage than their build. -g1 keeps the line tables a sanitizer report needs
# (function, file and line of every frame) without the variable descriptions of -g, which cost a third of
# the compile time.
# Unity builds as above, for compile time on the 2-core machine.
echo "== building and running the test suite under ASan + UBSan (build-sanitize/)"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGPILQG_SANITIZE=ON -DGPILQG_BUILD_TESTS=ON \
  -DGPILQG_BUILD_BENCH=OFF -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8
# Only the test programs (target gpilqg_test_programs): the label unit runs nothing else.
cmake --build build-sanitize -j"$jobs" --target gpilqg_test_programs
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure -j"$jobs" --timeout 900 -L unit
