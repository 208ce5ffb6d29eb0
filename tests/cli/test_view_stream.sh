#!/bin/sh
# gdr view --geometry-budget under Xvfb on lavapipe, validation on: a built-in scene streams without a
# prior gdr build, along a camera path with a jump (near, then far across the field looking back,
# then near again), and its last image is gdr render's of the same path; the keys work on a streamed
# scene (the pipeline key says the mesh pipeline is the only one, the LOD keys stay above 0, J jumps
# the camera to the start and back); a pool below what the view needs settles at a raised threshold,
# which the exit's statistics report.
# usage: test_view_stream.sh GDR_BINARY X11_CLOSE_WINDOW_BINARY WORK_DIR
set -u
gdr=$1
close_window=$2
work=$3
rm -rf "$work" && mkdir -p "$work/shots" "$work/cache"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

for tool in Xvfb xdotool; do
    command -v $tool >/dev/null || { echo "FAIL: $tool is missing (scripts/install-deps.sh installs it)"; exit 1; }
done
Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb=$!
trap 'kill $xvfb 2>/dev/null' EXIT
for _ in $(seq 50); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "FAIL: Xvfb did not start"; cat "$work/xvfb.log"; exit 1; }
DISPLAY=:$(cat "$work/display")
export DISPLAY
wait_file() {
    for _ in $(seq 150); do [ -s "$1" ] && return 0; sleep 0.1; done
    return 1
}

scene=unique-field:meshes=6,triangles=20000,seed=5
size="--width 160 --height 96"
stream="--geometry-budget 16 --cache-dir $work/cache"

# 1. A path with a jump: 25 frames near the front row, 25 from the far side looking back, 25 near
# again. The pool holds everything, so the last frame converges to the full cut: the same image as
# gdr render's of the same path.
{
    echo "gdr-camera-path 1"
    for _ in $(seq 25); do echo "-1.5 1.5 3 0 0 0 1"; done
    for _ in $(seq 25); do echo "0 3 -30 0 1 0 0"; done
    for _ in $(seq 25); do echo "-1.5 1.5 3 0 0 0 1"; done
} >"$work/jump.txt"
# shellcheck disable=SC2086
"$gdr" view $scene $size $stream --camera-path "$work/jump.txt" --frames 75 --overlay off \
    --screenshot "$work/view.png" --validate >"$work/view.out" 2>&1 || { fail "view along the path exited $?"; cat "$work/view.out"; }
ls "$work/cache"/unique-field*.pages.gdrc >/dev/null 2>&1 || fail "no paged cache built for the viewer"
grep -q '^streaming cut' "$work/view.out" || fail "the viewer printed no streaming figures: $(cat "$work/view.out")"
# shellcheck disable=SC2086
"$gdr" render $scene $size $stream --camera-path "$work/jump.txt" --out "$work/render.png" --stats "$work/path.json" \
    >/dev/null 2>&1 || fail "render along the path exited $?"
# The statistics hold a row per frame of the path (GPU time, threshold, pages, uploads, evictions).
[ "$(grep -c '"lod_error_px":' "$work/path.json")" = 76 ] || fail "render --camera-path --stats: not a row per frame"
cmp -s "$work/view.png" "$work/render.png" || fail "the viewer's last streamed image differs from gdr render's"
# The overlay, with its streaming lines, is drawn.
# shellcheck disable=SC2086
"$gdr" view $scene $size $stream --camera-path "$work/jump.txt" --frames 75 --screenshot "$work/overlay.png" \
    --validate >/dev/null 2>&1 || fail "view with the overlay exited $?"
cmp -s "$work/overlay.png" "$work/view.png" && fail "the overlay was not drawn"

# 2. A pool below the near view's pages: the viewer settles with the threshold raised.
# shellcheck disable=SC2086
"$gdr" view $scene $size --geometry-budget 2 --lod-error 0.1 --cache-dir "$work/cache" --camera-path "$work/jump.txt" \
    --frames 75 \
    --overlay off --validate >"$work/small.out" 2>&1 || { fail "view with a small pool exited $?"; cat "$work/small.out"; }
grep -q '^streaming cut .*x [1-9][0-9.]* to fit the pool' "$work/small.out" || fail "no threshold: $(cat "$work/small.out")"
grep -q '^streaming cut .*x 1 to fit' "$work/small.out" && fail "the small pool did not raise the threshold"

# 3. The keys on a streamed scene, interactively.
# shellcheck disable=SC2086
"$gdr" view $scene $size $stream --overlay off --validate --max-fps 30 --screenshot-dir "$work/shots" \
    >"$work/interactive.out" 2>&1 &
viewer=$!
window=$(timeout 20 xdotool search --sync --name "gdr view" | head -1)
[ -n "$window" ] || fail "no window appeared"
shot=0
screenshot() {
    xdotool key --window "$window" F12
    file="$work/shots/gdr-view-$(printf %04d $shot).png"
    shot=$((shot + 1))
    wait_file "$file" || fail "no screenshot $file"
    sleep 0.2
}
sleep 3
screenshot                                          # 0000: the start, converged
xdotool keydown --window "$window" s; sleep 0.5; xdotool keyup --window "$window" s
sleep 1.5
screenshot                                          # 0001: moved back
xdotool key --window "$window" j; sleep 1.5
screenshot                                          # 0002: J: the start again
xdotool key --window "$window" j; sleep 1.5
screenshot                                          # 0003: J: where S left it
cmp -s "$work/shots/gdr-view-0000.png" "$work/shots/gdr-view-0001.png" && fail "S did not move the streamed view"
cmp -s "$work/shots/gdr-view-0000.png" "$work/shots/gdr-view-0002.png" || fail "J did not jump to the start"
cmp -s "$work/shots/gdr-view-0001.png" "$work/shots/gdr-view-0003.png" || fail "J did not jump back"
for key in p r o c f v bracketleft bracketleft bracketleft bracketleft bracketright h Tab y; do
    xdotool key --window "$window" $key; sleep 0.2
done
screenshot
"$close_window" "$window" || fail "could not send the close request"
wait $viewer
status=$?
[ "$status" = 0 ] || { fail "closing the window: exit $status"; cat "$work/interactive.out"; }
grep -q "^gdr view: " "$work/interactive.out" && fail "a key's setting was refused: $(cat "$work/interactive.out")"
grep -q "validation" "$work/interactive.out" && { fail "validation messages"; cat "$work/interactive.out"; }

[ "$failures" = 0 ] && echo "test_view_stream: all passed"
exit $((failures > 0))
