#!/usr/bin/env bash
# The tests that wait on time (serve and its clients, the desktop windows, LOD streaming, injected device
# faults, camera-path videos, killed and interrupted writers) REPEAT times in a row each while stress-ng
# keeps every core busy at the same priority; a test fails the run at its first failure (ctest --repeat
# until-fail). Writes the ctest log and a summary (tests, passes each, failures, seconds, load) to OUT.
#   OUT=... [REPEAT=50] [TESTS=regex] scripts/timing-tests-under-load.sh [BUILD_DIR=build-test]
set -euo pipefail
build=$(realpath "${1:-build-test}")
out=${OUT:?the result folder}
repeat=${REPEAT:-50}
tests=${TESTS:-'^(Serve[A-Za-z]*|FrameStream|Browser[A-Za-z]*|Viewer[A-Za-z]*|Flight|Session|MotionQuality|CrashSafetyCli|LodBuildCli|RenderPath)\.|^BenchCli\.A(LostDevice|GpuThatStops)|^GpuTest\.Lod.*Stream|serve_soak_short'}
sudo=""
if [ "$(id -u)" != 0 ]; then sudo=sudo; fi
command -v stress-ng > /dev/null || $sudo apt-get install -y -q stress-ng
mkdir -p "$out"
export POINTRAST_REQUIRE_DATA=1 XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
count=$(cd "$build" && ctest -N -R "$tests" | sed -n 's/^Total Tests: //p')
stress-ng --cpu "$(nproc)" --timeout 24h > "$out/stress-ng.log" 2>&1 &
stress=$!
trap 'kill $stress 2> /dev/null || true' EXIT
start=$(date +%s)
code=0
(cd "$build" && ctest --output-on-failure -j"$(nproc)" --timeout 900 -R "$tests" \
  --repeat "until-fail:$repeat") > "$out/timing-tests.log" 2>&1 || code=$?
failed=$(sed -n '/The following tests FAILED/,$p' "$out/timing-tests.log" | grep -o ' - [^ ]*' | cut -c4- |
  paste -sd' ' -)
{
  echo "# Timing tests under load"
  echo
  echo "$(nproc) cores, stress-ng --cpu $(nproc) beside ctest -j$(nproc), $(date -u +%Y-%m-%d)," \
    "each test up to $repeat times in a row (stopping at its first failure)."
  echo
  echo "| tests | runs each | exit | failed | seconds | load average (1, 5, 15 min) at the end |"
  echo "| ---: | ---: | ---: | --- | ---: | --- |"
  echo "| $count | $repeat | $code | ${failed:-none} | $(($(date +%s) - start)) | $(cut -d' ' -f1-3 /proc/loadavg) |"
  echo
  echo "Selected by \`$tests\`."
} > "$out/summary.md"
cat "$out/summary.md"
exit $code
