#!/usr/bin/env bash
# Scaling of distributed rendering (docs/mpi.md) on one host: 1 rank against 2 ranks (one GPU each) at
# 2560x1140, the slowest rank's GPU time and rank 0's composite separately. Brute force on a generated
# terrain of POINTS points (default 1G), and, when OCTREE is given, lod on it at full detail.
#   scripts/bench-mpi.sh PointrastBinary OutDir [POINTS] [OCTREE]
# Writes OutDir/mpi-scaling.jsonl (one `render --json` object per run) and OutDir/mpi-scaling.md.
set -uo pipefail
pr=$1 out=$2 points=${3:-1G} octree=${4:-}
mkdir -p "$out"
jsonl=$out/mpi-scaling.jsonl md=$out/mpi-scaling.md
: >"$jsonl"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
view=(--width 2560 --height 1140 --frames "${MPI_FRAMES:-20}" --json -q)
field() { grep -o "\"$1\":[^,}]*" <<<"$2" | head -1 | cut -d: -f2; }
{
  echo "| input | method | ranks | points | render ms (slowest rank) | composite ms | readback ms | resolve ms | MB moved |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
} >"$md"
status=0
run() { # name method ranks args...
  local name=$1 method=$2 ranks=$3
  shift 3
  echo "== $name, $method, $ranks rank(s)"
  local line
  line=$(POINTRAST_VALIDATION=0 timeout 580 mpirun --oversubscribe --bind-to none -np "$ranks" "$pr" render "$@" \
    --method "$method" -o "/tmp/mpi-$ranks.png" "${view[@]}") || { status=1; return; }
  echo "$line" | tee -a "$jsonl"
  local mb
  mb=$(awk -v b="$(field bytes_moved "$line")" 'BEGIN { printf "%.1f", b / 1e6 }')
  echo "| $name | $method | $ranks | $(field points "$line") | $(field render_ms "$line") | $(field composite_ms "$line") | $(field readback_ms "$line") | $(field resolve_ms "$line") | $mb |" >>"$md"
}
for ranks in 1 2; do run "terrain $points" batch-prefetch "$ranks" terrain --points "$points"; done
if [ -n "$octree" ]; then
  for ranks in 1 2; do run "$(basename "$octree")" lod "$ranks" "$octree" --min-node-px 0; done
fi
cat "$md"
exit $status
