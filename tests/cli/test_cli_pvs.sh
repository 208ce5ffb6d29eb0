#!/bin/sh
# Precomputed visibility through the program: gdr build --pvs bakes the rooms scene's cache, and
# gdr render culls with it on every pipeline: the same image bytes with --pvs on and off from the
# scene's first camera, instances removed only with it on, the statistics printed and in the JSON,
# and the switch's errors.
# usage: test_cli_pvs.sh GDR_BINARY WORK_DIR
set -u
gdr=$1
work=$2
rm -rf "$work" && mkdir -p "$work"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect STATUS DESCRIPTION COMMAND...: the exit status, and a message on stderr for a failure.
expect() {
    want=$1; shift
    what=$1; shift
    "$@" >"$work/stdout" 2>"$work/stderr"
    got=$?
    if [ "$got" != "$want" ]; then
        fail "($what): exit $got, expected $want: $*"; cat "$work/stderr"
    elif [ "$want" != 0 ] && [ ! -s "$work/stderr" ]; then
        fail "($what): exit $got without a message: $*"
    fi
}

# A JSON number or string value of the last --stats file.
value() { sed -n "s/^[[:space:]]*\"$1\":[[:space:]]*\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2"; }

scene="rooms:rooms=4,objects=6"
expect 0 "build with a pvs" "$gdr" build "$scene" -o "$work/rooms.gdrc" --pvs-cell 1 --pvs-samples 1 --no-progress
grep -q '^pvs: ' "$work/stdout" || fail "gdr build printed no bake report"
expect 0 "build without a pvs" "$gdr" build "$scene" -o "$work/plain.gdrc" --no-progress

small="--width 96 --height 64 --validate"
for pipeline in mesh indirect cpu; do
    for pvs in on off; do
        # shellcheck disable=SC2086
        expect 0 "render $pipeline pvs $pvs" "$gdr" render "$work/rooms.gdrc" $small --pipeline "$pipeline" --pvs "$pvs" \
            --out "$work/$pipeline-$pvs.png" --stats "$work/$pipeline-$pvs.json"
        cp "$work/stdout" "$work/$pipeline-$pvs.txt"
    done
    cmp -s "$work/$pipeline-on.png" "$work/$pipeline-off.png" || fail "$pipeline: the image differs with the pvs on"
    [ "$(value pvs "$work/$pipeline-on.json")" = on ] || fail "$pipeline: pvs not on in the statistics"
    [ "$(value pvs "$work/$pipeline-off.json")" = off ] || fail "$pipeline: pvs not off in the statistics"
    [ "$(value pvs_cell_found "$work/$pipeline-on.json")" = true ] || fail "$pipeline: the camera in no cell"
    culled=$(value instances_pvs_culled "$work/$pipeline-on.json")
    [ "${culled:-0}" -gt 0 ] || fail "$pipeline: the pvs removed nothing"
    [ "$(value instances_pvs_culled "$work/$pipeline-off.json")" = 0 ] || fail "$pipeline: removed with the pvs off"
    on=$(value instances_visible "$work/$pipeline-on.json")
    off=$(value instances_visible "$work/$pipeline-off.json")
    [ $((on + culled)) -le "$off" ] || fail "$pipeline: $on drawn + $culled culled exceeds $off drawn without the pvs"
    grep -q "^pvs  *on: camera in a baked cell (of [0-9]*), $culled instances culled" "$work/$pipeline-on.txt" ||
        fail "$pipeline: the printout lacks the pvs line"
    echo "$pipeline: $off instances drawn without the pvs, $on with it ($culled removed), the same image"
done
# gdr bench culls with the cache's PVS too (on, as gdr render by default): its row draws what
# gdr render --pvs on draws from the same camera, fewer than with the PVS off.
expect 0 "bench of the cache" "$gdr" bench --scene "$work/rooms.gdrc" --pipelines mesh --frames 2 \
    --width 96 --height 64 --validate --json "$work/bench.json"
bench_drawn=$(sed -n 's/^[[:space:]]*"instances_visible":[[:space:]]*\([0-9]*\),\{0,1\}$/\1/p' "$work/bench.json" | head -n 1)
[ "$bench_drawn" = "$(value instances_visible "$work/mesh-on.json")" ] ||
    fail "bench drew ${bench_drawn:-?} instances, gdr render with the pvs $(value instances_visible "$work/mesh-on.json")"
# A streamed render reads the cache's PVS too (gdr build keeps it when it adds pages): the same
# image with it on and off once the pages are in, instances removed only with it on.
expect 0 "pages added to the cache" "$gdr" build "$work/rooms.gdrc" -o "$work/paged.gdrc" --pages --no-progress
for pvs in on off; do
    # shellcheck disable=SC2086
    expect 0 "streamed render, pvs $pvs" "$gdr" render "$work/paged.gdrc" $small --geometry-budget 64 --frames 30 \
        --pvs "$pvs" --out "$work/streamed-$pvs.png" --stats "$work/streamed-$pvs.json"
done
cmp -s "$work/streamed-on.png" "$work/streamed-off.png" || fail "streamed: the image differs with the pvs on"
[ "$(value instances_pvs_culled "$work/streamed-on.json")" -gt 0 ] 2>/dev/null || fail "streamed: the pvs removed nothing"
# By default the pvs is on when the cache has one, none otherwise.
# shellcheck disable=SC2086
expect 0 "render, pvs by default" "$gdr" render "$work/rooms.gdrc" $small --pipeline indirect --stats "$work/default.json"
[ "$(value pvs "$work/default.json")" = on ] || fail "the pvs is not on by default"
# shellcheck disable=SC2086
expect 0 "render, a cache without a pvs" "$gdr" render "$work/plain.gdrc" $small --stats "$work/plain.json"
[ "$(value pvs "$work/plain.json")" = none ] || fail "a cache without a pvs does not say none"
# shellcheck disable=SC2086
expect 0 "render, culling off" "$gdr" render "$work/rooms.gdrc" $small --cull off --stats "$work/cull-off.json"
[ "$(value pvs "$work/cull-off.json")" = off ] || fail "culling off leaves the pvs on"

expect 2 "pvs on without one" "$gdr" render "$work/plain.gdrc" --pvs on
grep -q "holds no precomputed visibility" "$work/stderr" || fail "pvs on without one: $(cat "$work/stderr")"
expect 2 "pvs on for a built-in scene" "$gdr" render "$scene" --pvs on
expect 2 "pvs maybe" "$gdr" render "$work/rooms.gdrc" --pvs maybe
expect 2 "pvs cell zero" "$gdr" build "$scene" -o "$work/bad.gdrc" --pvs-cell 0
expect 2 "pvs samples too many" "$gdr" build "$scene" -o "$work/bad.gdrc" --pvs-samples 5000
[ ! -e "$work/bad.gdrc" ] || fail "a refused build wrote a file"
expect 2 "rooms option out of range" "$gdr" build rooms:rooms=0 -o "$work/bad.gdrc"

if [ "$failures" != 0 ]; then
    echo "test_cli_pvs: $failures failure(s)"
    exit 1
fi
echo "test_cli_pvs: all checks passed"
