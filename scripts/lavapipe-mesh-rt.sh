#!/usr/bin/env bash
# A newer lavapipe (Mesa 25 from bookworm-backports) that has VK_EXT_mesh_shader and
# VK_KHR_ray_tracing_pipeline, so that sphere-mesh-points, sphere-mesh-tris and sphere-rt run on a machine
# without a GPU. Nothing of the system changes: the packages are fetched with a private apt state and
# unpacked under DIR (default ~/.cache/pointrast-lavapipe); the system's lavapipe (Mesa 22.3, which has neither
# extension) stays the default. Prints the environment that selects the new driver:
#   eval "$(scripts/lavapipe-mesh-rt.sh)" && build/tests/gpu_tests --gtest_filter='*SphereMeshRt*'
set -euo pipefail
cd "$(dirname "$0")/.."
DIR=$(realpath -m "${1:-${XDG_CACHE_HOME:-$HOME/.cache}/pointrast-lavapipe}")
mkdir -p "$DIR/lists/partial" "$DIR/cache/archives/partial" "$DIR/debs" "$DIR/root"
cat >"$DIR/sources.list" <<LIST
deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian bookworm-backports main
deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian bookworm main
LIST
apt=(-o "Dir::Etc::sourcelist=$DIR/sources.list" -o Dir::Etc::sourceparts=- -o "Dir::State::Lists=$DIR/lists"
     -o "Dir::Cache=$DIR/cache")
if [ ! -f "$DIR/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so" ]; then
  apt-get "${apt[@]}" update >&2
  (cd "$DIR/debs" && apt-get "${apt[@]}" download mesa-vulkan-drivers/bookworm-backports \
    libdrm2/bookworm-backports libdrm-amdgpu1/bookworm-backports >&2)
  for deb in "$DIR"/debs/*.deb; do dpkg -x "$deb" "$DIR/root"; done
fi
sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"$DIR/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so\"|" \
  "$DIR/root/usr/share/vulkan/icd.d/lvp_icd.json" >"$DIR/lvp_icd.json"
echo "export LD_LIBRARY_PATH=$DIR/root/usr/lib/x86_64-linux-gnu VK_DRIVER_FILES=$DIR/lvp_icd.json" \
  "VK_ICD_FILENAMES=$DIR/lvp_icd.json"
