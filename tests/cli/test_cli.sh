#!/bin/sh
# The gdr program: good runs produce their files; bad arguments get a message and a non-zero exit.
# usage: test_cli.sh GDR_BINARY WORK_DIR
set -u
gdr=$1
work=$2
rm -rf "$work" && mkdir -p "$work"
failures=0

# expect STATUS DESCRIPTION -- COMMAND...: runs the command, checks its exit status and that a
# failing command said something on stderr.
expect() {
    want=$1; shift
    what=$1; shift
    "$@" >"$work/stdout" 2>"$work/stderr"
    got=$?
    if [ "$got" != "$want" ]; then
        echo "FAIL ($what): exit $got, expected $want: $*"; cat "$work/stderr"; failures=$((failures + 1))
    elif [ "$want" != 0 ] && [ ! -s "$work/stderr" ]; then
        echo "FAIL ($what): exit $got without a message: $*"; failures=$((failures + 1))
    fi
}

expect 0 help "$gdr" --help
expect 0 version "$gdr" --version
grep -q '^gdr [0-9]' "$work/stdout" || { echo "FAIL: --version printed $(cat "$work/stdout")"; failures=$((failures + 1)); }
expect 2 "no command" "$gdr"
expect 2 "unknown command" "$gdr" paint demo

small="--width 64 --height 48"
# shellcheck disable=SC2086
expect 0 "render with validation" "$gdr" render demo:instances=50 $small --out "$work/a.png" --stats "$work/a.json" --validate --frames 3
[ -s "$work/a.png" ] || { echo "FAIL: no PNG written"; failures=$((failures + 1)); }
for key in instances_total instances_visible triangles draws cpu_ms_per_frame gpu_ms device validation_messages; do
    grep -q "\"$key\"" "$work/a.json" || { echo "FAIL: stats JSON lacks $key"; failures=$((failures + 1)); }
done
grep -q '"validation_messages":[[:space:]]*0' "$work/a.json" || { echo "FAIL: validation messages"; failures=$((failures + 1)); }
# Every pipeline and view renders with validation on; the mesh pipeline reports its cluster counts.
for pipeline in mesh indirect cpu; do
    # shellcheck disable=SC2086
    expect 0 "pipeline $pipeline" "$gdr" render demo:instances=50 $small --pipeline $pipeline --validate --stats "$work/p.json"
    grep -q "\"pipeline\":[[:space:]]*\"$pipeline\"" "$work/p.json" || { echo "FAIL: stats do not name pipeline $pipeline"; failures=$((failures + 1)); }
done
for key in meshlets_total meshlets_frustum_culled meshlets_cone_culled meshlets_visible task_overflow; do
    # shellcheck disable=SC2086
    "$gdr" render demo:instances=50 $small --pipeline mesh --stats "$work/m.json" >/dev/null 2>&1
    grep -q "\"$key\"" "$work/m.json" || { echo "FAIL: mesh stats JSON lacks $key"; failures=$((failures + 1)); }
done
for view in shaded meshlets instances triangles overdraw lod; do
    # shellcheck disable=SC2086
    expect 0 "view $view" "$gdr" render demo:instances=50 $small --view $view --validate --out "$work/v.png"
done
# shellcheck disable=SC2086
expect 0 "single culling levels off" "$gdr" render demo:instances=50 $small --pipeline mesh --cone-cull off --triangle-cull off --meshlet-cull off --validate
# shellcheck disable=SC2086
{
expect 0 "lod error and depth" "$gdr" render demo:instances=50 $small --lod-error 4 --validate
grep -q '^lod_depths' "$work/stdout" || { echo "FAIL: render printed no lod_depths"; failures=$((failures + 1)); }
expect 0 "lod depth" "$gdr" render demo:instances=50 $small --lod-depth 2 --validate
expect 0 "occlusion on" "$gdr" render occlusion $small --occlusion on --frames 3 --validate
grep -q '^occlusion late' "$work/stdout" || { echo "FAIL: render printed no occlusion statistics"; failures=$((failures + 1)); }
expect 0 "occlusion off" "$gdr" render occlusion $small --occlusion off --pipeline indirect --validate
grep -q '^occlusion' "$work/stdout" && { echo "FAIL: occlusion statistics with occlusion off"; failures=$((failures + 1)); }
expect 0 "bench, lod and occlusion side by side" "$gdr" bench --scene demo:instances=30 --lod-errors 0,2 --occlusion on,off --frames 2 --width 64 --height 48 --validate
for raster in hw sw forward hybrid; do
    expect 0 "raster $raster" "$gdr" render demo:instances=50 $small --raster $raster --sw-threshold 4 --validate
done
grep -q '^raster_clusters' "$work/stdout" || { echo "FAIL: render printed no raster statistics"; failures=$((failures + 1)); }
expect 1 "raster sw needs the mesh pipeline" "$gdr" render demo:instances=50 $small --raster sw --pipeline indirect
expect 2 "raster unknown" "$gdr" render demo --raster soft
expect 2 "sw threshold zero" "$gdr" render demo --sw-threshold 0
expect 2 "lod error negative" "$gdr" render demo --lod-error -1
expect 2 "lod error not a number" "$gdr" render demo --lod-error 1px
expect 2 "lod depth too deep" "$gdr" render demo --lod-depth 65
expect 2 "occlusion maybe" "$gdr" render demo --occlusion maybe
expect 2 "view unknown" "$gdr" render demo --view depth
}
# shellcheck disable=SC2086
expect 0 "bench, three pipelines" "$gdr" bench --sizes 20 --pipelines cpu,indirect,mesh --frames 2 --width 64 --height 48 --validate

# shellcheck disable=SC2086
expect 0 "render with culling off and a camera" "$gdr" render demo:instances=50 $small --cull off --camera 0,3,10,0,0,0,1

# shellcheck disable=SC2086
{
expect 2 "no scene" "$gdr" render $small
expect 2 "two scenes" "$gdr" render demo demo
expect 2 "width 0" "$gdr" render demo $small --width 0
expect 2 "width not a number" "$gdr" render demo --width 12abc
expect 2 "height too large" "$gdr" render demo --height 99999
expect 2 "negative frames" "$gdr" render demo --frames -1
expect 2 "cull maybe" "$gdr" render demo --cull maybe
expect 2 "unknown pipeline" "$gdr" render demo --pipeline vertex
expect 2 "unknown view" "$gdr" render demo --view wireframe
expect 2 "cone cull maybe" "$gdr" render demo --cone-cull 1
expect 2 "bench unknown pipeline" "$gdr" bench --pipelines mesh,fast
expect 2 "short camera" "$gdr" render demo --camera 1,2,3
expect 2 "camera with NaN" "$gdr" render demo --camera 0,0,0,nan,0,0,1
expect 2 "zero quaternion" "$gdr" render demo --camera 0,0,0,0,0,0,0
expect 2 "missing value" "$gdr" render demo --width
expect 2 "unknown option" "$gdr" render demo --colour red
expect 2 "camera index out of range" "$gdr" render demo:instances=10 $small --camera-index 3
expect 2 "zero instances" "$gdr" render demo:instances=0 $small
expect 2 "unknown demo option" "$gdr" render demo:size=3 $small
expect 1 "missing scene file" "$gdr" render "$work/does-not-exist.gltf" $small
expect 2 "no such device" "$gdr" render demo:instances=10 $small --device 99
expect 2 "no such device name" "$gdr" render demo:instances=10 $small --device "no such gpu"
expect 1 "unwritable PNG" "$gdr" render demo:instances=10 $small --out "$work/missing-dir/a.png"
expect 2 "bench bad sizes" "$gdr" bench --sizes 10,abc
}
[ ! -e "$work/missing-dir" ] || { echo "FAIL: created a folder for the PNG"; failures=$((failures + 1)); }
ls "$work" | grep -q '\.tmp\.' && { echo "FAIL: temporary files left behind"; failures=$((failures + 1)); }

# shellcheck disable=SC2086
expect 0 "bench" "$gdr" bench --sizes 20,40 --frames 2 $small --json "$work/bench.json" --validate
grep -q '"instances_total"' "$work/bench.json" || { echo "FAIL: bench JSON"; failures=$((failures + 1)); }

# The built-in scenes for LOD and occlusion, rendered small; info and build
# accept them; bad options are errors.
tiny="--width 160 --height 90"
# shellcheck disable=SC2086
{
expect 0 "render lod-field" "$gdr" render lod-field:instances=30,triangles=3000 $tiny --validate --out "$work/lod-field.png"
[ -s "$work/lod-field.png" ] || { echo "FAIL: no lod-field PNG"; failures=$((failures + 1)); }
expect 0 "render occlusion" "$gdr" render occlusion $tiny --validate --out "$work/occlusion.png"
[ -s "$work/occlusion.png" ] || { echo "FAIL: no occlusion PNG"; failures=$((failures + 1)); }
expect 0 "render occlusion from behind the wall" "$gdr" render occlusion:hidden=300,visible=40,seed=2 $tiny --camera-index 1 --validate
expect 0 "info lod-field" "$gdr" info lod-field
grep -q '^instances: *1000$' "$work/stdout" || { echo "FAIL: info lod-field: $(cat "$work/stdout")"; failures=$((failures + 1)); }
grep -q '^lod nodes: *[1-9][0-9]* (hierarchies of up to [1-9][0-9]* levels)$' "$work/stdout" ||
    { echo "FAIL: info lod-field hierarchy: $(cat "$work/stdout")"; failures=$((failures + 1)); }
expect 0 "info occlusion" "$gdr" info occlusion:hidden=100,visible=10
grep -q '^cameras: *6$' "$work/stdout" || { echo "FAIL: info occlusion: $(cat "$work/stdout")"; failures=$((failures + 1)); }
expect 0 "build lod-field" "$gdr" build lod-field:instances=5,triangles=2000 -o "$work/field.gdrc" --no-progress
expect 0 "render the built lod-field" "$gdr" render "$work/field.gdrc" $tiny --validate
expect 2 "lod-field triangles too few" "$gdr" render lod-field:triangles=10 $tiny
expect 2 "lod-field spacing too small" "$gdr" info lod-field:spacing=1
expect 2 "occlusion unknown option" "$gdr" info occlusion:walls=3
grep -q 'seed, hidden, visible' "$work/stderr" || { echo "FAIL: occlusion option message: $(cat "$work/stderr")"; failures=$((failures + 1)); }
expect 2 "occlusion zero hidden" "$gdr" build occlusion:hidden=0 -o "$work/bad.gdrc"
expect 0 "render unique-field" "$gdr" render unique-field:meshes=4,triangles=2000 $tiny --validate
expect 0 "build unique-field with pages" "$gdr" build unique-field:meshes=3,triangles=2000 -o "$work/unique.gdrc" --pages=16 --no-progress
expect 0 "info of a paged cache" "$gdr" info "$work/unique.gdrc"
grep -q '^pages: *[1-9][0-9]* pages of [1-9][0-9]* groups, [0-9]* bytes, [0-9.]* bytes per source triangle' "$work/stdout" ||
    { echo "FAIL: info pages: $(cat "$work/stdout")"; failures=$((failures + 1)); }
grep -q '^cache: *[1-9][0-9]* bytes, [0-9.]* bytes per source triangle$' "$work/stdout" ||
    { echo "FAIL: info cache bytes: $(cat "$work/stdout")"; failures=$((failures + 1)); }
grep -q '^vertices: *3 of 3 meshes on a grid' "$work/stdout" ||
    { echo "FAIL: build --pages did not quantize: $(cat "$work/stdout")"; failures=$((failures + 1)); }
grep -q '^geometry: *in the pages alone' "$work/stdout" ||
    { echo "FAIL: info geometry of a paged cache: $(cat "$work/stdout")"; failures=$((failures + 1)); }
# The cache whose geometry is in its pages alone: refused whole, saying how to read it; with the whole
# geometry beside the pages (--whole-geometry) it renders whole too; streamed, the two give the same
# image, byte for byte, which is the whole render's.
expect 1 "a cache of pages alone rendered whole" "$gdr" render "$work/unique.gdrc" $tiny
grep -q 'pages alone.*--geometry-budget' "$work/stderr" || { echo "FAIL: pages alone whole: $(cat "$work/stderr")"; failures=$((failures + 1)); }
expect 2 "--whole-geometry without pages" "$gdr" build unique-field:meshes=1,triangles=1000 -o "$work/bad.gdrc" --whole-geometry
expect 0 "build with the whole geometry" "$gdr" build unique-field:meshes=3,triangles=2000 -o "$work/unique-whole.gdrc" \
    --pages=16 --whole-geometry --no-progress
expect 0 "info with the whole geometry" "$gdr" info "$work/unique-whole.gdrc"
grep -q '^geometry: *whole, and in the pages' "$work/stdout" || { echo "FAIL: info geometry: $(cat "$work/stdout")"; failures=$((failures + 1)); }
for layout in unique unique-whole; do
    expect 0 "stream $layout" "$gdr" render "$work/$layout.gdrc" $tiny --geometry-budget 1 --frames 12 --validate \
        --out "$work/$layout-streamed.png"
done
expect 0 "render with the whole geometry" "$gdr" render "$work/unique-whole.gdrc" $tiny --out "$work/unique-whole.png"
cmp -s "$work/unique-streamed.png" "$work/unique-whole-streamed.png" ||
    { echo "FAIL: the two layouts stream different images"; failures=$((failures + 1)); }
cmp -s "$work/unique-streamed.png" "$work/unique-whole.png" ||
    { echo "FAIL: the pages alone stream another image than the whole render"; failures=$((failures + 1)); }
expect 0 "info of a cache without pages" "$gdr" info "$work/field.gdrc"
grep -q '^pages: *none' "$work/stdout" || { echo "FAIL: info no pages: $(cat "$work/stdout")"; failures=$((failures + 1)); }
expect 2 "page size too small" "$gdr" build unique-field:meshes=1,triangles=1000 -o "$work/bad.gdrc" --pages=1
# Streaming: a paged cache renders within a budget and reports its pool; anything else is refused.
expect 0 "render streamed" "$gdr" render "$work/unique.gdrc" $tiny --geometry-budget 1 --upload-budget 1 --frames 4 --validate
grep -q '^streaming pool' "$work/stdout" || { echo "FAIL: streamed render printed no pool: $(cat "$work/stdout")"; failures=$((failures + 1)); }
# --settle: each pose of a path drawn until streaming settles, its row the settled frame (nothing asked
# for, copied or moved); without it the first pose's frame still asks for pages.
printf 'gdr-camera-path 1\n0 3.5 2 -0.174108 0 0 0.984727\n3 3.5 -6 -0.174108 0 0 0.984727\n' > "$work/settle.path"
for settle in "" "--settle 60"; do
    expect 0 "stream a path $settle" "$gdr" render "$work/unique.gdrc" $tiny --geometry-budget 1 --camera-path "$work/settle.path" \
        $settle --stats "$work/settle.json" --validate
    python3 - "$work/settle.json" "$settle" <<'PY' || failures=$((failures + 1))
import json, sys
rows = json.load(open(sys.argv[1]))["path"]
settled = [r["requests"] == 0 and r["uploads"] == 0 and r["evictions"] == 0 for r in rows]
if len(rows) != 2 or (sys.argv[2] != "") != all(settled):
    print(f"FAIL: --settle '{sys.argv[2]}': rows {rows}")
    sys.exit(1)
PY
done
# --warm-up: frames at the first pose before the rows, in none of them: the first pose's row then
# finds its pages there (nothing asked for, nothing copied; without it, it asks). Each row names where its
# frame went (every pass's GPU time, the renderer's CPU time, the pose's wall time).
expect 0 "stream a path after a warm-up" "$gdr" render "$work/unique.gdrc" $tiny --geometry-budget 1 \
    --camera-path "$work/settle.path" --warm-up 60 --stats "$work/warm.json" --validate
python3 - "$work/warm.json" <<'PY' || failures=$((failures + 1))
import json, sys
rows = json.load(open(sys.argv[1]))["path"]
quiet = [r["requests"] == 0 and r["uploads"] == 0 for r in rows]
timed = all(r["wall_ms"] > 0 and r["cpu_ms"] > 0 and abs(sum(r["gpu_ms_passes"].values()) - r["gpu_ms"]) < 1e-3
            for r in rows)
if len(rows) != 2 or not quiet[0] or not timed:
    print(f"FAIL: --warm-up 60: rows {rows}")
    sys.exit(1)
PY
expect 2 "--warm-up not a count" "$gdr" render "$work/unique.gdrc" $tiny --geometry-budget 1 --warm-up -3
expect 2 "--settle without a path" "$gdr" render "$work/unique.gdrc" $tiny --geometry-budget 1 --settle 5
expect 2 "--settle in the viewer" "$gdr" view "$work/unique.gdrc" $tiny --geometry-budget 1 --settle 5
expect 2 "--warm-up in the viewer" "$gdr" view "$work/unique.gdrc" $tiny --geometry-budget 1 --warm-up 5
# Streaming any scene: a built-in scene, a glTF and an OBJ without a prior gdr build get their paged
# cache built in the cache folder (once: a second run reads it), and a glTF streamed with room for
# everything converges to the image of that cache uploaded whole; --no-cache cannot stream a file.
expect 0 "stream a built-in scene" "$gdr" render unique-field:meshes=2,triangles=2000 $tiny --geometry-budget 1 \
    --cache-dir "$work/cache" --frames 8 --validate
ls "$work/cache"/unique-field*.pages.gdrc >/dev/null 2>&1 || { echo "FAIL: no paged cache of the built-in scene"; failures=$((failures + 1)); }
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
expect 0 "stream a glTF" "$gdr" render "$engine" $tiny --geometry-budget 64 --cache-dir "$work/cache" --frames 30 \
    --out "$work/engine-streamed.png" --stats "$work/engine.json" --validate
paged=$(ls "$work/cache"/2CylinderEngine.glb-*.pages.gdrc 2>/dev/null)
[ -n "$paged" ] || { echo "FAIL: no paged cache of the glTF"; failures=$((failures + 1)); }
for key in lod_error_px lod_error_scale wanted_pages settled_frames; do
    grep -q "\"$key\"" "$work/engine.json" || { echo "FAIL: streaming stats JSON lacks $key"; failures=$((failures + 1)); }
done
cp "$paged" "$work/paged-before.gdrc" 2>/dev/null
expect 0 "stream the glTF again" "$gdr" render "$engine" $tiny --geometry-budget 64 --cache-dir "$work/cache" --frames 30 \
    --out "$work/engine-again.png"
cmp -s "$paged" "$work/paged-before.gdrc" || { echo "FAIL: the paged cache was rebuilt"; failures=$((failures + 1)); }
expect 1 "the paged cache whole" "$gdr" render "$paged" $tiny --out "$work/engine-whole.png"
grep -q 'pages alone' "$work/stderr" || { echo "FAIL: paged cache whole: $(cat "$work/stderr")"; failures=$((failures + 1)); }
expect 0 "the glTF with its whole geometry and pages" "$gdr" build "$engine" -o "$work/engine-whole.gdrc" --pages \
    --whole-geometry --no-progress
expect 0 "that cache whole" "$gdr" render "$work/engine-whole.gdrc" $tiny --out "$work/engine-whole.png"
cmp -s "$work/engine-streamed.png" "$work/engine-whole.png" ||
    { echo "FAIL: the streamed glTF's image is not its cache's"; failures=$((failures + 1)); }
expect 0 "that cache streamed" "$gdr" render "$work/engine-whole.gdrc" $tiny --geometry-budget 64 --frames 30 \
    --out "$work/engine-whole-streamed.png"
cmp -s "$work/engine-streamed.png" "$work/engine-whole-streamed.png" ||
    { echo "FAIL: the two layouts of the glTF stream different images"; failures=$((failures + 1)); }
expect 0 "stream an OBJ" "$gdr" render /usr/share/assimp/models/OBJ/WusonOBJ.obj $tiny --geometry-budget 8 \
    --cache-dir "$work/cache" --frames 10 --validate
expect 1 "stream without a cache" "$gdr" render "$engine" $tiny --geometry-budget 8 --no-cache
grep -q 'no_cache' "$work/stderr" || { echo "FAIL: stream --no-cache: $(cat "$work/stderr")"; failures=$((failures + 1)); }
expect 1 "stream a cache without pages" "$gdr" render "$work/field.gdrc" $tiny --geometry-budget 1
grep -q 'has no geometry pages' "$work/stderr" || { echo "FAIL: stream without pages: $(cat "$work/stderr")"; failures=$((failures + 1)); }
expect 2 "unique-field no meshes" "$gdr" info unique-field:meshes=0
}
[ ! -e "$work/bad.gdrc" ] || { echo "FAIL: a failed build left a cache"; failures=$((failures + 1)); }

# Precomputed visibility in the cache: gdr build --pvs bakes it, gdr info reports it,
# a rebuild from the .gdrc keeps it, a damaged section is refused by name, a failed bake writes
# nothing.
printf 'g floor\nv -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf 1 3 2\nf 1 4 3\ng wall\nv -4 0 0\nv 4 0 0\nv 4 2 0\nv -4 2 0\nf 5 6 7\nf 5 7 8\n' >"$work/room.obj"
expect 0 "build --pvs" "$gdr" build "$work/room.obj" -o "$work/room.gdrc" --pvs --no-progress
grep -q '^pvs: .* baked' "$work/stdout" || { echo "FAIL: build --pvs printed no bake report"; failures=$((failures + 1)); }
expect 0 "info with a pvs" "$gdr" info "$work/room.gdrc"
grep -q '^pvs: *[1-9][0-9]* cells, 2 objects' "$work/stdout" || { echo "FAIL: info pvs: $(grep pvs "$work/stdout")"; failures=$((failures + 1)); }
expect 0 "rebuild keeps the pvs" "$gdr" build "$work/room.gdrc" -o "$work/room2.gdrc"
expect 0 "info of the rebuilt cache" "$gdr" info "$work/room2.gdrc"
grep -q '^pvs: *[1-9][0-9]* cells, 2 objects' "$work/stdout" || { echo "FAIL: rebuilt cache lost its pvs"; failures=$((failures + 1)); }
expect 0 "build without --pvs" "$gdr" build "$work/room.obj" -o "$work/plain.gdrc" --no-progress
expect 0 "info without a pvs" "$gdr" info "$work/plain.gdrc"
grep -q '^pvs: *none$' "$work/stdout" || { echo "FAIL: info of a cache without pvs: $(grep pvs "$work/stdout")"; failures=$((failures + 1)); }
size=$(wc -c <"$work/room.gdrc")
cp "$work/room.gdrc" "$work/damaged.gdrc"
printf '\252' | dd of="$work/damaged.gdrc" bs=1 seek=$((size - 40)) conv=notrunc 2>/dev/null
if cmp -s "$work/room.gdrc" "$work/damaged.gdrc"; then
    echo "FAIL: the damage did not change the file"; failures=$((failures + 1))
fi
expect 1 "damaged pvs section" "$gdr" info "$work/damaged.gdrc"
grep -q "section 'PVIS'" "$work/stderr" || { echo "FAIL: damaged pvs: $(cat "$work/stderr")"; failures=$((failures + 1)); }
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' >"$work/points.obj"
expect 1 "bake without triangles" "$gdr" build "$work/points.obj" -o "$work/points.gdrc" --pvs --no-progress
[ ! -e "$work/points.gdrc" ] || { echo "FAIL: a failed bake left a cache"; failures=$((failures + 1)); }

if [ "$failures" != 0 ]; then
    echo "test_cli: $failures failure(s)"
    exit 1
fi
echo "test_cli: all checks passed"
