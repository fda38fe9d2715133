#!/usr/bin/env bash
# The tests that wait on time (serve and its clients, the desktop windows, LOD streaming, injected device
# faults, camera-path videos, killed and interrupted writers) REPEAT times in a row each while stress-ng
# keeps every core busy at the same priority. The runs go in blocks of BLOCK (ctest --repeat until-fail:BLOCK,
# JOBS tests at once); a block's line is added to the summary as it ends, so a long run shows how far it
# got, and the first failure ends the run. Writes one ctest log per block and the summary to OUT.
#   OUT=... [REPEAT=50] [BLOCK=5] [JOBS=nproc] [TESTS=regex] [EXCLUDE=regex] \
#     scripts/timing-tests-under-load.sh [BUILD_DIR]
set -euo pipefail
build=$(realpath "${1:-build-test}")
out=${OUT:?the result folder}
repeat=${REPEAT:-50}
block=${BLOCK:-5}
jobs=${JOBS:-$(nproc)}
exclude=${EXCLUDE:-^$}
tests=${TESTS:-'^(Serve[A-Za-z]*|FrameStream|Browser[A-Za-z]*|Viewer[A-Za-z]*|Flight|Session|MotionQuality|CrashSafetyCli|LodBuildCli|RenderPath)\.|^BenchCli\.A(LostDevice|GpuThatStops)|^GpuTest\.Lod.*Stream|serve_soak_short'}
sudo=""
if [ "$(id -u)" != 0 ]; then sudo=sudo; fi
command -v stress-ng > /dev/null || $sudo apt-get install -y -q stress-ng
mkdir -p "$out"
export POINTRAST_REQUIRE_DATA=1 XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
count=$(cd "$build" && ctest -N -R "$tests" -E "$exclude" | sed -n 's/^Total Tests: //p')
stress-ng --cpu "$(nproc)" --timeout 72h > "$out/stress-ng.log" 2>&1 &
stress=$!
trap 'kill $stress 2> /dev/null || true' EXIT
summary="$out/summary.md"
{
  echo "# Timing tests under load"
  echo
  echo "$(nproc) cores, stress-ng --cpu $(nproc) beside ctest -j$jobs, from $(date -u '+%Y-%m-%d %H:%M') UTC:" \
    "$count tests, each up to $repeat times in a row, in blocks of $block (a block stops a test at its" \
    "first failure, and a failing block ends the run)."
  echo
  echo "| block | runs of each test | exit | failed | seconds | load average (1, 5, 15 min) at its end |"
  echo "| ---: | ---: | ---: | --- | ---: | --- |"
} > "$summary"
code=0
done_runs=0
total=$(date +%s)
for ((b = 1; done_runs < repeat; b++)); do
  n=$((repeat - done_runs < block ? repeat - done_runs : block))
  start=$(date +%s)
  (cd "$build" && ctest --output-on-failure -j"$jobs" --timeout 900 -R "$tests" -E "$exclude" \
    --repeat "until-fail:$n") > "$out/timing-tests-$b.log" 2>&1 || code=$?
  # (grep finds nothing in a block without failures: not an error of this script)
  failed=$(sed -n '/The following tests FAILED/,$p' "$out/timing-tests-$b.log" | grep -o ' - [^ ]*' |
    cut -c4- | paste -sd' ' - || true)
  echo "| $b | $((done_runs + 1))-$((done_runs + n)) | $code | ${failed:-none} | $(($(date +%s) - start)) |" \
    "$(cut -d' ' -f1-3 /proc/loadavg) |" >> "$summary"
  [ "$code" = 0 ] || break
  done_runs=$((done_runs + n))
done
{
  echo
  echo "Every test passed $done_runs times in a row ($(($(date +%s) - total)) s in all); exit $code."
  echo
  echo "Selected by \`$tests\`$([ "$exclude" = '^$' ] || echo ", less \`$exclude\`")."
} >> "$summary"
cat "$summary"
exit $code
