#!/usr/bin/env bash
# A newer lavapipe (Mesa 25.0.7 from bookworm-backports, pinned below) that has VK_EXT_mesh_shader and
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
# Exact versions, so that the driver under test cannot change under us: a new backport is taken by editing
# these lines (versions from `apt-cache madison` with the private state above), never silently.
pinned=(
  mesa-vulkan-drivers=25.0.7-2~bpo12+1
  libdrm2=2.4.123-1~bpo12+1
  libdrm-amdgpu1=2.4.123-1~bpo12+1
)
if [ "$(cat "$DIR/pinned" 2>/dev/null)" != "${pinned[*]}" ]; then
  apt-get "${apt[@]}" update >&2
  for p in "${pinned[@]}"; do
    if ! apt-cache "${apt[@]}" madison "${p%%=*}" | awk -F' [|] ' '{print $2}' | grep -qxF "${p#*=}"; then
      echo "lavapipe-mesh-rt: pinned package ${p%%=*} ${p#*=} is no longer in bookworm-backports; update the pins in $0" >&2
      exit 1
    fi
  done
  rm -rf "$DIR/debs" "$DIR/root" "$DIR/pinned"
  mkdir -p "$DIR/debs" "$DIR/root"
  (cd "$DIR/debs" && apt-get "${apt[@]}" download "${pinned[@]}" >&2)
  for deb in "$DIR"/debs/*.deb; do dpkg -x "$deb" "$DIR/root"; done
  echo "${pinned[*]}" >"$DIR/pinned"
fi
sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"$DIR/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so\"|" \
  "$DIR/root/usr/share/vulkan/icd.d/lvp_icd.json" >"$DIR/lvp_icd.json"
echo "export LD_LIBRARY_PATH=$DIR/root/usr/lib/x86_64-linux-gnu VK_DRIVER_FILES=$DIR/lvp_icd.json" \
  "VK_ICD_FILENAMES=$DIR/lvp_icd.json"
