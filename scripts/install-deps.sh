#!/usr/bin/env bash
# Installs the Debian 12 packages pointrast needs to build, test and run on software Vulkan (lavapipe).
# Idempotent: skips apt when everything is already there. Uses sudo when not run as root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-dev glslc spirv-tools mesa-vulkan-drivers vulkan-validationlayers
  libglm-dev libcli11-dev nlohmann-json3-dev libstb-dev libgtest-dev libzstd-dev
  libbrotli-dev
  # the desktop viewer (GLFW is loaded at run time, the panel is Dear ImGui), its tests on a virtual X
  # server driven by xdotool, and video output of camera paths
  libglfw3-dev libimgui-dev libx11-dev xvfb xauth xdotool ffmpeg
  # the browser viewer (civetweb is loaded at run time, TurboJPEG linked statically) and its tests in a
  # headless chromium
  libcivetweb-dev libturbojpeg0-dev chromium
  clang libclang-rt-dev llvm # libFuzzer targets (scripts/fuzz.sh): the fuzzer runtime and llvm-symbolizer
  # the Python module (python/, for Debian's python3) and its tests; pip installs it from the checkout
  python3-dev pybind11-dev python3-numpy python3-pytest python3-setuptools python3-wheel python3-venv python3-pip
  libopenmpi-dev openmpi-bin # distributed rendering under mpirun (docs/mpi.md) and its tests
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
