#!/usr/bin/env bash
# The cost of filters on the GPU: the overview of the generated terrain (POINTS, default 1G, Morton order)
# with batch-prefetch at 2560x1140, one process per row: no filter; a clip box over the western half
# (x up to the overview's target); that box with a class filter (ground only); the class filter alone; the
# box with --clip-mode outside; no filter again. Writes filter-cost.jsonl and filter-cost.md to OUT.
#   scripts/bench-filter-cost.sh POINTRAST OUT [POINTS]
set -euo pipefail
pr="$1" out="$2" points="${3:-1G}"
mkdir -p "$out"
common=(render terrain --points "$points" --order morton --method batch-prefetch --width 2560 --height 1140
        --frames 30 --json -q -o /tmp/filter-cost.png)
rm -f "$out/filter-cost.jsonl"
run() { # label, extra options...
  local label="$1"
  shift
  echo "== $label"
  "$pr" "${common[@]}" "$@" | python3 -c '
import json, sys
j = json.loads(sys.stdin.read().splitlines()[-1])
j["row"] = sys.argv[1]
print(json.dumps(j))' "$label" | tee -a "$out/filter-cost.jsonl" | cut -c 1-200
}
run "no filter"
# The overview's target: the box covers the cloud west of it.
tx=$(python3 -c 'import json,sys; j=json.loads(open(sys.argv[1]).readline()); print(j["camera"].split("--target ")[1].split(",")[0])' "$out/filter-cost.jsonl")
box="0,0,-100000,$tx,100000000,100000"
run "--clip-box over the western half" --clip-box "$box"
run "the box and --classes 2 (ground)" --clip-box "$box" --classes 2
run "--classes 2 alone" --classes 2
run "the box with --clip-mode outside" --clip-box "$box" --clip-mode outside
run "no filter, again"
python3 - "$out" "$points" <<'PY'
import json, sys
out, points = sys.argv[1], sys.argv[2]
rows = [json.loads(l) for l in open(out + "/filter-cost.jsonl")]
with open(out + "/filter-cost.md", "w") as f:
    f.write("# Filters on the GPU: cost on the %s overview\n\n" % points)
    f.write("Device %s; `pointrast render terrain --points %s --order morton --method batch-prefetch --width 2560 "
            "--height 1140 --frames 30`, one process per row, in this order. The box covers the cloud west of the "
            "overview's target (about half); `--classes 2` keeps the ground (the generated terrain's classes: "
            "2 ground, 5 high vegetation, 6 building). Class filters drop points when the cloud is loaded; the "
            "clip box is tested on the GPU, where batches wholly outside are skipped.\n\n" % (rows[0]["device"], points))
    f.write("| run | points loaded | batches skipped by the clip | points drawn | median ms | min | max |\n"
            "| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n")
    for r in rows:
        b = r.get("batch_stats", {})
        f.write("| %s | %s | %s | %s | %.3f | %.3f | %.3f |\n" % (
            r["row"], format(r["points"], ","), format(b.get("batches_clipped", 0), ","),
            format(b.get("points_rendered", 0), ","), r["median_ms"], r["min_ms"], r["max_ms"]))
PY
cat "$out/filter-cost.md"
