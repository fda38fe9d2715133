#!/usr/bin/env bash
# The whole ctest suite of a built tree RUNS times in a row while stress-ng keeps every core busy at the
# same priority: a test that passes only on an idle machine fails here. Writes one log per run and a
# summary (each run's exit status, seconds, failed tests, the load average) to OUT.
#   OUT=... [RUNS=3] scripts/ctest-under-load.sh [BUILD_DIR=build-test]
set -euo pipefail
build=$(realpath "${1:-build-test}")
out=${OUT:?the result folder}
runs=${RUNS:-3}
sudo=""
if [ "$(id -u)" != 0 ]; then sudo=sudo; fi
command -v stress-ng > /dev/null || $sudo apt-get install -y -q stress-ng
mkdir -p "$out"
export POINTRAST_REQUIRE_DATA=1 XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
stress-ng --cpu "$(nproc)" --timeout 24h > "$out/stress-ng.log" 2>&1 &
stress=$!
trap 'kill $stress 2> /dev/null || true' EXIT
summary="$out/summary.md"
{
  echo "# ctest under load"
  echo
  echo "$(nproc) cores, stress-ng --cpu $(nproc) beside ctest -j$(nproc), $(date -u +%Y-%m-%d)."
  echo
  echo "| run | exit | seconds | tests | failed | load average (1, 5, 15 min) at the end |"
  echo "| ---: | ---: | ---: | ---: | --- | --- |"
} > "$summary"
status=0
for ((i = 1; i <= runs; i++)); do
  start=$(date +%s)
  code=0
  (cd "$build" && ctest --output-on-failure -j"$(nproc)" --timeout 900) > "$out/ctest-$i.log" 2>&1 || code=$?
  [ "$code" = 0 ] || status=1
  # (grep finds nothing in a run without failures: not an error of this script)
  tests=$(grep -o 'out of [0-9]*' "$out/ctest-$i.log" | tail -n 1 | cut -d' ' -f3 || true)
  failed=$(sed -n '/The following tests FAILED/,$p' "$out/ctest-$i.log" | grep -o ' - [^ ]*' | cut -c4- |
    paste -sd' ' - || true)
  echo "| $i | $code | $(($(date +%s) - start)) | ${tests:-?} | ${failed:-none} |" \
    "$(cut -d' ' -f1-3 /proc/loadavg) |" >> "$summary"
done
cat "$summary"
exit $status
