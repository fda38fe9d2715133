#!/usr/bin/env bash
# Short targeted GPU checks used to chase a hang without losing the whole device call: each argument is
# one bench process, METHODS[:ENV=VALUE ...] (environment for that process only),
# on a 4 M-point tls cloud, all views and orders, with a short GPU timeout; a process that does not exit
# DIAG_KILL_S seconds after it starts is killed (a stalled GPU can hold the exit for minutes).
# Same setup as gpu-check.sh.
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-$PWD/gpu-out}; mkdir -p "$OUT"
if ! ldconfig -p | grep -q libvulkan.so.1; then for f in .vkrt/*.deb; do dpkg -x "$f" /; done; ldconfig; fi
for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json; do
  if [ -f "$icd" ]; then export VK_DRIVER_FILES=$icd; break; fi
done
dmesg 2>/dev/null | grep -i -E 'xid|nvrm' | tail -20 || true
pr=$PWD/.gpu/bin/pointrast
export XDG_RUNTIME_DIR=/tmp POINTRAST_VALIDATION=0 POINTRAST_GPU_TIMEOUT_S=${DIAG_TIMEOUT_S:-6}
n=0
for spec in "$@"; do
  n=$((n + 1))
  IFS=: read -r methods extra <<< "$spec"
  start=$(date +%s%N)
  env $extra timeout -s KILL "${DIAG_KILL_S:-30}" $pr bench tls --points 4M \
    --views "${DIAG_VIEWS:-all}" --methods "$methods" --orders "${DIAG_ORDERS:-all}" --frames 15 --out /tmp/diag --name "d$n" > "$OUT/diag-$n.log" 2>&1
  rc=$?
  stalled=$(grep -m1 'n/a' "$OUT/diag-$n.log" | sed 's/:.*//')
  printf '== %-2s %-50s rc=%s %6s ms, first n/a: %s\n' "$n" "$methods $extra" "$rc" \
    "$((($(date +%s%N) - start) / 1000000))" "${stalled:-none}"
done
dmesg 2>/dev/null | grep -i -E 'xid|nvrm' | tail -20 || true
# With DIAG_GPU_AV=1: the trigger sequence once more under the validation layer with GPU-assisted
# validation (out-of-bounds buffer-device-address accesses are reported).
if [ "${DIAG_GPU_AV:-0}" = 1 ] && ls .vkrt/layers/*.deb >/dev/null 2>&1; then
  rm -rf /tmp/vklayer && dpkg -x .vkrt/layers/*.deb /tmp/vklayer
  VK_LAYER_PATH=/tmp/vklayer/usr/share/vulkan/explicit_layer.d \
  LD_LIBRARY_PATH=/tmp/vklayer/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH} \
  POINTRAST_VALIDATION=1 VK_LAYER_ENABLES=VK_VALIDATION_FEATURE_ENABLE_GPU_ASSISTED_EXT \
    timeout -s KILL "${DIAG_KILL_S:-30}" $pr bench tls --points 4M --views all --orders all --frames 15 \
    --methods "${DIAG_GPU_AV_METHODS:-justset,hqs,hqs1r,dedup-ballot}" --out /tmp/diag --name gav > "$OUT/diag-gav.log" 2>&1
  echo "== GPU-AV: rc=$?"; tr '\r' '\n' < "$OUT/diag-gav.log" | grep -v '^\[' | head -30
  tr '\r' '\n' < "$OUT/diag-gav.log" | grep -m3 'n/a'
fi
