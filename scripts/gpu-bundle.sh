#!/usr/bin/env bash
# Prepares what a GPU machine needs, in folders git ignores (.gpu/, .vkrt/):
#   .gpu/bin   Release pointrast + GPU/CLI test binaries, statically linked C++ runtime
#   .gpu/data  the few shared data files the GPU and CLI tests read
#   .gpu/ffmpeg a small ffmpeg/ffprobe for machines without one (scripts/device-ffmpeg.sh)
#   .vkrt      Vulkan loader (+ validation layer) packages for a machine that lacks them
# Then run on that machine: scripts/gpu-check.sh (carry .gpu and .vkrt).
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p .git/info; grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >> .git/info/exclude
mkdir -p .git/info; grep -qx '/.vkrt/' .git/info/exclude 2>/dev/null || echo '/.vkrt/' >> .git/info/exclude
cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2" -DPOINTRAST_STATIC_RUNTIME=ON
cmake --build build-gpu -j"$(nproc)" --target pointrast gpu_tests cli_tests bench_tests serve_load
rm -rf .gpu && mkdir -p .gpu/bin .gpu/data/las .gpu/data/laz .gpu/data/las/permutations .gpu/data/mmpld
cp build-gpu/pointrast build-gpu/tests/gpu_tests build-gpu/tests/cli_tests build-gpu/tests/bench_tests .gpu/bin/
cp build-gpu/serve_load .gpu/bin/
# `serve` loads civetweb at run time, from beside the binary where the system has none.
cp -L /usr/lib/x86_64-linux-gnu/libcivetweb.so.1 .gpu/bin/
strip .gpu/bin/*
data=../shared/data
cp $data/las/{autzen_trim,1.2-with-color,no-points,test1_4}.las .gpu/data/las/ # the CLI tests' LAS files
cp $data/las/permutations/1.2-no-points.las .gpu/data/las/permutations/
cp $data/laz/*.laz .gpu/data/laz/
cp $data/mmpld/*.mmpld .gpu/data/mmpld/ # 72 KiB: the particle CLI tests read every one
bash scripts/device-ffmpeg.sh .gpu/ffmpeg
mkdir -p .vkrt/layers
cp ../shared/vulkan-runtime/*.deb .vkrt/ 2>/dev/null || true
if ! ls .vkrt/layers/vulkan-validationlayers_*.deb >/dev/null 2>&1; then
  (cd .vkrt/layers && apt-get download vulkan-validationlayers)
fi
du -sh .gpu .vkrt
