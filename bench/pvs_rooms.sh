#!/bin/sh
# Precomputed visibility on the rooms scene: bakes rooms[:rooms=N] with 1 m cells, then renders from
# each of its three cameras on every pipeline with --pvs off and on, and prints per run the
# instances drawn, those the PVS removed, triangles, GPU ms and CPU ms per frame (means over the
# frames) and the PVS lookup's CPU ms; the JSON of each run stays in OUT_DIR.
# usage: pvs_rooms.sh GDR_BINARY OUT_DIR [ROOMS] [FRAMES] [WIDTH HEIGHT]
set -eu
gdr=$1
out=$2
rooms=${3:-16}
frames=${4:-300}
width=${5:-1280}
height=${6:-720}
mkdir -p "$out"
"$gdr" build "rooms:rooms=$rooms" -o "$out/rooms.gdrc" --pvs-cell 1 --no-progress
printf '%-6s %-9s %-4s %9s %9s %8s %10s %9s %9s %9s\n' camera pipeline pvs instances drawn removed triangles gpu_ms cpu_ms pvs_ms
for camera in 0 1 2; do
    for pipeline in mesh indirect cpu; do
        for pvs in off on; do
            json="$out/$camera-$pipeline-$pvs.json"
            "$gdr" render "$out/rooms.gdrc" --camera-index "$camera" --pipeline "$pipeline" --pvs "$pvs" \
                --width "$width" --height "$height" --frames "$frames" --stats "$json" >/dev/null
            python3 - "$json" "$camera" "$pipeline" "$pvs" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print('%-6s %-9s %-4s %9d %9d %8d %10d %9.4f %9.4f %9.4f' % (sys.argv[2], sys.argv[3], sys.argv[4],
      d['instances_total'], d['instances_visible'], d['instances_pvs_culled'], d['triangles'],
      d['gpu_ms_per_frame'], d['cpu_ms_per_frame'], d['pvs_cpu_ms_per_frame']))
PY
        done
    done
done
