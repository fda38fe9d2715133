#!/usr/bin/env bash
# Builds the libFuzzer targets (the list in tests/fuzz/CMakeLists.txt) in their own tree with clang, ASan
# and UBSan, and runs each for a bounded time, JOBS of them at once. A target is seeded from the shared
# test data (the folders its "// Seeds:" line names, else the folder NAME; a target that generates its
# seeds reads the folder to write them to from NAME_FUZZ_SEEDS, e.g. POTREE_FUZZ_SEEDS) and from its
# regression inputs (tests/fuzz/regressions/NAME/), with the dictionary tests/fuzz/NAME.dict where there
# is one and the libFuzzer flags of the target's "// Fuzz flags:" line. Exits 1 if any target finds a crash, a leak, undefined behaviour, an input that takes over 10 s,
# or an allocation over 256 MiB (an input is at most 64 KiB: a reader allocating that much trusts a count
# it should have checked); the input that did it is kept under BUILD/findings/DATE-TIME/ and the command
# that replays it is printed.
#
#   scripts/fuzz.sh [SECONDS] [NAME...]          SECONDS per target (default 25), NAME: las, ply...
#   scripts/fuzz.sh --total SECONDS [NAME...]    the running of all targets takes about SECONDS of wall
#                                                time: each gets SECONDS x JOBS / targets (at least 10)
#   scripts/fuzz.sh --report ...                 also appends the run to docs/fuzzing.md ("Runs" at its
#                                                end): per target its seconds, executions, executions per
#                                                second, coverage (cov / ft) and findings, and updates the
#                                                table of cumulative executions per target over all runs;
#                                                the appended block is also kept in BUILD/logs/report.md
#   scripts/fuzz.sh --build-only                 configures and builds the tree, runs nothing
#   scripts/fuzz.sh --merge FILE                 appends a block another machine's --report run kept
#                                                (its BUILD/logs/report.md) to docs/fuzzing.md and updates
#                                                the cumulative table
#   scripts/fuzz.sh --until EXECUTIONS [--report] --total SECONDS [NAME...]
#                                                every target (or NAME...) whose cumulative executions in
#                                                docs/fuzzing.md are short of EXECUTIONS runs, all at once
#                                                for SECONDS, each with -fork workers in proportion to the
#                                                core-seconds it lacks (its missing executions divided by
#                                                its rate per core in tests/fuzz/rates), every core used
#   scripts/fuzz.sh --pack DIR [NAME...]         builds, then puts what a run elsewhere needs into DIR:
#                                                DIR/fuzz/NAME_fuzz.gz (debug info stripped, symbols kept,
#                                                compressed), DIR/seeds/NAME (the seeds generating targets
#                                                write from the shared data) and DIR/corpus/NAME (this
#                                                tree's corpus, minimized by -merge=1); run it there with
#                                                POINTRAST_FUZZ_PREBUILT=1 POINTRAST_FUZZ_BUILD=DIR, which
#                                                unpacks the binaries first
#   POINTRAST_FUZZ_JOBS     targets run at once (default: the number of cores); 1 for long runs on a
#                           shared machine
#   POINTRAST_FUZZ_FORK     libFuzzer worker processes per target (-fork=N); default 0 (the target runs
#                           in one process), but with POINTRAST_FUZZ_PREBUILT=1 the cores divided by the
#                           targets running at once, so that a few targets use every core
#   POINTRAST_FUZZ_PREBUILT 1: no configure and no build, the binaries of BUILD/fuzz are run as they are
#                           (a machine without clang, running what --pack made; a NAME_fuzz.gz there is
#                           unpacked into NAME_fuzz first)
#   POINTRAST_FUZZ_TESTS    1: the tree also builds the parser and cloud test binaries (BUILD/tests/io_tests,
#                           cloud_tests) with the same sanitizers: scripts/test.sh runs them there, so the
#                           libraries are compiled once for the tests and the fuzz targets
#   POINTRAST_FUZZ_BUILD    the build tree (default build-fuzz). Its corpus/NAME folders keep what a run
#                           found, so a later run starts from there.
#   POINTRAST_DATA_DIR      the shared test data (default ../shared/data beside the checkout)
#   POINTRAST_FUZZ_FLAGS    more libFuzzer flags, e.g. "-use_value_profile=1" for long runs
#   POINTRAST_FUZZ_COMMIT   the commit --report names, where the checkout has no git history
set -euo pipefail
cd "$(dirname "$0")/.."
docs="docs/fuzzing.md"

# Rewrites the table of cumulative executions per target in docs/fuzzing.md (between its
# "<!-- cumulative -->" markers, added before "## Runs" when missing) from every row of the Runs section.
updateCumulative() {
  local table
  table="$(awk -F'|' '
    /^## Runs$/ { runs = 1; next }
    runs && /^\| `[a-z0-9_]+` \| [0-9]+ s \| [0-9]+ \|/ {
      name = $2; gsub(/[ `]/, "", name); secs = $3; gsub(/[ s]/, "", secs); ex = $4; gsub(/ /, "", ex)
      if (!(name in total)) order[n++] = name
      total[name] += ex; seconds[name] += secs; count[name]++
    }
    END {
      print "| target | runs | seconds | executions | of 10^6 |"
      print "| --- | --- | --- | --- | --- |"
      for (i = 0; i < n; ++i) {
        name = order[i]
        share = total[name] >= 1000000 ? "reached" : sprintf("%d %%", total[name] / 10000)
        printf "| `%s` | %d | %d | %d | %s |\n", name, count[name], seconds[name], total[name], share
      }
    }' "$docs")"
  if ! grep -q '^<!-- cumulative -->$' "$docs"; then
    awk '/^## Runs$/ && !done {
      print "## Cumulative executions\n"
      print "Every run recorded under Runs below, summed per target (updated by `scripts/fuzz.sh --report`"
      print "and `--merge`); a target has had its 10^6 executions when the last column says so.\n"
      print "<!-- cumulative -->\n<!-- /cumulative -->\n"
      done = 1 }
      { print }' "$docs" >"$docs.tmp" && mv "$docs.tmp" "$docs"
  fi
  awk -v table="$table" '
    /^<!-- cumulative -->$/ { print; print table; skip = 1; next }
    /^<!-- \/cumulative -->$/ { skip = 0 }
    !skip { print }' "$docs" >"$docs.tmp" && mv "$docs.tmp" "$docs"
}

if [ "${1:-}" = "--merge" ]; then
  block="${2:?--merge needs the report block of a run (BUILD/logs/report.md)}"
  [ -f "$block" ] || { echo "fuzz: no report block $block" >&2; exit 1; }
  cat "$block" >>"$docs"
  updateCumulative
  echo "fuzz: $block is appended to $docs"
  exit 0
fi
buildOnly=""
if [ "${1:-}" = "--build-only" ]; then
  buildOnly=1
  shift
fi
until=""
if [ "${1:-}" = "--until" ]; then
  until="${2:?--until needs EXECUTIONS}"
  [[ "$until" =~ ^[0-9]+$ ]] || { echo "fuzz: --until needs a number of executions, not $until" >&2; exit 1; }
  shift 2
fi
pack=""
if [ "${1:-}" = "--pack" ]; then
  pack="${2:?--pack needs a folder}"
  shift 2
fi
report=""
if [ "${1:-}" = "--report" ]; then
  report="$docs"
  shift
fi
total=""
if [ "${1:-}" = "--total" ]; then
  total="${2:?--total needs SECONDS}"
  shift 2
fi
seconds=25
if [ -z "$total" ] && [ $# -gt 0 ] && [[ "$1" =~ ^[0-9]+$ ]]; then
  seconds="$1"
  shift
fi
build="${POINTRAST_FUZZ_BUILD:-build-fuzz}"
data="${POINTRAST_DATA_DIR:-$PWD/../shared/data}"
jobs="${POINTRAST_FUZZ_JOBS:-$(nproc)}"

names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  # The targets CMake builds: the names of the foreach() line.
  read -r -a names <<<"$(sed -n 's/^foreach(name \(.*\))[[:space:]]*$/\1/p' tests/fuzz/CMakeLists.txt)"
fi
[ ${#names[@]} -gt 0 ] || { echo "fuzz: no targets in tests/fuzz/CMakeLists.txt" >&2; exit 1; }

# --until: the targets short of EXECUTIONS and their workers. A target's need is its missing executions
# divided by its rate per core (tests/fuzz/rates; 1000 per second where it has no line), in core-seconds.
# The targets of smallest need first get the workers that finish them within SECONDS (with a tenth to
# spare for the fork jobs' restarts), as long as every target after them keeps a core; the targets
# left share the remaining cores in proportion to their needs (at least one each). Cores beyond every
# target's need go to the targets of largest need per worker.
declare -A workers=()
if [ -n "$until" ]; then
  [ -n "$total" ] || { echo "fuzz: --until needs --total SECONDS" >&2; exit 1; }
  plan="$(awk -v until="$until" -v cores="$(nproc)" -v time="$total" -v wanted="${names[*]}" '
    FILENAME ~ /rates$/ { if ($1 !~ /^#/ && NF >= 2) rate[$1] = $2; next }
    /^<!-- cumulative -->$/ { table = 1; next }
    /^<!-- \/cumulative -->$/ { table = 0 }
    table && /^\| `/ { split($0, f, "|"); name = f[2]; gsub(/[ `]/, "", name); ex = f[5]; gsub(/ /, "", ex); done[name] = ex }
    END {
      n = split(wanted, list, " ")
      for (i = 1; i <= n; ++i) {
        name = list[i]; lack = until - done[name]
        if (lack <= 0) continue
        need[name] = lack / ((name in rate) ? rate[name] : 1000)
        # Insertion into order[], smallest need first.
        for (j = m++; j > 0 && need[order[j - 1]] > need[name]; --j) order[j] = order[j - 1]
        order[j] = name
      }
      if (m == 0) exit
      if (m > cores) { print "error " m " targets lack executions but there are only " cores " cores"; exit }
      left = cores; first = 0
      for (; first < m; ++first) {
        name = order[first]; w[name] = int(need[name] * 1.1 / time) + 1
        if (left - w[name] < m - first - 1) break
        left -= w[name]
      }
      if (first < m) {
        for (i = first; i < m; ++i) sum += need[order[i]]
        for (i = first; i < m; ++i) {
          name = order[i]; share = (left - (m - first)) * need[name] / sum
          w[name] = 1 + int(share); rest[name] = share - int(share); given += w[name]
        }
        for (; given < left; ++given) {
          best = ""
          for (i = first; i < m; ++i) if (best == "" || rest[order[i]] > rest[best]) best = order[i]
          ++w[best]; rest[best] = -1
        }
      } else {
        for (; left > 0; --left) {
          best = ""
          for (i = 0; i < m; ++i) if (best == "" || need[order[i]] / w[order[i]] > need[best] / w[best]) best = order[i]
          ++w[best]
        }
      }
      for (i = 0; i < m; ++i) {
        name = order[i]
        printf "%s %d %d %.0f %s\n", name, w[name], until - done[name], need[name], \
          (w[name] * time >= need[name] * 1.1 ? "all" : sprintf("about %d %%", 100 * w[name] * time / 1.1 / need[name]))
      }
    }' tests/fuzz/rates "$docs")"
  if [[ "$plan" == error* ]]; then echo "fuzz: ${plan#error }" >&2; exit 1; fi
  names=()
  while read -r name count lack need outcome; do
    [ -n "$name" ] || continue
    names+=("$name")
    workers[$name]=$count
    echo "fuzz: $name lacks $lack executions, ~$need core-seconds at its rate: $count workers for $outcome of it in $total s"
  done <<<"$plan"
  if [ ${#names[@]} -eq 0 ]; then
    echo "fuzz: every target has had $until executions"
    exit 0
  fi
  jobs=${#names[@]}
fi
if [ "$jobs" -gt ${#names[@]} ]; then jobs=${#names[@]}; fi
fork="${POINTRAST_FUZZ_FORK:-0}"
if [ "${POINTRAST_FUZZ_PREBUILT:-0}" = 1 ] && [ -z "${POINTRAST_FUZZ_FORK:-}" ]; then
  fork=$(($(nproc) / jobs))
  if [ "$fork" -lt 2 ]; then fork=0; fi
fi
if [ -n "$total" ]; then
  seconds=$((total * jobs / ${#names[@]}))
  if [ "$seconds" -lt 10 ]; then seconds=10; fi
fi

if [ "${POINTRAST_FUZZ_PREBUILT:-0}" != 1 ]; then
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  # -O1 without -DNDEBUG: the asserts stay on (a file must never reach one). Line tables only: a stack
  # names files and lines, and the tree compiles in less time than with full debug information.
  # The static runtime (libstdc++, libgcc, brotli) lets --pack's binaries run where only the C library is.
  tests=OFF testTargets=()
  if [ "${POINTRAST_FUZZ_TESTS:-0}" = 1 ]; then tests=ON testTargets=(io_tests cloud_tests); fi
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DPOINTRAST_FUZZ=ON -DPOINTRAST_TESTS="$tests" -DPOINTRAST_STATIC_RUNTIME=ON "${launcher[@]}" >/dev/null
  if [ -n "$pack" ]; then
    cmake --build "$build" -j"$(nproc)" --target $(printf '%s_fuzz ' "${names[@]}")
  else
    cmake --build "$build" -j"$(nproc)" --target fuzz "${testTargets[@]}"
  fi
fi
if [ -n "$buildOnly" ]; then exit 0; fi

if [ -n "$pack" ]; then
  mkdir -p "$pack/fuzz"
  for name in "${names[@]}"; do
    binary="$build/fuzz/${name}_fuzz"
    [ -x "$binary" ] || { echo "fuzz: no target $name (tests/fuzz/${name}_fuzz.cpp)" >&2; exit 1; }
    objcopy --strip-debug "$binary" "$pack/fuzz/${name}_fuzz.tmp"
    libraries="$(ldd "$pack/fuzz/${name}_fuzz.tmp" | awk '{ print $1 }' |
      grep -vE '^(linux-vdso|/lib64/ld-linux|ld-linux|libc|libm|libpthread|libdl|librt)[.-]' || true)"
    if [ -n "$libraries" ]; then echo "fuzz: ${name}_fuzz needs" $libraries >&2; exit 1; fi
    # A sanitized, instrumented binary shrinks to about a quarter: nine of them fit a 64 MiB folder.
    gzip -9 -n -c "$pack/fuzz/${name}_fuzz.tmp" >"$pack/fuzz/${name}_fuzz.gz.tmp"
    mv "$pack/fuzz/${name}_fuzz.gz.tmp" "$pack/fuzz/${name}_fuzz.gz"
    rm -f "$pack/fuzz/${name}_fuzz.tmp" "$pack/fuzz/${name}_fuzz"
    variable="$(echo "$name" | tr '[:lower:]' '[:upper:]')_FUZZ_SEEDS"
    if grep -q "$variable" "tests/fuzz/${name}_fuzz.cpp"; then
      rm -rf "$pack/seeds/$name" && mkdir -p "$pack/seeds/$name"
      env "$variable=$pack/seeds/$name" "$binary" -runs=0 "$pack/seeds/$name" >/dev/null 2>&1
    fi
    if [ -d "$build/corpus/$name" ]; then
      # Only the inputs that add coverage (-merge=1 keeps the smallest input of each feature): the
      # corpus of many runs is mostly redundant, and a smaller one starts every fork job sooner.
      rm -rf "$pack/corpus/$name" && mkdir -p "$pack/corpus/$name"
      if ! "$binary" -merge=1 -max_len=65536 -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=256 \
        "$pack/corpus/$name" "$build/corpus/$name" >"$build/logs/$name.pack.log" 2>&1; then
        echo "fuzz: $name: minimizing the corpus failed (see $build/logs/$name.pack.log)" >&2
        exit 1
      fi
    fi
  done
  echo "fuzz: $pack holds ${names[*]}: $(du -sm "$pack" | cut -f 1) MiB; run there with" \
    "POINTRAST_FUZZ_PREBUILT=1 POINTRAST_FUZZ_BUILD=$pack scripts/fuzz.sh ..."
  exit 0
fi

if [ -z "${ASAN_SYMBOLIZER_PATH:-}" ] && ! command -v llvm-symbolizer >/dev/null; then
  for s in /usr/lib/llvm-*/bin/llvm-symbolizer; do
    if [ -x "$s" ]; then export ASAN_SYMBOLIZER_PATH="$s"; fi
  done
fi
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"

findings="$build/findings/$(date +%Y%m%d-%H%M%S)"
mkdir -p "$findings" "$build/logs"

# Runs target $1; its outcome goes to $build/logs/NAME.result (the lines to print, "failed" first if it
# found something).
fuzzTarget() {
  local name="$1"
  local binary="$build/fuzz/${name}_fuzz"
  local result="$build/logs/$name.result"
  local seeds=() generator=() dict=()
  # A target that writes its own seeds (valid inputs of a layout no data file has) reads NAME_FUZZ_SEEDS:
  # it fills that folder when it starts, before the corpus is loaded.
  local variable
  variable="$(echo "$name" | tr '[:lower:]' '[:upper:]')_FUZZ_SEEDS"
  if grep -q "$variable" "tests/fuzz/${name}_fuzz.cpp"; then
    mkdir -p "$build/seeds/$name"
    generator=(env "$variable=$build/seeds/$name")
    seeds+=("$build/seeds/$name")
  else
    local folders folder
    folders="$(sed -n 's|^// Seeds:[[:space:]]*||p' "tests/fuzz/${name}_fuzz.cpp" | head -n 1)"
    for folder in ${folders:-$name}; do
      if [ -d "$data/$folder" ]; then seeds+=("$data/$folder"); else echo "fuzz: $name: no seed folder $data/$folder"; fi
    done
  fi
  if [ -d "tests/fuzz/regressions/$name" ]; then seeds+=("tests/fuzz/regressions/$name"); fi
  if [ -f "tests/fuzz/$name.dict" ]; then dict=(-dict="tests/fuzz/$name.dict"); fi
  # libFuzzer flags of the target's own, from its "// Fuzz flags:" line (e.g. -entropic=0).
  local targetFlags
  targetFlags="$(sed -n 's|^// Fuzz flags:[[:space:]]*||p' "tests/fuzz/${name}_fuzz.cpp" | head -n 1)"
  local corpus="$build/corpus/$name"
  local log="$build/logs/$name.log"
  local forkFlags=() workerCount="${workers[$name]:-$fork}"
  if [ "$workerCount" -gt 0 ]; then forkFlags=(-fork="$workerCount"); fi
  mkdir -p "$corpus"
  echo "== fuzz $name: ${seconds} s${forkFlags[*]:+, ${forkFlags[*]}}, seeds: ${seeds[*]:-none}"
  local started=$SECONDS
  if "${generator[@]}" "$binary" -max_total_time="$seconds" -timeout=10 -max_len=65536 -rss_limit_mb=2048 \
    -malloc_limit_mb=256 -print_final_stats=1 -artifact_prefix="$findings/$name-" "${dict[@]}" "${forkFlags[@]}" \
    $targetFlags ${POINTRAST_FUZZ_FLAGS:-} "$corpus" "${seeds[@]}" >"$log" 2>&1; then
    {
      echo "== $name"
      # "#123456 DONE cov: 812 ft: 2931 corp: 401/1873Kb ..." and the executions from the final stats.
      # With -fork, the last "#123456: cov: 812 ft: 2931 corp: 401 exec/s 1234 ..." line instead.
      grep -E '^#[0-9]+([[:space:]]+DONE|:[[:space:]]+cov:)' "$log" | tail -n 1 || true
      grep -E '^stat::(number_of_executed_units|average_exec_per_sec):' "$log" | tr '\n' ' ' || true
      echo
    } >"$result"
  else
    {
      echo "failed"
      echo "== $name: FINDING"
      tail -n 80 "$log"
      local input
      for input in "$findings/$name-"*; do
        [ -e "$input" ] && echo "fuzz: $name: finding kept in $input; replay: $binary $input"
      done
    } >"$result"
  fi
  reportRow "$name" "$log" $((SECONDS - started)) >"$build/logs/$name.row"
}

# One Markdown row of the report for target $1 from its log $2, run for $3 s of wall time: libFuzzer's
# final stats (executions, executions per second), the cov and ft of its last status line, and what it
# found (the sanitizer's or libFuzzer's first error line and the kept input).
reportRow() {
  local name="$1" log="$2" wall="$3"
  local executions rate status cov ft finding="none"
  executions="$(sed -n 's/^stat::number_of_executed_units:[[:space:]]*//p' "$log" | tail -n 1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec:[[:space:]]*//p' "$log" | tail -n 1)"
  status="$(grep -E '^#[0-9]+:?[[:space:]].*cov: [0-9]+' "$log" | tail -n 1 || true)"
  cov="$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")"
  ft="$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")"
  # -fork prints no final stats: the executions of all workers are its last status line's count.
  if [ -z "$executions" ]; then executions="$(sed -n 's/^#\([0-9]*\):\{0,1\}[[:space:]].*/\1/p' <<<"$status")"; fi
  if [ -z "$rate" ] && [ -n "$executions" ] && [ "$wall" -gt 0 ]; then rate=$((executions / wall)); fi
  local input
  for input in "$findings/$name-"*; do
    if [ -e "$input" ]; then
      local what
      what="$(grep -m 1 -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error)' "$log" | sed 's/^==[0-9]*==//; s/|/\\|/g' | cut -c 1-120)"
      finding="${what:-a finding}: \`$input\`"
      break
    fi
  done
  printf '| `%s` | %s s | %s | %s | %s / %s | %s |\n' "$name" "$wall" "${executions:-?}" "${rate:-?}" \
    "${cov:-?}" "${ft:-?}" "$finding"
}

for name in "${names[@]}"; do
  if [ "${POINTRAST_FUZZ_PREBUILT:-0}" = 1 ] && [ -f "$build/fuzz/${name}_fuzz.gz" ] &&
    [ ! "$build/fuzz/${name}_fuzz" -nt "$build/fuzz/${name}_fuzz.gz" ]; then
    gzip -d -c "$build/fuzz/${name}_fuzz.gz" >"$build/fuzz/${name}_fuzz.tmp"
    chmod +x "$build/fuzz/${name}_fuzz.tmp" && mv "$build/fuzz/${name}_fuzz.tmp" "$build/fuzz/${name}_fuzz"
  fi
  [ -x "$build/fuzz/${name}_fuzz" ] || { echo "fuzz: no target $name (tests/fuzz/${name}_fuzz.cpp)" >&2; exit 1; }
  rm -f "$build/logs/$name.result" "$build/logs/$name.row"
done
running=0
for name in "${names[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true # a target's outcome is in its result file
    running=$((running - 1))
  fi
  fuzzTarget "$name" &
  running=$((running + 1))
done
wait || true

failed=()
for name in "${names[@]}"; do
  result="$build/logs/$name.result"
  if [ ! -f "$result" ] || [ "$(head -n 1 "$result")" = "failed" ]; then
    failed+=("$name")
    tail -n +2 "$result" 2>/dev/null || echo "fuzz: $name: no result (see $build/logs/$name.log)"
  else
    cat "$result"
  fi
done
if [ -n "$report" ]; then
  if ! grep -q '^## Runs$' "$report"; then
    printf '\n## Runs\n\nAppended by `scripts/fuzz.sh --report`, newest last.\n' >>"$report"
  fi
  forkNote=""
  if [ "$fork" -gt 0 ]; then forkNote=", $fork workers each (-fork)"; fi
  if [ -n "$until" ]; then
    forkNote=", workers (-fork) in proportion to the executions each lacked for $until:"
    for name in "${names[@]}"; do forkNote+=" $name ${workers[$name]},"; done
    forkNote="${forkNote%,}"
  fi
  {
    echo
    echo "$(date -u +'%Y-%m-%d %H:%M') UTC, commit ${POINTRAST_FUZZ_COMMIT:-$(git rev-parse --short HEAD 2>/dev/null || echo unknown)}," \
      "$seconds s per target, $jobs at once$forkNote on $(nproc) cores (load average $(cut -d ' ' -f 1 /proc/loadavg)):"
    echo
    echo "| target | time | executions | per second | cov / ft | findings |"
    echo "| --- | --- | --- | --- | --- | --- |"
    for name in "${names[@]}"; do
      cat "$build/logs/$name.row" 2>/dev/null || echo "| \`$name\` | | | | | no result |"
    done
  } >"$build/logs/report.md"
  cat "$build/logs/report.md" >>"$report"
  updateCumulative
  echo "fuzz: the run is appended to $report"
fi
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]} (logs in $build/logs)" >&2
  exit 1
fi
echo "fuzz: ${#names[@]} targets, no findings"
