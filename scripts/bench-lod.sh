#!/usr/bin/env bash
# Octree build throughput (`pointrast lod`) on generated terrain, for bench/results/<device>/lod-build.md.
# LAS in (point format 2: 26 B a point), Potree 2.0 octree out (DEFAULT encoding, 24 B a point); each
# input is read once before its build, so the build reads it from the page cache. Reports every phase
# (seconds, CPU seconds, points/s, points/s per core) beside the PotreeConverter 2 and SimLOD anchors.
#
#   scripts/bench-lod.sh run [SIZES...]      builds each size (default: 100M 1G) -> $OUT/lod-build.jsonl
#   scripts/bench-lod.sh report [JSONL]      -> $OUT/lod-build.json and $OUT/lod-build.md (needs python3)
#
# Environment: POINTRAST_BIN (default .gpu/bin/pointrast, else build-rel/pointrast), OUT (default
# ./gpu-out), WORK (scratch folder for inputs and octrees, default /tmp/pointrast-lod-bench), LOD_ARGS (extra
# `pointrast lod` arguments), KEEP=1 (keep the generated LAS files).
# Space: N points need 26 N bytes of LAS plus 24 N of octree at once (1 G: 26 + 24 GB; each octree is
# deleted after its run) and about 58 N bytes of memory to build in memory (1 G: 58 GB, under the default
# --memory of half the RAM on a 128 GB machine); above that the build runs out of core, and says so.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-$PWD/gpu-out}
WORK=${WORK:-${TMPDIR:-/tmp}/pointrast-lod-bench} # never under $OUT: its files travel back
PR=${POINTRAST_BIN:-}
if [ -z "$PR" ]; then
  if [ -x .gpu/bin/pointrast ]; then PR=$PWD/.gpu/bin/pointrast; else PR=$PWD/build-rel/pointrast; fi
fi
mkdir -p "$OUT"

machine_json() {
  local cpu gpu mem
  cpu=$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //; s/"//g' || echo unknown)
  gpu=$(nvidia-smi -L 2>/dev/null | head -1 | sed 's/ (UUID.*//; s/"//g' || true)
  mem=$(awk '/MemTotal/ {printf "%d", $2 * 1024}' /proc/meminfo)
  printf '{"cores":%s,"memory_bytes":%s,"cpu":"%s","gpu":"%s","dirty_ratio":%s,"dirty_background_ratio":%s,"kernel":"%s"}' \
    "$(nproc)" "$mem" "$cpu" "${gpu:-none}" "$(cat /proc/sys/vm/dirty_ratio)" \
    "$(cat /proc/sys/vm/dirty_background_ratio)" "$(uname -r)"
}

run() {
  local sizes=("$@")
  [ ${#sizes[@]} -gt 0 ] || sizes=(100M 1G)
  mkdir -p "$WORK"
  for size in "${sizes[@]}"; do
    local las=$WORK/terrain-$size.las octree=$WORK/octree-$size
    if [ ! -f "$las" ]; then
      echo "== generating $size terrain points"
      /usr/bin/time -f "generate: %e s, %M KB" "$PR" generate terrain --points "$size" --point-format 2 -o "$las"
    fi
    echo "== reading $las once (page cache)"
    cat "$las" >/dev/null
    rm -rf "$octree"
    echo "== pointrast lod $size"
    local json
    json=$(/usr/bin/time -f "lod: %e s, %M KB" "$PR" lod "$las" -o "$octree" --json ${LOD_ARGS:-})
    printf '{"size":"%s","machine":%s,"build":%s}\n' "$size" "$(machine_json)" "$json" | tee -a "$OUT/lod-build.jsonl"
    rm -rf "$octree"
    [ "${KEEP:-0}" = 1 ] || rm -f "$las"
  done
}

report() {
  local jsonl=${1:-$OUT/lod-build.jsonl}
  python3 - "$jsonl" "$OUT/lod-build.json" "$OUT/lod-build.md" <<'PY'
import json, sys
src, out_json, out_md = sys.argv[1:4]
runs = [json.loads(line) for line in open(src) if line.strip()]
json.dump(runs, open(out_json, "w"), indent=1)
# Anchors: PotreeConverter 2 measured on the 16-core NVIDIA machine on 100 M generated terrain points;
# SimLOD (Schuetz et al. 2023) builds in GPU memory on an RTX 4090 and writes nothing to disk.
anchors = [("PotreeConverter 2, poisson (its default)", 7.7e6), ("PotreeConverter 2, poisson_average", 7.1e6),
           ("PotreeConverter 2, random", 14.3e6), ("SimLOD, in GPU memory, no files (RTX 4090)", 580e6)]
def m(v): return f"{v / 1e6:,.1f} M"
lines = ["# Octree build throughput (`pointrast lod`)", "",
         "Generated terrain (`pointrast generate terrain --point-format 2`), LAS in from the page cache, Potree 2.0 "
         "octree out (DEFAULT encoding), written by `scripts/bench-lod.sh`. Points/s are input points over wall "
         "seconds; per core divides by the threads the build ran. `write` runs during `index` (its time is part "
         "of it), so the phases above it add up to the total.", ""]
if runs:
    mc = runs[0]["machine"]
    lines += [f"Machine: {mc['cores']} cores ({mc['cpu']}), {mc['memory_bytes'] / 2**30:.0f} GiB, GPU {mc['gpu']}, "
              f"kernel {mc['kernel']}, dirty_ratio {mc['dirty_ratio']} %.", ""]
lines += ["| points | total s | points/s | points/s per core | octree GB | in memory | threads | vs PotreeConverter 2 poisson | vs random |",
          "| ---: | ---: | ---: | ---: | ---: | :---: | ---: | ---: | ---: |"]
for r in runs:
    b = r["build"]
    pps = b["points_per_second"]
    lines.append(f"| {b['points']:,} | {b['seconds']:.2f} | {m(pps)} | {m(pps / b['threads'])} | "
                 f"{b['bytes'] / 1e9:.1f} | {'no' if b['out_of_core'] else 'yes'} | {b['threads']} | "
                 f"{pps / 7.7e6:.1f}x | {pps / 14.3e6:.1f}x |")
for r in runs:
    b = r["build"]
    lines += ["", f"## {r['size']} points: phases", "",
              "| phase | seconds | CPU seconds | points/s | points/s per core |", "| --- | ---: | ---: | ---: | ---: |"]
    for p in b["phases"]:
        cpu = "(in index)" if p["overlapped"] else f"{p['cpu_seconds']:.2f}"
        lines.append(f"| {p['name']} | {p['seconds']:.2f} | {cpu} | {m(p['points_per_second'])} | "
                     f"{m(p['points_per_second'] / b['threads'])} |")
    lines.append(f"| **total** | **{b['seconds']:.2f}** | | **{m(b['points_per_second'])}** | "
                 f"{m(b['points_per_second'] / b['threads'])} |")
lines += ["", "## Anchors", "", "| builder | points/s |", "| --- | ---: |"]
lines += [f"| {name} | {m(v)} |" for name, v in anchors]
lines += ["", "Target: at least 100 M points/s end to end for 1 G points on this machine."]
open(out_md, "w").write("\n".join(lines) + "\n")
print(out_md)
PY
}

case ${1:-} in
run)
  shift
  run "$@"
  ;;
report)
  shift
  report "$@"
  ;;
*)
  sed -n '2,18p' "$0"
  exit 1
  ;;
esac
