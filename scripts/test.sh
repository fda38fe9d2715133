#!/usr/bin/env bash
# Checks that every file the docs name exists, then builds pointrast and runs every test: all tests on the
# default Vulkan device (lavapipe without a GPU) with the Khronos validation layer on, then the parser and
# data-preparation tests again under AddressSanitizer + UBSan with clang (truncation sweeps must never
# read out of bounds), and the sphere tests on a newer lavapipe (Mesa 25, Debian 12 backports, unpacked
# privately) that has mesh shaders and ray tracing, which the system's Mesa 22.3 lacks: there those
# pipelines are only skipped. Then a tree built with the test-only point method of tests/methods (one table row, one
# shader) checks that the method appears in every generated name list and renders like atomicmin. Last
# the libFuzzer targets (tests/fuzz), built in the same clang tree as the sanitizer tests (build-fuzz), run
# for $POINTRAST_FUZZ_SECONDS (120) seconds of wall time in all, shared between them, as many at once as
# there are cores. Each step's line says how long the script has run when it starts.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/web-test-setup.sh
jobs=$(nproc)
step() { echo "== $* [$((SECONDS / 60)) min $((SECONDS % 60)) s]"; }
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
# Tests that read ../shared/data skip, naming the missing file, where it is absent (a fresh clone); CI has the
# data, so there such a skip fails the test instead.
if [ "${CI:-}" = true ]; then export POINTRAST_REQUIRE_DATA=1; fi

step "every file the README and docs/ name exists"
scripts/check-doc-links.sh

step "tests (warnings as errors, validation layer on)"
# Optimized, but with asserts on (no -DNDEBUG): the push-constant size checks are asserts. No debug
# information: it made compiling and linking this tree a fifth slower, and a failing test names its line.
cmake -S . -B build-test -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2" -DPOINTRAST_WERROR=ON \
  -DPOINTRAST_PYTHON=ON -DPython_EXECUTABLE=/usr/bin/python3
cmake --build build-test -j"$jobs"

step "parser and cloud tests under AddressSanitizer and UBSan (clang, in the libFuzzer targets' tree)"
# The fuzz targets' tree (clang, -O1, ASan, UBSan, coverage instrumentation) builds these two test binaries
# as well: the parsers are compiled once for both, and run later by libFuzzer.
export POINTRAST_FUZZ_TESTS=1
scripts/fuzz.sh --build-only
# Each binary in as many gtest shards at once as there are cores; a failing shard's output is shown.
sharded() {
  local binary=$1 i failed=0
  local pids=()
  for ((i = 0; i < jobs; i++)); do
    GTEST_TOTAL_SHARDS=$jobs GTEST_SHARD_INDEX=$i ASAN_OPTIONS=detect_leaks=1 \
      "$binary" --gtest_brief=1 > "$binary.shard$i.log" 2>&1 &
    pids+=($!)
  done
  for i in "${!pids[@]}"; do
    if ! wait "${pids[$i]}"; then
      failed=1
      cat "$binary.shard$i.log"
    fi
  done
  tail -n 1 "$binary".shard*.log
  return $failed
}
sharded build-fuzz/tests/io_tests
sharded build-fuzz/tests/cloud_tests

step "all tests"
cd build-test
ctest --output-on-failure -j"$jobs" --timeout 900
cd ..

step "the Python module (pytest, Debian's python3, validation layer on)"
# Exit status 5 (no tests collected) fails as any other non-zero status does.
PYTHONPATH="$PWD/build-test/python" POINTRAST_VALIDATION=1 /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
# pip install from the checkout into a fresh environment over Debian's packages (the extension from the tree
# built above), then a render from outside the checkout.
rm -rf build-test/venv
/usr/bin/python3 -m venv --system-site-packages build-test/venv
POINTRAST_BUILD_DIR="$PWD/build-test" build-test/venv/bin/pip install -q --no-build-isolation .
(cd /tmp && "$OLDPWD/build-test/venv/bin/python" -c 'import numpy, pointrast
assert pointrast.render(numpy.random.default_rng(1).random((1000, 3)), width=64, height=48)[..., :3].any()
assert pointrast.cli_path().endswith("pointrast/_bin/pointrast"), pointrast.cli_path()')

step "sphere pipelines on Mesa 25 lavapipe (mesh shaders, ray tracing)"
(
  # Assigned first: a failing eval "$(...)" would not stop the script and the tests would run on Mesa 22.3.
  lavapipe25=$(scripts/lavapipe-mesh-rt.sh "$PWD/build-test/lavapipe25")
  eval "$lavapipe25"
  POINTRAST_VALIDATION=1 build-test/tests/gpu_tests --gtest_brief=1 --gtest_filter='*Sphere*'
)

step "a test-only point method (tests/methods: one table row, one shader) and a test-only command (tests/commands)"
# Unoptimized and without debug information: this tree only shows the table at work, and a second -O2 -g
# build of the three targets would cost CI several minutes.
cmake -S . -B build-method -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O0" \
  -DPOINTRAST_WERROR=ON -DPOINTRAST_TEST_METHODS=ON -DPOINTRAST_TEST_COMMANDS=ON
cmake --build build-method -j"$jobs" --target pointrast table_tests
POINTRAST_VALIDATION=1 build-method/tests/table_tests --gtest_brief=1 \
  --gtest_filter='MethodTable.*:Table/*closest_variant*:TestMethodCli.*:TestCommandCli.*'

step "parsers under libFuzzer (clang, ASan, UBSan), ${POINTRAST_FUZZ_SECONDS:-120} s in all"
scripts/fuzz.sh --total "${POINTRAST_FUZZ_SECONDS:-120}"
step "every step passed"
