#!/usr/bin/env bash
# Runs on a GPU machine (after scripts/gpu-bundle.sh here; carry .gpu and .vkrt): the GPU tests with the
# validation layer, the CLI tests, and the checks and benchmarks named by the arguments. Results go to
# $OUT (default ./gpu-out). Suites: SUITE_LIMIT (bench --time-limit: wall seconds after which no further
# combination starts; the process is killed 90 s later if it still runs), SUITE_FRAMES,
# SUITE_BUDGET (GPU seconds per combination, see `pointrast bench --help`), SUITE_METHODS, SUITE_ARGS,
# SUITE_VIEWS (batch1g);
# BIG4G_METHOD (default batch).
# OCTREE_CACHE: the octree cache of lodsuite and lod2022 (default /tmp/octrees: on the machine's disk).
# LOD_SIZES, LOD_INDEX (lod: the sizes, and "cpu gpu" to build each on the CPU and with the GPU index phase).
#   scripts/gpu-check.sh tests big    # tests + the 1.2-billion-point equivalence run
#   scripts/gpu-check.sh lazio        # LAZ decoding throughput (bench-io) on 1, 8 and all cores
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-$PWD/gpu-out}
mkdir -p "$OUT"
log="$OUT/gpu-check.log"
exec > >(tee -a "$log") 2>&1

# Vulkan loader for machines that have the NVIDIA driver but no loader.
if ! ldconfig -p | grep -q libvulkan.so.1; then
  for f in .vkrt/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json; do
  if [ -f "$icd" ]; then export VK_DRIVER_FILES=$icd; break; fi
done
# Validation layer unpacked aside (never into /).
if ls .vkrt/layers/*.deb >/dev/null 2>&1; then
  rm -rf /tmp/vklayer && dpkg -x .vkrt/layers/*.deb /tmp/vklayer
  export VK_LAYER_PATH=/tmp/vklayer/usr/share/vulkan/explicit_layer.d
  export LD_LIBRARY_PATH=/tmp/vklayer/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
else
  export POINTRAST_VALIDATION=0
fi
# A hung submission becomes an error after this long instead of stalling the call (0 = the default 120 s).
export POINTRAST_GPU_TIMEOUT_S=${POINTRAST_GPU_TIMEOUT_S:-40}
export POINTRAST_BIN=$PWD/.gpu/bin/pointrast POINTRAST_DATA_DIR=$PWD/.gpu/data XDG_RUNTIME_DIR=/tmp
pr=$POINTRAST_BIN
# The small ffmpeg gpu-bundle.sh builds, where the machine has none (video checks and the CLI video tests).
if ! command -v ffmpeg >/dev/null && [ -x .gpu/ffmpeg/ffmpeg ]; then
  export PATH=$PWD/.gpu/ffmpeg:$PATH LD_LIBRARY_PATH=$PWD/.gpu/ffmpeg${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
fi

echo "== machine"
nvidia-smi -L 2>/dev/null || true
# A machine that ran a hung kernel stays busy with no process and hangs graphics work from then on
# (docs/performance.md): say so at once instead of producing stalls.
busy=$(nvidia-smi --query-gpu=utilization.gpu --format=csv,noheader,nounits 2>/dev/null | head -1)
if [ -n "$busy" ] && [ "$busy" -gt 50 ] && [ -z "$(nvidia-smi --query-compute-apps=pid --format=csv,noheader 2>/dev/null)" ]; then
  echo "WARNING: GPU ${busy}% busy with no process: probably wedged by an earlier hang; use a fresh machine"
fi
nproc; free -g | head -2
$pr info --devices

status=0
for what in "$@"; do
  case $what in
  tests)
    echo "== GPU tests (validation ${POINTRAST_VALIDATION:-on})"
    .gpu/bin/gpu_tests --gtest_brief=1 || status=1
    .gpu/bin/cli_tests --gtest_brief=1 || status=1
    .gpu/bin/bench_tests --gtest_brief=1 || status=1
    ;;
  lod)
    echo "== octree build: pointrast lod on generated terrain (scripts/bench-lod.sh), ${LOD_SIZES:-10M/2 100M 1G} points"
    # shellcheck disable=SC2086
    { POINTRAST_BIN=$pr OUT=$OUT scripts/bench-lod.sh run ${LOD_SIZES:-10M/2 100M 1G} && OUT=$OUT scripts/bench-lod.sh report; } || status=1
    ;;
  autzen)
    echo "== autzen_trim.las"
    $pr render .gpu/data/las/autzen_trim.las -o "$OUT/autzen.png" --json --frames 50 | tee "$OUT/autzen.json" || status=1
    ;;
  lazio)
    # LAZ decoding on 1, 8 and all cores (CPU only): autzen_trim.laz (point format 3, pointwise chunks),
    # las_with_several_extra_byte_bloc.laz (point format 8 + 3 extra bytes, layered: the items of point format
    # 7 and more) and lone-star.copc.laz (COPC, point format 6), each replicated from its own chunks to
    # IO_POINTS points: about 1 s a file on 16 cores at the 40 M points/s target. Writes
    # $OUT/laz-decode.{json,md}.
    echo "== LAZ decoding (bench-io), ${IO_POINTS:-50M} points per file"
    $pr bench-io .gpu/data/laz/autzen_trim.laz .gpu/data/laz/las_with_several_extra_byte_bloc.laz \
      .gpu/data/laz/lone-star.copc.laz --points "${IO_POINTS:-50M}" --threads "1,8,$(nproc)" \
      --repeats "${IO_REPEATS:-5}" --out "$OUT" --name laz-decode --quiet || status=1
    ;;
  post)
    # GPU time of each pass of the resolve stage at 1920x1080 and one VR eye (2478x2740).
    scripts/time-post.sh "$pr" "$OUT/post-passes.jsonl" 20M 50 || status=1
    ;;
  viewpath)
    # The 5 s orbit at 60 fps (300 frames) over a 1 G-point cloud into MP4 (PNG frames where no ffmpeg).
    echo "== render --path, 1 G points, 300 frames at 1920x1080"
    if command -v ffmpeg >/dev/null || [ -n "${POINTRAST_FFMPEG:-}" ]; then dst=(--video /tmp/orbit-1g.mp4); else dst=(--frames-dir /tmp/orbit-1g); fi
    POINTRAST_VALIDATION=0 $pr render terrain --points 1G --order morton --method batch-prefetch --path orbit \
      --fps 60 --width 1920 --height 1080 "${dst[@]}" --json | tee "$OUT/view-path-1g.json" || status=1
    if [ -f /tmp/orbit-1g.mp4 ] && command -v ffprobe >/dev/null; then
      echo "== ffprobe of the video (frames counted by decoding)"
      ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=codec_name,width,height,nb_read_frames \
        -of json /tmp/orbit-1g.mp4 | tee "$OUT/view-path-1g-ffprobe.json" || status=1
    fi
    ;;
  big)
    # 1.2 billion generated points (float32 xyz alone: 14.4 GB) drawn as one upload and as 12 separately
    # uploaded scenes of 100 M points; the two images must be identical.
    echo "== 1.2 G points, one upload"
    POINTRAST_VALIDATION=0 $pr render terrain --points 1.2G -o "$OUT/big.png" --json --frames 20 | tee "$OUT/big.json" || status=1
    echo "== 1.2 G points, 12 parts"
    POINTRAST_VALIDATION=0 $pr render terrain --points 1.2G -o "$OUT/big12.png" --json --frames 20 --parts 12 | tee "$OUT/big12.json" || status=1
    if cmp "$OUT/big.png" "$OUT/big12.png"; then echo "big: images identical"; else echo "big: IMAGES DIFFER"; status=1; fi
    ;;
  sweep)
    # Every method on a 200 M-point generated terrain in Morton order, overview: first look at the family.
    for m in atomicmin earlyz reduce reduce-earlyz dedup dedup-ballot busyloop justset hqs hqs1r; do
      POINTRAST_VALIDATION=0 $pr render terrain --points 200M --order morton --method $m -o "$OUT/sweep.png" --json --frames 20 -q | tee -a "$OUT/sweep.json" || status=1
    done
    ;;
  paper2021)
    # The 2021 evaluation: 4 stand-ins x all methods x 4 orders x 3 views at 1920x1080, one run.
    # --json lines are kept as they come, so a run cut short still leaves its results.
    # SUITE_METHODS replaces the suite's methods (the 2021 family by default); SUITE_FRAMES the timed frames.
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite paper2021 --frames "${SUITE_FRAMES:-15}" \
      --budget "${SUITE_BUDGET:-2}" ${SUITE_METHODS:+--methods "$SUITE_METHODS"} --out "$OUT" --name paper2021 --json > "$OUT/paper2021.jsonl" || status=1
    ;;
  paper2022)
    # The 2022 evaluation: 69 M .. 1,000 M stand-ins at 2560x1140, batch methods vs hw-points, dedup, hqs, and
    # lod, lod-hqs on the stand-ins' octrees (built into OCTREE_CACHE when missing: ~34 GB, ~2 min, once).
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite paper2022 --frames "${SUITE_FRAMES:-15}" \
      --budget "${SUITE_BUDGET:-2}" ${SUITE_METHODS:+--methods "$SUITE_METHODS"} --octree-cache "${OCTREE_CACHE:-/tmp/octrees}" \
      --out "$OUT" --name paper2022 --json > "$OUT/paper2022.jsonl" || status=1
    ;;
  spheres2023)
    # The 2023 sphere study: every sphere pipeline x layout x billboard x conservative on four particle
    # stand-ins (306 M, 4 M, 30 M, 200 M), 10 cameras per orbit. SUITE_ARGS narrows the matrix
    # (e.g. "--layouts vec4x2 --conservative off"), SUITE_SCALE shrinks the data sets.
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite spheres2023 --scale "${SUITE_SCALE:-1}" \
      --budget "${SUITE_BUDGET:-2}" ${SUITE_ARGS:-} --out "$OUT" --name spheres2023 --json > "$OUT/spheres2023.jsonl" || status=1
    ;;
  vr2022)
    # The 2022 VR frame (2 x 2478x2740, lod-hqs, foveated, dilation) on the 529 M tls stand-in's octree, stereo
    # pass against two mono renders. The octree is built into OCTREE_CACHE on the first run (about 10 GB; the
    # generation and build about 1 min on 16 cores) and reused after, also by paper2022's scan529m.
    mkdir -p "${OCTREE_CACHE:-/tmp/octrees}" && df -hT "${OCTREE_CACHE:-/tmp/octrees}"
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite vr2022 \
      --octree-cache "${OCTREE_CACHE:-/tmp/octrees}" ${SUITE_FRAMES:+--frames "$SUITE_FRAMES"} ${SUITE_SCALE:+--scale "$SUITE_SCALE"} \
      --out "$OUT" --name vr2022 --json > "$OUT/vr2022.jsonl" || status=1
    ls -l "${OCTREE_CACHE:-/tmp/octrees}"
    ;;
  batch1g)
    # The batch methods against dedup on the 1,000 M terrain overview of paper2022 (Morton, 2560x1140), in
    # one process so that their ratios are sound; SUITE_METHODS picks the methods. dedup comes first: the clocks
    # settle on it and it runs for a while, so that no batch method is the first one timed after the upload.
    # SUITE_VIEWS: the views (default overview).
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench terrain --points 1G --orders morton --views "${SUITE_VIEWS:-overview}" \
      --width 2560 --height 1140 --methods "${SUITE_METHODS:-dedup,batch,batch-prefetch}" --frames "${SUITE_FRAMES:-30}" \
      --time-limit "${SUITE_LIMIT:-470}" --out "$OUT" --name batch1g --json > "$OUT/batch1g.jsonl" || status=1
    ;;
  hqs796)
    # HQS against the closest-point methods on paper2021's 796 M stand-in (tls, 1920x1080), Morton and original
    # order, every view, in one process so that the ratios are sound; SUITE_METHODS picks the methods.
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite paper2021 \
      --datasets endeavor --orders morton,original --methods "${SUITE_METHODS:-reduce-earlyz,dedup-ballot,hqs,hqs1r}" \
      --frames "${SUITE_FRAMES:-15}" --budget "${SUITE_BUDGET:-2}" --out "$OUT" --name hqs796 --json > "$OUT/hqs796.jsonl" || status=1
    ;;
  big4g)
    # 4 billion generated points (the 2022 target: >= 60 fps on an H200), batched layout, in the terrain's
    # flight-strip scan order: a Morton reorder of 4 G points needs a second copy of the positions (48 GB)
    # beside the cloud (64 GB) and its permutation, more than the 128 GB such a machine has.
    echo "== 4 G points, ${BIG4G_METHOD:-batch}"
    POINTRAST_VALIDATION=0 $pr render terrain --points 4G --method "${BIG4G_METHOD:-batch}" --width 2560 \
      --height 1140 -o "$OUT/big4g.png" --json --frames 20 | tee "$OUT/big4g.json" || status=1
    ;;
  lodsuite)
    # The lod suite on the 1,000 M stand-in's octree: sweeps of point budget and --min-node-px, then streaming
    # with 1/8 of the octree in GPU memory (a flight and jumps). The octree is built into OCTREE_CACHE on the
    # machine's disk (about 18 GB; generation + build about 1-2 min on 16 cores) unless a run before built it;
    # lod2022 reuses it. df says which filesystem it is on (the page cache drop needs a real disk).
    mkdir -p "${OCTREE_CACHE:-/tmp/octrees}" && df -hT "${OCTREE_CACHE:-/tmp/octrees}"
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite lod \
      --octree-cache "${OCTREE_CACHE:-/tmp/octrees}" ${SUITE_FRAMES:+--frames "$SUITE_FRAMES"} ${SUITE_ARGS:-} --out "$OUT" --name lod \
      --json > "$OUT/lod.jsonl" || status=1
    ls -l "${OCTREE_CACHE:-/tmp/octrees}"
    ;;
  lod2022)
    # paper2022's LOD columns on the 1,000 M stand-in only: batch-prefetch against lod and lod-hqs at
    # 2560x1140, the octree from OCTREE_CACHE (built there first when lodsuite did not run before).
    mkdir -p "${OCTREE_CACHE:-/tmp/octrees}" && df -hT "${OCTREE_CACHE:-/tmp/octrees}"
    POINTRAST_VALIDATION=0 timeout $((${SUITE_LIMIT:-470} + 90)) $pr bench --time-limit "${SUITE_LIMIT:-470}" --suite paper2022 \
      --datasets aerial1g --methods batch-prefetch,lod,lod-hqs --frames "${SUITE_FRAMES:-15}" --budget "${SUITE_BUDGET:-2}" \
      --octree-cache "${OCTREE_CACHE:-/tmp/octrees}" --out "$OUT" --name lod2022 --json > "$OUT/lod2022.jsonl" || status=1
    ;;
  rendertime)
    # What a newcomer sees first: `render` of the 1 G overview (batch-prefetch, 2560x1140) as the first
    # process of the machine, then `bench` of the same method and view; the two medians belong side by side.
    echo "== render against bench: 1 G terrain, batch-prefetch, overview, 2560x1140"
    POINTRAST_VALIDATION=0 $pr render terrain --points 1G --order morton --method batch-prefetch --width 2560 \
      --height 1140 --frames 30 -o "$OUT/render-1g.png" --json | tee "$OUT/render-1g.json" || status=1
    POINTRAST_VALIDATION=0 $pr bench terrain --points 1G --orders morton --views overview --width 2560 \
      --height 1140 --methods batch-prefetch --frames 30 --out "$OUT" --name render-vs-bench --json \
      > "$OUT/render-vs-bench.jsonl" || status=1
    ;;
  servelod)
    # The browser viewer with level of detail: the 1 G stand-in's octree, a node cache of 1/8 of it, one
    # loopback client flying low and jumping (scripts/bench-serve-lod.sh); writes serve-lod.json and .md.
    echo "== serve with LOD: ${SERVE_POINTS:-1G} points as an octree, one client at 1920x1080"
    POINTRAST_VALIDATION=0 SERVE_LOAD=$PWD/.gpu/bin/serve_load OUT=$OUT POINTRAST_BIN=$pr \
      timeout 560 scripts/bench-serve-lod.sh "${SERVE_POINTS:-1G}" || status=1
    ;;
  serve)
    # The browser viewer: `serve` on 1 G generated points (SERVE_POINTS, SERVE_METHOD), one loopback client
    # at 1920x1080 (serve_load); writes serve.json and serve.md.
    echo "== serve: ${SERVE_POINTS:-1G} points, one client at 1920x1080"
    POINTRAST_VALIDATION=0 SERVE_LOAD=$PWD/.gpu/bin/serve_load OUT=$OUT \
      timeout 540 scripts/bench-serve.sh "${SERVE_POINTS:-1G}" "${SERVE_METHOD:-batch-prefetch}" || status=1
    ;;
  filtercost)
    # Clip volumes and a class filter on the 1 G overview against no filter (scripts/bench-filter-cost.sh);
    # writes filter-cost.{jsonl,md}.
    echo "== filter cost: ${FILTER_POINTS:-1G} points"
    POINTRAST_VALIDATION=0 timeout 560 scripts/bench-filter-cost.sh "$pr" "$OUT" "${FILTER_POINTS:-1G}" || status=1
    ;;
  deviceloss)
    # A lost GPU under serve (scripts/bench-device-loss.py): the 1 G stand-in with the device lost at the
    # INJECT-th submission; the page must be told and the process exit 1 within 5 s. Writes device-loss.*.
    echo "== device loss under serve: ${LOSS_POINTS:-1G} points"
    POINTRAST_VALIDATION=0 INJECT=${INJECT:-2000} timeout 300 python3 scripts/bench-device-loss.py "$pr" "$OUT" \
      terrain --points "${LOSS_POINTS:-1G}" || status=1
    ;;
  python)
    # The Python module against the CLI (scripts/bench-python.py): pointrast.render of NumPy arrays, upload
    # GB/s and frame ms beside `pointrast render` of the same points. Needs .gpu/python/pointrast, the
    # module built for this machine's python3 (docs/python.md says how). Writes python-render.{json,md}.
    echo "== python: ${PY_POINTS:-100M 1G}"
    PYTHONPATH=$PWD/.gpu/python POINTRAST_VALIDATION=0 BENCH_TMP=${BENCH_TMP:-/tmp} \
      timeout 560 python3 scripts/bench-python.py "$OUT" "$pr" ${PY_POINTS:-100M 1G} || status=1
    ;;
  mpi)
    # Distributed rendering (docs/mpi.md) at 2560x1140, render, read-back, composite and resolve ms apart
    # (scripts/bench-mpi.sh): the runs in MPI_RUNS (its RUN syntax; default 1 G points on 1 and 2 ranks).
    # lod runs read MPI_OCTREE; with MPI_OCTREE_POINTS set and no octree there, it is built first from that
    # many generated terrain points (LAS, then `pointrast lod`; the LAS is removed after). Writes
    # mpi-scaling.{jsonl,md} and each run's image. A machine without mpirun takes Debian's Open MPI from
    # .mpirt/ (its .deb files, carried beside .vkrt/; the binary is built against Debian's libmpi.so.40).
    if ! command -v mpirun >/dev/null && ls .mpirt/*.deb >/dev/null 2>&1; then
      for f in .mpirt/*.deb; do dpkg -x "$f" /; done
      ldconfig
    fi
    mpirun --version | head -1
    nvidia-smi --query-gpu=index,name,memory.total --format=csv,noheader
    if [ -n "${MPI_OCTREE_POINTS:-}" ] && [ ! -f "${MPI_OCTREE:?MPI_OCTREE_POINTS needs MPI_OCTREE}/metadata.json" ]; then
      start=$SECONDS
      mkdir -p "$(dirname "$MPI_OCTREE")"
      $pr generate terrain --points "$MPI_OCTREE_POINTS" --point-format 2 -o "$MPI_OCTREE.las" -q &&
        $pr lod "$MPI_OCTREE.las" -o "$MPI_OCTREE" --json -q >"$OUT/mpi-octree-build.json" || status=1
      rm -f "$MPI_OCTREE.las"
      echo "mpi: generated and built $MPI_OCTREE_POINTS points into $MPI_OCTREE in $((SECONDS - start)) s"
      du -sh "$MPI_OCTREE"
    fi
    # shellcheck disable=SC2086 # MPI_RUNS is a list of runs
    MPI_OCTREE=${MPI_OCTREE:-} timeout 1500 scripts/bench-mpi.sh "$pr" "$OUT" ${MPI_RUNS:-} || status=1
    ;;
  *)
    echo "unknown check '$what' (tests, mpi, python, filtercost, deviceloss, autzen, lazio, post, viewpath, big, big4g, batch1g, hqs796, sweep, paper2021, paper2022, spheres2023, lodsuite, lod2022, serve, servelod, rendertime, vr2022)"; status=1 ;;
  esac
done
echo "gpu-check: exit $status"
exit $status
