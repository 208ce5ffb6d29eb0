#!/bin/sh
# gdr view under Xvfb on lavapipe, validation on: the presented image equals gdr render's, keys sent
# with xdotool change the view mode and freeze culling, resizing and unmapping while rendering, a
# window manager's close request exits 0, a recorded path replays to the same image, and without a
# display or a presenting driver gdr view fails with a message while gdr render works.
# usage: test_view.sh GDR_BINARY X11_CLOSE_WINDOW_BINARY VIEW_DEMO_BINARY WORK_DIR
set -u
gdr=$1
close_window=$2
view_demo=$3
work=$4
rm -rf "$work" && mkdir -p "$work/shots"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

for tool in Xvfb xdotool; do
    command -v $tool >/dev/null || { echo "FAIL: $tool is missing (scripts/install-deps.sh installs it)"; exit 1; }
done

# A display of our own: Xvfb picks a free number and writes it to fd 3.
Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb=$!
trap 'kill $xvfb 2>/dev/null' EXIT
for _ in $(seq 50); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "FAIL: Xvfb did not start"; cat "$work/xvfb.log"; exit 1; }
DISPLAY=:$(cat "$work/display")
export DISPLAY

scene=demo:instances=300
size="--width 160 --height 96"
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{print $3*256+$4 "x" $7*256+$8}'; }
# wait_file FILE: up to 15 s for FILE to appear.
wait_file() {
    for _ in $(seq 150); do [ -s "$1" ] && return 0; sleep 0.1; done
    return 1
}

# 1. N frames presented, the screenshot (the swapchain image as shown) equals gdr render's PNG.
# shellcheck disable=SC2086
"$gdr" view $scene $size --frames 4 --overlay off --screenshot "$work/view.png" --validate >"$work/out" 2>&1 ||
    { fail "view --frames exited $?"; cat "$work/out"; }
# shellcheck disable=SC2086
"$gdr" render $scene $size --out "$work/render.png" --validate >/dev/null 2>&1 || fail "render exited $?"
cmp -s "$work/view.png" "$work/render.png" || fail "the viewer's screenshot differs from gdr render's image"
# The overlay is drawn on the presented image.
# shellcheck disable=SC2086
"$gdr" view $scene $size --frames 2 --screenshot "$work/overlay.png" --validate >/dev/null 2>&1 || fail "overlay run"
cmp -s "$work/overlay.png" "$work/render.png" && fail "the overlay was not drawn"

# examples/view_demo.c, the embedding frame loop, presents frames and exits 0.
"$view_demo" 5 >"$work/out" 2>&1 || { fail "view_demo exited $?"; cat "$work/out"; }

# 2. Interactive: keys, resizing, unmapping, a close request.
# shellcheck disable=SC2086
# (Xvfb does not pace presents: --max-fps keeps the recorded path, replayed below, short.)
"$gdr" view $scene $size --overlay off --validate --max-fps 30 --screenshot-dir "$work/shots" --record-path "$work/path.txt" \
    --screenshot "$work/last.png" >"$work/interactive.out" 2>&1 &
viewer=$!
window=$(timeout 20 xdotool search --sync --name "gdr view" | head -1)
[ -n "$window" ] || fail "no window appeared"
shot=0
# screenshot: F12, then the next numbered file.
screenshot() {
    xdotool key --window "$window" F12
    file="$work/shots/gdr-view-$(printf %04d $shot).png"
    shot=$((shot + 1))
    wait_file "$file" || fail "no screenshot $file"
    sleep 0.2
}
sleep 0.3
screenshot
cmp -s "$work/shots/gdr-view-0000.png" "$work/render.png" || fail "first interactive frame differs from gdr render"
xdotool key --window "$window" v
screenshot
# shellcheck disable=SC2086
"$gdr" render $scene $size --view meshlets --out "$work/meshlets.png" >/dev/null 2>&1 || fail "render --view meshlets"
cmp -s "$work/shots/gdr-view-0001.png" "$work/meshlets.png" || fail "key v did not switch to the meshlets view"
# Freeze culling, fly backwards (S held), look: then the same place with culling following again.
xdotool key --window "$window" f
xdotool keydown --window "$window" s
sleep 0.5
xdotool keyup --window "$window" s
screenshot
xdotool key --window "$window" f
screenshot
cmp -s "$work/shots/gdr-view-0002.png" "$work/shots/gdr-view-0003.png" &&
    fail "frozen culling drew the same image as culling from the moved camera"
cmp -s "$work/shots/gdr-view-0002.png" "$work/shots/gdr-view-0001.png" && fail "S did not move the camera"
# The camera stays where S left it. Pipeline (P: mesh -> indirect -> cpu -> mesh), LOD threshold
# (]: 1 -> 2 -> 4 px) and culling (C: off), each screenshot checked after the exit against gdr
# render with the matching options from the path's last pose.
xdotool key --window "$window" p
screenshot
xdotool key --window "$window" p
screenshot
xdotool key --window "$window" p bracketright bracketright
screenshot
xdotool key --window "$window" c
screenshot
# Resized, unmapped and mapped again, minimised, tiny: frames go on.
xdotool windowsize "$window" 200 120
sleep 0.3
screenshot
[ "$(png_size "$work/shots/gdr-view-0008.png")" = 200x120 ] ||
    fail "after resizing, the screenshot is $(png_size "$work/shots/gdr-view-0008.png"), expected 200x120"
xdotool windowunmap "$window"; sleep 0.2; xdotool windowmap "$window"; sleep 0.2
# Without a window manager nobody gives the mapped window its keyboard focus back.
xdotool windowfocus "$window"
xdotool windowminimize "$window"; sleep 0.2
xdotool windowsize "$window" 1 1; sleep 0.2
xdotool windowsize "$window" 160 96; sleep 0.3
screenshot
"$close_window" "$window" || fail "could not send the close request"
wait $viewer
status=$?
[ "$status" = 0 ] || { fail "closing the window: exit $status"; cat "$work/interactive.out"; }
grep -q "validation" "$work/interactive.out" && { fail "validation messages"; cat "$work/interactive.out"; }

# The keys' screenshots against gdr render from the last pose (the camera did not move after S).
{ head -n 1 "$work/path.txt"; tail -n 1 "$work/path.txt"; } >"$work/last_pose.txt"
# key_matches SHOT DESCRIPTION RENDER_OPTIONS...
key_matches() {
    shot_file="$work/shots/gdr-view-$1.png"; what=$2; shift 2
    # shellcheck disable=SC2086
    "$gdr" render $scene $size --view meshlets --camera-path "$work/last_pose.txt" --out "$work/key.png" "$@" \
        >/dev/null 2>&1 || fail "render $* exited $?"
    cmp -s "$shot_file" "$work/key.png" || fail "$what: the screenshot differs from gdr render $*"
}
key_matches 0003 "F again (culling follows)"
key_matches 0004 "P (indirect)" --pipeline indirect
key_matches 0005 "P (cpu)" --pipeline cpu
key_matches 0006 "P, ] ]" --pipeline mesh --lod-error 4
key_matches 0007 "C" --pipeline mesh --lod-error 4 --cull off
cmp -s "$work/shots/gdr-view-0006.png" "$work/shots/gdr-view-0003.png" && fail "] did not change the LOD cut"

# 3. The recorded path replayed by gdr render gives the viewer's last image (the settings of the
# keys above).
# shellcheck disable=SC2086
"$gdr" render $scene $size --view meshlets --lod-error 4 --cull off --camera-path "$work/path.txt" \
    --out "$work/replay.png" --validate >/dev/null 2>&1 || fail "render --camera-path exited $?"
cmp -s "$work/replay.png" "$work/last.png" || fail "the replayed path's last image differs from the viewer's"
[ "$(grep -c '^[-0-9]' "$work/path.txt")" -gt 10 ] || fail "the recorded path has too few frames"
printf 'gdr-camera-path 1\n0 1 2 0 0 0 1\n0 1 nan 0 0 0 1\n' >"$work/bad.txt"
"$gdr" render $scene $size --camera-path "$work/bad.txt" >/dev/null 2>"$work/err" && fail "a bad path was accepted"
grep -q 'bad.txt:3' "$work/err" || fail "the bad path's message does not name its line: $(cat "$work/err")"

# gdr bench along the path (every 40th pose): a row per pose, and a plot of GPU ms per pass.
{ head -n 2 "$work/path.txt"; grep '^[-0-9]' "$work/path.txt" | awk 'NR % 40 == 1'; } >"$work/short.txt"
poses=$(grep -c '^[-0-9]' "$work/short.txt")
"$gdr" bench --scene $scene --width 64 --height 48 --camera-path "$work/short.txt" --json "$work/bench.json" \
    --plot "$work/bench.svg" --validate >/dev/null 2>"$work/err" || { fail "bench --camera-path --plot"; cat "$work/err"; }
[ "$(grep -c '"frame":' "$work/bench.json")" = "$poses" ] || fail "bench --camera-path: not one row per pose ($poses)"
grep -q '<svg' "$work/bench.svg" && grep -q 'cull' "$work/bench.svg" || fail "bench --plot wrote no plot of the passes"
"$gdr" bench --plot-from "$work/bench.json" --plot "$work/again.svg" >/dev/null 2>&1 || fail "bench --plot-from"
grep -q 'cull' "$work/again.svg" || fail "bench --plot-from wrote no plot of the passes"
"$gdr" bench --plot-from "$work/path.txt" --plot "$work/bad.svg" >/dev/null 2>&1 && fail "--plot-from took a non-JSON file"

# Bad usage: status 2 and a message, before any window opens.
for args in "" "demo --out x.png" "demo --max-fps 0" "demo --overlay maybe" "demo --record-path"; do
    # shellcheck disable=SC2086
    "$gdr" view $args >/dev/null 2>"$work/err"
    status=$?
    [ "$status" = 2 ] && [ -s "$work/err" ] || fail "gdr view $args: exit $status, expected 2 with a message"
done

# A cache's precomputed visibility: the viewer culls with it as gdr render does (the same first
# frame), and --pvs on for a scene without one is refused before a window opens.
"$gdr" build "rooms:rooms=4,objects=6" -o "$work/rooms.gdrc" --pvs-cell 1 --pvs-samples 1 --no-progress >/dev/null ||
    fail "build of the rooms scene with a pvs"
# shellcheck disable=SC2086
"$gdr" view "$work/rooms.gdrc" $size --pvs on --frames 2 --overlay off --screenshot "$work/rooms-view.png" \
    --validate >/dev/null 2>"$work/err" || { fail "view with the cache's pvs"; cat "$work/err"; }
# shellcheck disable=SC2086
"$gdr" render "$work/rooms.gdrc" $size --pvs on --out "$work/rooms-render.png" >/dev/null 2>&1 ||
    fail "render with the cache's pvs"
cmp -s "$work/rooms-view.png" "$work/rooms-render.png" || fail "view with the pvs drew another image than render"
"$gdr" view demo:instances=4 --pvs on --frames 1 >/dev/null 2>"$work/err"
status=$?
[ "$status" = 2 ] && grep -q 'holds no precomputed visibility' "$work/err" ||
    fail "view --pvs on without a pvs: exit $status, expected 2 with a message"

# 4. No display, no presenting driver: a message and a non-zero exit; gdr render is unaffected.
env -u DISPLAY -u WAYLAND_DISPLAY "$gdr" view $scene --frames 1 >/dev/null 2>"$work/err" && fail "view without a display"
[ -s "$work/err" ] || fail "view without a display said nothing"
VK_ICD_FILENAMES=/nonexistent.json "$gdr" view $scene --frames 1 >/dev/null 2>"$work/err" &&
    fail "view without a Vulkan driver"
[ -s "$work/err" ] || fail "view without a Vulkan driver said nothing"
# shellcheck disable=SC2086
env -u DISPLAY "$gdr" render $scene $size --out "$work/headless.png" >/dev/null 2>&1 || fail "render without a display"
cmp -s "$work/headless.png" "$work/render.png" || fail "render without a display drew another image"

[ "$failures" = 0 ] && echo "test_view: all passed"
exit $((failures > 0))
