#!/usr/bin/env bash
# Scaling of distributed rendering (docs/mpi.md) on one host: 1 rank against 2 ranks (one GPU each, or
# both on the one GPU of a single-GPU host) at 2560x1140, the slowest rank's GPU time and rank 0's
# composite separately; 2 ranks composite in shared memory (one host) and again by MPI_Reduce (what
# several hosts use), side by side. Brute force on a generated terrain of POINTS points (default 1G), and,
# when OCTREE is given, lod on it at full detail.
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
  gpus=$(nvidia-smi -L 2>/dev/null | grep -c GPU || true)
  echo "Host: $(nproc) cores, ${gpus:-?} GPU(s) ($(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null |
    sort -u | paste -sd, -)); $(mpirun --version 2>/dev/null | head -1); 2560x1140, ${MPI_FRAMES:-20} frames," \
    "medians. With one GPU, both ranks draw on it: their render times share it, the read-back and composite" \
    "are what one host pays for any number of GPUs."
  echo
  echo "| input | method | ranks | points | render ms (slowest rank) | readback ms | composite ms | composite | resolve ms | MB moved |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
} >"$md"
status=0
run() { # composite name method ranks args...  (composite: shared or reduce)
  local composite=$1 name=$2 method=$3 ranks=$4
  shift 4
  echo "== $name, $method, $ranks rank(s), composite $composite"
  local line
  line=$(POINTRAST_MPI_COMPOSITE=$composite POINTRAST_VALIDATION=0 timeout 580 \
    mpirun --oversubscribe --bind-to none -np "$ranks" "$pr" render "$@" \
    --method "$method" -o "/tmp/mpi-$ranks.png" "${view[@]}" ${camera[@]+"${camera[@]}"}) || { status=1; return; }
  echo "$line" | tee -a "$jsonl"
  # Every later run of this input uses the first run's camera (the overview of 2 ranks is framed from rank
  # 0's share), so that the images and times compare.
  [ ${#camera[@]} -gt 0 ] || read -r -a camera <<<"$(grep -o '"camera":"[^"]*"' <<<"$line" | head -1 | cut -d'"' -f4)"
  local mb path
  mb=$(awk -v b="$(field bytes_moved "$line")" 'BEGIN { printf "%.1f", b / 1e6 }')
  path=$(grep -o '"composite_path":"[^"]*"' <<<"$line" | head -1 | cut -d'"' -f4)
  echo "| $name | $method | $ranks | $(field points "$line") | $(field render_ms "$line") | $(field readback_ms "$line") | $(field composite_ms "$line") | ${path:--} | $(field resolve_ms "$line") | $mb |" >>"$md"
}
camera=()
run shared "terrain $points" batch-prefetch 1 terrain --points "$points"
run shared "terrain $points" batch-prefetch 2 terrain --points "$points"
run reduce "terrain $points" batch-prefetch 2 terrain --points "$points"
if [ -n "$octree" ]; then
  camera=()
  for ranks in 1 2; do run shared "$(basename "$octree")" lod "$ranks" "$octree" --min-node-px 0; done
fi
cat "$md"
exit $status
