#!/usr/bin/env bash
# A soak of the browser viewer's server: `serve_soak` keeps clients coming and going (viewers flying
# around, clients gone mid-frame, slow readers, malformed messages, idle sockets) against
#   1. `pointrast serve terrain` (a generated cloud), then
#   2. `pointrast serve` of an octree with a small --gpu-memory, so nodes stream all the time, where one
#      node's bytes are damaged: a page that meets it must be sent an error message while the server goes
#      on serving the others.
# Each phase takes half of SECONDS; each fails if the server died, its memory grew past the bound after the
# warm-up, descriptors leaked, or a well-behaved client was refused. Writes $OUT/serve-soak.{json,md}
# (both phases). The damaged node is the first DAMAGE_DEPTH levels down; at the viewers' 160x120 canvas,
# MIN_NODE_PX=30 leaves it out of the first view (a viewer meets it when it zooms towards it), 25 draws it
# from the first view on (the CI run, where it must be met).
#   POINTRAST_BIN=... SERVE_SOAK=... OUT=... [WORK=/tmp/soak] [VIEWERS=2] [RATE=30] [POINTS=200k] \
#     [DAMAGE_DEPTH=2] [MIN_NODE_PX=30] \
#     scripts/soak-serve.sh [SECONDS]
set -euo pipefail
seconds=${1:-120}
pr=${POINTRAST_BIN:?the pointrast binary}
soak=${SERVE_SOAK:?the serve_soak binary}
out=${OUT:?the result folder}
work=${WORK:-/tmp/soak-serve-$$}
viewers=${VIEWERS:-2}
rate=${RATE:-30}
points=${POINTS:-200k}
half=$((seconds / 2))
warmup=$((half / 5 > 5 ? half / 5 : 5))
mkdir -p "$out" "$work"

# The octree (Brotli nodes, so damaged bytes cannot pass for points) and a copy with one node damaged.
octree="$work/octree"
if [ ! -f "$octree/metadata.json" ]; then
  "$pr" generate terrain --points "$points" -o "$work/terrain.las" -q
  "$pr" lod "$work/terrain.las" -o "$octree" --encoding brotli --leaf-points 2k -q
  rm -f "$work/terrain.las"
fi
damaged="$work/octree-damaged"
rm -rf "$damaged"
cp -r "$octree" "$damaged"
node=$(python3 - "$damaged" "${DAMAGE_DEPTH:-2}" <<'EOF'
# Potree 2.0: hierarchy.bin holds 22-byte records (type u8, child mask u8, points u32, byte offset u64,
# byte size u64), breadth first from the root in the first chunk. The first node DAMAGE_DEPTH levels
# down (default 2) that holds points has its bytes in octree.bin overwritten.
import json, struct, sys
folder, depth = sys.argv[1], int(sys.argv[2])
meta = json.load(open(folder + "/metadata.json"))
hierarchy = open(folder + "/hierarchy.bin", "rb").read()[: meta["hierarchy"]["firstChunkSize"]]
depths = [0]
for i in range(len(hierarchy) // 22):
    kind, mask, points, offset, size = struct.unpack_from("<BBIqq", hierarchy, i * 22)
    depths += [depths[i] + 1] * bin(mask).count("1")
    if depths[i] == depth and kind != 2 and points > 0 and size > 16:
        with open(folder + "/octree.bin", "r+b") as f:
            f.seek(offset + 4)
            f.write(bytes((i * 37 + k * 101) & 0xFF for k in range(size - 8)))
        print(i)
        break
else:
    sys.exit(f"no node {depth} levels down to damage")
EOF
)
echo "soak-serve: node record $node of $damaged damaged"
bytes=$(du -sb "$octree/octree.bin" | cut -f1)
budget=$((bytes * 3 / 2)) # about 2/3 of what its points take on the GPU: nodes come and go

status=0
"$soak" --seconds "$half" --warmup "$warmup" --viewers "$viewers" --rate "$rate" \
  -o "$out/serve-soak-cloud.json" --markdown "$out/serve-soak-cloud.md" \
  -- "$pr" serve terrain --points "$points" || status=1
"$soak" --seconds "$half" --warmup "$warmup" --viewers "$viewers" --rate "$rate" \
  --expect-page-error "Brotli" \
  -o "$out/serve-soak-octree.json" --markdown "$out/serve-soak-octree.md" \
  -- "$pr" serve "$damaged" --gpu-memory "$budget" --min-node-px "${MIN_NODE_PX:-30}" || status=1

python3 - "$out" <<'EOF'
import json, sys
out = sys.argv[1]
phases = {name: json.load(open(f"{out}/serve-soak-{name}.json")) for name in ("cloud", "octree")}
json.dump({"pass": all(p["pass"] for p in phases.values()), "phases": phases}, open(f"{out}/serve-soak.json", "w"), indent=2)
with open(f"{out}/serve-soak.md", "w") as md:
    md.write("# serve soak\n\n")
    for name in ("cloud", "octree"):
        text = open(f"{out}/serve-soak-{name}.md").read().split("\n", 2)[2]
        md.write(f"## {'generated cloud' if name == 'cloud' else 'octree streamed, one node damaged'}\n\n{text}\n")
EOF
rm -f "$out/serve-soak-cloud.json" "$out/serve-soak-cloud.md" "$out/serve-soak-octree.json" "$out/serve-soak-octree.md"
[ -n "${WORK:-}" ] || rm -rf "$work"
echo "soak-serve: $([ $status = 0 ] && echo pass || echo FAIL), report in $out/serve-soak.md"
exit $status
