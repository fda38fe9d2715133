#!/usr/bin/env bash
# Octree build throughput (`pointrast lod`) on generated terrain, for bench/results/<device>/lod-build.md.
# LAS in (point format 2: 26 B a point), Potree 2.0 octree out (DEFAULT encoding, 24 B a point); each
# input is read once before its build, so the build reads it from the page cache. Reports every phase
# (seconds, CPU seconds, points/s, points/s per core) beside the PotreeConverter 2 and SimLOD anchors.
#
#   scripts/bench-lod.sh run [SIZES...]      builds each size (default: 10M/2 100M 1G) -> $OUT/lod-build.jsonl
#                                            SIZE/C: on the first C cores only (taskset, --threads C)
#   scripts/bench-lod.sh report [JSONL]      -> $OUT/lod-build.json and $OUT/lod-build.md (needs python3)
#
# Environment: POINTRAST_BIN (default .gpu/bin/pointrast, else build-rel/pointrast), OUT (default
# ./gpu-out), WORK (scratch folder for inputs and octrees, default /tmp/pointrast-lod-bench), LOD_ARGS (extra
# `pointrast lod` arguments), KEEP=1 (keep the generated LAS files), LOD_FORMAT=copc (a COPC file out instead
# of the Potree folder; the runs and report are then named copc-lod-build), LOD_INDEX (where the index phase
# runs, `--index-on`: "cpu" by default; "cpu gpu" builds each size both ways, one after the other, from the
# same cached LAS, and checks that the two octrees are the same bytes), LOD_OUT_DIR (where the octrees go,
# default WORK: /dev/shm builds with the points and the octree in memory), LOD_DISK (the size of the file
# that measures WORK's write bandwidth first, default 8G; 0 skips it).
# Space: N points need 26 N bytes of LAS plus 24 N of octree at once (1 G: 26 + 24 GB; each octree is
# deleted after its run; a size that does not fit the free space of WORK is skipped, saying so) and about
# 56 N bytes of memory by the builder's estimate to build in memory (1 G: 56 GB, under the default --memory
# of half the RAM on a 128 GB machine; about 42 GB resident measured); above that the build runs out of
# core, and says so.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-$PWD/gpu-out}
WORK=${WORK:-${TMPDIR:-/tmp}/pointrast-lod-bench} # never under $OUT: its files travel back
PR=${POINTRAST_BIN:-}
if [ -z "$PR" ]; then
  if [ -x .gpu/bin/pointrast ]; then PR=$PWD/.gpu/bin/pointrast; else PR=$PWD/build-rel/pointrast; fi
fi
mkdir -p "$OUT"
name=lod-build ext=""
if [ "${LOD_FORMAT:-potree}" = copc ]; then name=copc-lod-build ext=.copc.laz; fi

machine_json() {
  local cpu gpu mem
  cpu=$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //; s/"//g' || echo unknown)
  gpu=$(nvidia-smi -L 2>/dev/null | head -1 | sed 's/ (UUID.*//; s/"//g' || true)
  mem=$(awk '/MemTotal/ {printf "%d", $2 * 1024}' /proc/meminfo)
  printf '{"cores":%s,"memory_bytes":%s,"cpu":"%s","gpu":"%s","dirty_ratio":%s,"dirty_background_ratio":%s,"kernel":"%s"}' \
    "$(nproc)" "$mem" "$cpu" "${gpu:-none}" "$(cat /proc/sys/vm/dirty_ratio)" \
    "$(cat /proc/sys/vm/dirty_background_ratio)" "$(uname -r)"
}

# Bytes of a count such as 100M or 1G.
count_of() {
  python3 -c "import sys; s = sys.argv[1]; k = {'K': 1e3, 'M': 1e6, 'G': 1e9}.get(s[-1:].upper()); print(int(float(s[:-1]) * k if k else int(s)))" "$1"
}

# One checksum of files' bytes, hashed in 1 GiB slices on all cores (an octree of 24 GB in seconds, not
# the minute of one md5sum): the md5 of each slice's md5, in order.
checksum() {
  local f size slices
  for f in "$@"; do
    size=$(stat -c %s "$f")
    slices=$(((size + (1 << 30) - 1) >> 30))
    [ "$slices" -gt 0 ] || slices=1
    # shellcheck disable=SC2016 # expanded by the inner shell
    seq 0 $((slices - 1)) | xargs -P "$(nproc)" -I{} sh -c \
      'printf "%s %s\n" {} "$(dd if="$1" bs=1M skip=$(({} * 1024)) count=1024 status=none | md5sum | cut -c1-32)"' _ "$f" |
      sort -n
  done | md5sum | cut -c1-32
}

# The disk's sequential write bandwidth in WORK (bench-io --disk: plain, and with the octree writer's
# write-behind), into $OUT/$name-disk.json; LOD_DISK sets the file's size (default 8G, 0 to skip).
disk() {
  local laz="" f
  [ "${LOD_DISK:-8G}" != 0 ] || return 0
  for f in .gpu/data/laz/autzen_trim.laz ../shared/data/laz/autzen_trim.laz; do
    [ -f "$f" ] && { laz=$f; break; }
  done
  [ -n "$laz" ] || { echo "== no autzen_trim.laz for bench-io: the disk is not measured"; return 0; }
  echo "== the disk's sequential write bandwidth in $WORK (${LOD_DISK:-8G})"
  "$PR" bench-io "$laz" --threads all --repeats 1 --no-read-cloud --no-encode --disk "${LOD_DISK:-8G}" \
    --disk-dir "$WORK" --out "$OUT" --name "$name-disk" --quiet >/dev/null
}

run() {
  local sizes=("$@")
  [ ${#sizes[@]} -gt 0 ] || sizes=(10M/2 100M 1G)
  mkdir -p "$WORK"
  disk
  for spec in "${sizes[@]}"; do
    local size=${spec%/*} cores="" pin=()
    if [ "$spec" != "$size" ]; then
      cores=${spec#*/}
      pin=(taskset -c "0-$((cores - 1))")
    fi
    local las=$WORK/terrain-$size.las octree=${LOD_OUT_DIR:-$WORK}/octree-$size$ext
    local need free
    need=$(($(count_of "$size") * 52)) # 26 B of LAS + 24 B of octree a point, and 2 B of slack
    [ -f "$las" ] && need=$((need - $(stat -c %s "$las")))
    free=$(df -B1 --output=avail "$WORK" | tail -1)
    if [ "$need" -gt "$free" ]; then
      echo "== skipping $size: needs $((need / 1000000000)) GB in $WORK, $((free / 1000000000)) GB free"
      continue
    fi
    if [ ! -f "$las" ]; then
      echo "== generating $size terrain points"
      /usr/bin/time -f "generate: %e s, %M KB" "$PR" generate terrain --points "$size" --point-format 2 -o "$las"
    fi
    echo "== reading $las once (page cache)"
    cat "$las" >/dev/null
    local index reference="" same
    for index in ${LOD_INDEX:-cpu}; do
      rm -rf "$octree"
      echo "== pointrast lod $size${cores:+ on $cores cores}, index on $index"
      local json
      # shellcheck disable=SC2086
      json=$(/usr/bin/time -f "lod: %e s, %M KB" "${pin[@]}" "$PR" lod "$las" -o "$octree" --json \
        --index-on "$index" ${cores:+--threads $cores} ${LOD_ARGS:-})
      # The same octree whichever device indexed it: the first build's checksum against the others'.
      local sum
      if [ -d "$octree" ]; then sum=$(checksum "$octree/octree.bin" "$octree/hierarchy.bin")
      else sum=$(checksum "$octree"); fi
      [ -n "$reference" ] || reference=$sum
      same=true
      [ "$sum" = "$reference" ] || { same=false; echo "== $size: the octree indexed on $index differs" >&2; }
      printf '{"size":"%s","cores":%s,"index":"%s","same_as_first":%s,"out_dir":"%s","machine":%s,"build":%s}\n' \
        "$size" "${cores:-$(nproc)}" "$index" "$same" "${LOD_OUT_DIR:-$WORK}" "$(machine_json)" "$json" |
        tee -a "$OUT/$name.jsonl"
      rm -rf "$octree"
    done
    [ "${KEEP:-0}" = 1 ] || rm -f "$las"
  done
}

report() {
  local jsonl=${1:-$OUT/$name.jsonl}
  python3 - "$jsonl" "$OUT/$name.json" "$OUT/$name.md" "$ext" <<'PY'
import json, sys
src, out_json, out_md, ext = sys.argv[1:5]
runs = [json.loads(line) for line in open(src) if line.strip()]
json.dump(runs, open(out_json, "w"), indent=1)
# Anchors: PotreeConverter 2 measured on the 16-core NVIDIA machine on 100 M generated terrain points;
# SimLOD (Schuetz et al. 2023) builds in GPU memory on an RTX 4090 and writes nothing to disk.
anchors = [("PotreeConverter 2, poisson (its default)", 7.7e6), ("PotreeConverter 2, poisson_average", 7.1e6),
           ("PotreeConverter 2, random", 14.3e6), ("SimLOD, in GPU memory, no files (RTX 4090)", 580e6)]
def m(v): return f"{v / 1e6:,.1f} M"
lines = ["# Octree build throughput (`pointrast lod`)", "",
         "Generated terrain (`pointrast generate terrain --point-format 2`), LAS in from the page cache, "
         + ("a COPC file out (LAZ, one chunk a node)" if ext else "Potree 2.0 octree out (DEFAULT encoding)") + ", written by `scripts/bench-lod.sh`. Points/s are input points over wall "
         "seconds; per core divides by the threads the build ran. `write` runs during `index` (its time is part "
         "of it), so the phases above it add up to the total.", ""]
if runs:
    mc = runs[0]["machine"]
    gpu = mc["gpu"].split(": ", 1)[-1] # nvidia-smi -L: "GPU 0: NAME"
    lines += [f"Machine: {mc['cores']} cores ({mc['cpu']}), {mc['memory_bytes'] / 2**30:.0f} GiB, GPU {gpu}, "
              f"kernel {mc['kernel']}, dirty_ratio {mc['dirty_ratio']} %.", ""]
# The disk's sequential write bandwidth, measured in the same run (bench-io --disk), where it was.
disk = {}
try:
    for d in json.load(open(out_json[:-len(".json")] + "-disk.json"))["disk_write"]["runs"]:
        disk[d["mode"]] = d["bytes_per_s"]
except (OSError, KeyError, ValueError):
    pass
best_disk = max(disk.values()) if disk else None
if disk:
    lines += ["Disk (the build's output folder), sequential write until fdatasync: " +
              ", ".join(f"{mode} {v / 1e6:,.0f} MB/s" for mode, v in disk.items()) +
              ". `disk floor` is the octree's bytes over the faster of the two: the least time the disk "
              "allows the build, and `points/s the disk allows` the points over it.", ""]
lines += ["`after read` times the build from the points in memory (the total less the read phase: counting, "
          "chunking, distributing, indexing with the writes, commit).", ""]
lines += ["| points | cores | index on | total s | points/s | after read: s | points/s | points/s per core | octree GB | "
          "written MB/s over index | disk floor s | points/s the disk allows | in memory | threads | vs PotreeConverter 2 poisson | vs random |",
          "| ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | :---: | ---: | ---: | ---: |"]
def anchor(r):
    # PotreeConverter 2 on 2 cores was measured on the 2-core development machine (1.5 M points/s, poisson);
    # on all cores, on this machine (7.7 M poisson, 14.3 M random).
    return (1.5e6, None) if r.get("cores") == 2 else (7.7e6, 14.3e6)
for r in runs:
    b = r["build"]
    pps = b["points_per_second"]
    poisson, rnd = anchor(r)
    index = r.get("index", "cpu") + ("" if r.get("same_as_first", True) else " (**differs**)")
    phase = {p["name"]: p for p in b["phases"]}
    after = b["seconds"] - phase["read"]["seconds"] if "read" in phase else b["seconds"]
    index_s = phase["index"]["seconds"] if "index" in phase else 0
    octree_in_ram = r.get("out_dir", "").startswith("/dev/shm")
    if octree_in_ram: index += ", octree to /dev/shm"
    floor = b["bytes"] / best_disk if best_disk and not octree_in_ram else None
    lines.append(f"| {b['points']:,} | {r.get('cores', '')} | {index} | {b['seconds']:.2f} | {m(pps)} | "
                 f"{after:.2f} | {m(b['points'] / after)} | {m(pps / b['threads'])} | "
                 f"{b['bytes'] / 1e9:.1f} | {b['bytes'] / index_s / 1e6 if index_s else 0:,.0f} | "
                 f"{f'{floor:.2f}' if floor else '-'} | {m(b['points'] / floor) if floor else '-'} | "
                 f"{'no' if b['out_of_core'] else 'yes'} | {b['threads']} | "
                 f"{pps / poisson:.1f}x | {f'{pps / rnd:.1f}x' if rnd else '-'} |")
for r in runs:
    b = r["build"]
    cores = f" on {r['cores']} cores" if r.get("cores") else ""
    device = ""
    if b.get("index_device"):
        st = b.get("index_device_steps", {})
        steps = ", ".join(f"{k} {st[k]:.2f}" for k in ("stage", "sort", "order", "levels", "read") if k in st)
        device = (f", index on {b['index_device']} ({b['index_gpu_chunks']} chunks; {b['index_cpu_chunks']} on the CPU; "
                  f"{b['index_device_seconds']:.2f} s in its steps, summed over the chunks in flight: {steps}; "
                  + (f"submissions {b['index_device_busy_seconds']:.2f} s (one at a time: the device's busy time); "
                     if "index_device_busy_seconds" in b else "") +
                  f"threads waited {b.get('index_wait_seconds', 0):.2f} s for a free slot, summed)")
    lines += ["", f"## {r['size']} points{cores}{device}: phases", "",
              "| phase | seconds | CPU seconds | points/s | points/s per core |", "| --- | ---: | ---: | ---: | ---: |"]
    for p in b["phases"]:
        if p["overlapped"]:
            cpu = f"(in index; {p.get('thread_seconds', 0):.2f} s over all threads)"
        else:
            cpu = f"{p['cpu_seconds']:.2f}"
        lines.append(f"| {p['name']} | {p['seconds']:.2f} | {cpu} | {m(p['points_per_second'])} | "
                     f"{m(p['points_per_second'] / b['threads'])} |")
    lines.append(f"| **total** | **{b['seconds']:.2f}** | | **{m(b['points_per_second'])}** | "
                 f"{m(b['points_per_second'] / b['threads'])} |")
lines += ["", "`write` seconds are its part in the builder's order (placing nodes in octree.bin, one thread at a time); "
          "the bytes are written from all indexing threads at once, the time of that over all threads in brackets."]
lines += ["", "## Anchors", "", "| builder | points/s |", "| --- | ---: |"]
lines += [f"| {name} | {m(v)} |" for name, v in anchors]
lines += ["| PotreeConverter 2, poisson, 2 cores of the development machine (AMD EPYC VM; 10.65 M airborne points) | 1.5 M |"]
lines += ["", "Targets: at least 100 M points/s end to end for 1 G points on this machine; on 2 cores, at least 5x "
          "PotreeConverter 2 on 2 cores (7.5 M points/s; its figure comes from another machine's 2 cores)."]
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
