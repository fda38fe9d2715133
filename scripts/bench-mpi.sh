#!/usr/bin/env bash
# Scaling of distributed rendering (docs/mpi.md) on one host at 2560x1140: each run's slowest rank's GPU
# time, rank 0's read-back, composite and resolve separately, and their sum (a frame's stages one after
# another, as a viewer runs them). 2 ranks composite in shared memory (one host) or by MPI_Reduce (what
# several hosts use). With one GPU, ranks share it: their render times are then not a scaling figure.
#   scripts/bench-mpi.sh PointrastBinary OutDir [RUN...]
# A RUN is POINTS:RANKS[:COMPOSITE[:METHOD]] on generated terrain (COMPOSITE shared or reduce, METHOD
# batch-prefetch unless given), or lod:RANKS[:BUDGET] on MPI_OCTREE at full detail (--min-node-px 0),
# with a node cache of BUDGET per rank (e.g. 8G; the octree's size when not given). Without RUNs:
# 1G:1 1G:2 1G:2:reduce, and lod:1 lod:2 when MPI_OCTREE is set. Every terrain run uses the first terrain
# run's camera (make it a 1-rank run: 2 ranks frame the overview from rank 0's share), or MPI_CAMERA's
# options (--eye ... --target ...) when set; every lod run uses the first lod run's.
# Each closest-point run's composited words are kept (POINTRAST_MPI_WORDS, in MPI_WORDS_DIR or /tmp) and a
# run of several ranks is compared with the first 1-rank run of its input and method: the pixels whose words
# differ, and how many of them are depth ties (the same depth, another of the tied points chosen).
# Where nvidia-smi is, each GPU's SM clock is sampled every 100 ms during a run, and the table gives each
# GPU's median clock over the samples where it was at least half busy (a rank timed at a low clock shows).
# Writes OutDir/mpi-scaling.jsonl (one `render --json` object per run) and OutDir/mpi-scaling.md.
set -uo pipefail
pr=$1 out=$2
shift 2
runs=("$@")
if [ ${#runs[@]} -eq 0 ]; then
  runs=(1G:1 1G:2 1G:2:reduce)
  [ -n "${MPI_OCTREE:-}" ] && runs+=(lod:1 lod:2)
fi
mkdir -p "$out"
jsonl=$out/mpi-scaling.jsonl md=$out/mpi-scaling.md
: >"$jsonl"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
frames=${MPI_FRAMES:-20}
view=(--width 2560 --height 1140 --frames "$frames" --json -q)
field() { grep -o "\"$1\":[^,}]*" <<<"$2" | head -1 | cut -d: -f2; }
ms() { awk -v v="$1" 'BEGIN { if (v == "") print "-"; else printf "%.2f", v }'; }
{
  gpus=$(nvidia-smi -L 2>/dev/null | grep -c GPU || true)
  echo "Host: $(nproc) cores, $(free -g | awk '/Mem:/ { print $2 }') GiB, ${gpus:-?} GPU(s)" \
    "($(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | sort -u | paste -sd, -));" \
    "$(mpirun --version 2>/dev/null | head -1); 2560x1140, $frames frames, medians."
  echo
  echo "| input | method | ranks | points | render ms (slowest rank) | per rank | readback ms | composite ms | composite | resolve ms (first) | frame ms | MB moved | image hash | words unlike 1 rank (ties) | SM MHz while busy, per GPU |"
  echo "| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | --- | ---: | ---: | ---: | --- | ---: | --- |"
} >"$md"
status=0
words_dir=${MPI_WORDS_DIR:-/tmp/mpi-words}
mkdir -p "$words_dir"
rm -f "$words_dir"/*.reference
# The pixels whose words differ between two dumps, and how many of those hold the same depth (high 32 bits).
compare_words() { # REFERENCE OTHER
  python3 - "$1" "$2" <<'PY'
import sys
from array import array
a, b = array('Q'), array('Q')
with open(sys.argv[1], 'rb') as f: a.frombytes(f.read())
with open(sys.argv[2], 'rb') as f: b.frombytes(f.read())
if len(a) != len(b): sys.exit(f"the dumps differ in size ({len(a)} and {len(b)} words)")
differ = ties = 0
for x, y in zip(a, b):
    if x != y:
        differ += 1
        ties += (x >> 32) == (y >> 32)
print(f"{differ} ({ties})")
PY
}
# Each GPU's median SM clock over the samples of CSV (index, clock, utilization) where it was >= 50 % busy.
busy_clocks() { # CSV
  python3 - "$1" <<'PY'
import sys, statistics
clocks = {}
for line in open(sys.argv[1]):
    try:
        index, clock, busy = (int(v) for v in line.split(','))
    except ValueError:
        continue
    if busy >= 50: clocks.setdefault(index, []).append(clock)
print(', '.join(f"{i}: {statistics.median(c):.0f}" for i, c in sorted(clocks.items())) or '-')
PY
}
# shellcheck disable=SC2034 # the cameras are used through `local -n` in run
terrain_camera=() lod_camera=()
# shellcheck disable=SC2034 # likewise
[ -z "${MPI_CAMERA:-}" ] || read -r -a terrain_camera <<<"$MPI_CAMERA" # the terrain runs' camera, given
run() { # name method ranks composite cameraVar args...
  local name=$1 method=$2 ranks=$3 composite=$4 var=$5
  shift 5
  local -n camera=$var
  echo "== $name, $method, $ranks rank(s), composite $composite ($(date +%T))"
  local line start=$SECONDS key="${name%% cache *}" words
  key="${key// /-}-$method" # a lod run compares with the 1-rank run whatever its node cache
  words="$words_dir/$key-$ranks-$composite.bin"
  rm -f "$words"
  local clocks="$out/clocks-${name// /-}-$method-$ranks-$composite.csv" sampler=""
  if command -v nvidia-smi >/dev/null; then
    nvidia-smi --query-gpu=index,clocks.sm,utilization.gpu --format=csv,noheader,nounits -lms 100 >"$clocks" &
    sampler=$!
  fi
  line=$(POINTRAST_MPI_WORDS=$words POINTRAST_MPI_COMPOSITE=$composite POINTRAST_VALIDATION=0 \
    timeout "${MPI_RUN_LIMIT:-580}" \
    mpirun --oversubscribe --bind-to none -np "$ranks" "$pr" render "$@" \
    --method "$method" -o "$out/mpi-${name// /-}-$method-$ranks-$composite.png" "${view[@]}" ${camera[@]+"${camera[@]}"}) ||
    { status=1; echo "bench-mpi: $name on $ranks rank(s) failed after $((SECONDS - start)) s"
      [ -z "$sampler" ] || kill "$sampler"; return; }
  local busy=-
  if [ -n "$sampler" ]; then
    kill "$sampler"
    wait "$sampler" 2>/dev/null
    busy=$(busy_clocks "$clocks")
  fi
  echo "$line" | tee -a "$jsonl"
  echo "   ($((SECONDS - start)) s with loading)"
  [ ${#camera[@]} -gt 0 ] || read -r -a camera <<<"$(grep -o '"camera":"[^"]*"' <<<"$line" | head -1 | cut -d'"' -f4)"
  local mb path per hash
  mb=$(awk -v b="$(field bytes_moved "$line")" 'BEGIN { printf "%.1f", b / 1e6 }')
  path=$(grep -o '"composite_path":"[^"]*"' <<<"$line" | head -1 | cut -d'"' -f4)
  [ "$ranks" -gt 1 ] || path=""
  per=$(grep -o '"rank_render_ms":\[[^]]*\]' <<<"$line" | head -1 | sed 's/.*\[//; s/\]//' |
    tr ',' '\n' | awk '{ printf "%s%.2f", (NR > 1 ? ", " : ""), $1 }')
  hash=$(field image_hash "$line" | tr -d '"')
  local versus=-
  if [ -f "$words" ]; then
    if [ "$ranks" -eq 1 ] && [ ! -f "$words_dir/$key.reference" ]; then
      cp "$words" "$words_dir/$key.reference"
    elif [ "$ranks" -gt 1 ] && [ -f "$words_dir/$key.reference" ]; then
      versus=$(compare_words "$words_dir/$key.reference" "$words") || versus="?"
    fi
    rm -f "$words"
  fi
  echo "| $name | $method | $ranks | $(field points "$line") | $(ms "$(field render_ms "$line")") | $per |" \
    "$(ms "$(field readback_ms "$line")") | $(ms "$(field composite_ms "$line")") | ${path:--} |" \
    "$(ms "$(field resolve_ms "$line")") ($(ms "$(field resolve_first_ms "$line")")) |" \
    "$(ms "$(field frame_ms "$line")") | $mb | \`$hash\` | $versus | $busy |" >>"$md"
}
for spec in "${runs[@]}"; do
  IFS=: read -r what ranks composite method <<<"$spec"
  if [ "$what" = lod ]; then
    [ -n "${MPI_OCTREE:-}" ] || { echo "bench-mpi: $spec needs MPI_OCTREE"; status=1; continue; }
    budget=${composite:-$(du -sb "$MPI_OCTREE" | cut -f1)}
    run "$(basename "$MPI_OCTREE") cache $budget" lod "$ranks" shared lod_camera "$MPI_OCTREE" \
      --min-node-px 0 --gpu-memory "$budget"
  else
    run "terrain $what" "${method:-batch-prefetch}" "$ranks" "${composite:-shared}" terrain_camera \
      terrain --points "$what"
  fi
done
cat "$md"
exit $status
