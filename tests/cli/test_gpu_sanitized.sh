#!/bin/sh
# The GPU paths under AddressSanitizer and UndefinedBehaviorSanitizer (the sanitizer build's gdr):
# every pipeline, rasteriser and view renders a few frames of small scenes with validation on, and a
# file scene goes through import, cache and render. Any sanitizer report fails (lavapipe's own leaks
# are not gdr's: leak detection is off).
# usage: test_gpu_sanitized.sh GDR_BINARY WORK_DIR
set -u
gdr=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
export ASAN_OPTIONS="detect_leaks=0:halt_on_error=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failures=0 runs=0

run() {
    runs=$((runs + 1))
    timeout 120 "$gdr" "$@" >"$work/stdout" 2>"$work/stderr"
    status=$?
    if [ $status -ne 0 ] || grep -Eq "runtime error|AddressSanitizer|UndefinedBehaviorSanitizer" "$work/stderr"; then
        echo "FAIL (exit $status): gdr $*"; grep -E -A12 "runtime error|Sanitizer|^gdr:" "$work/stderr" | head -30
        failures=$((failures + 1))
    fi
}

small="--width 64 --height 48 --frames 3 --validate"
# shellcheck disable=SC2086
for pipeline in mesh indirect cpu; do
    run render demo:instances=60 $small --pipeline $pipeline --out "$work/$pipeline.png" --stats "$work/$pipeline.json"
done
for raster in hybrid hw sw forward; do
    # shellcheck disable=SC2086
    run render lod-field:instances=4,triangles=2000 $small --raster $raster
done
for view in meshlets instances triangles overdraw lod; do
    # shellcheck disable=SC2086
    run render demo:instances=20 $small --view $view
done
# shellcheck disable=SC2086
run render occlusion:hidden=50,visible=20 $small --occlusion on
# shellcheck disable=SC2086
run render occlusion:hidden=50,visible=20 $small --occlusion off --cull off
# A file through import, the cache (written, then read) and the renderer.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n' > "$work/quad.obj"
# shellcheck disable=SC2086
run render "$work/quad.obj" $small
# shellcheck disable=SC2086
run render "$work/quad.obj" $small
run bench --sizes 20 --frames 2 --width 64 --height 48 --pipelines mesh,indirect,cpu

echo "test_gpu_sanitized: $runs runs, $failures failure(s)"
echo "$((runs - failures)) passed, $failures failed"
[ "$failures" = 0 ]
