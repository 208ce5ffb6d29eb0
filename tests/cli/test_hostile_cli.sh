#!/bin/sh
# The gdr program with hostile files and output paths (docs/SECURITY.md): refusals with a message
# and the documented exit status; --out/--stats/-o onto links, devices and FIFOs.
# usage: test_hostile_cli.sh GDR_BINARY WORK_DIR
set -u
gdr=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
work=$2
rm -rf "$work" && mkdir -p "$work/scene" "$work/outside"
failures=0

# expect STATUS DESCRIPTION PATTERN -- COMMAND...: the exit status, and PATTERN (grep -E) in stderr.
expect() {
    want=$1 what=$2 pattern=$3
    shift 3
    timeout 20 "$@" >"$work/stdout" 2>"$work/stderr"
    got=$?
    if [ "$got" != "$want" ]; then
        echo "FAIL ($what): exit $got, expected $want: $*"; cat "$work/stderr"; failures=$((failures + 1))
    elif [ -n "$pattern" ] && ! grep -Eq "$pattern" "$work/stderr"; then
        echo "FAIL ($what): stderr lacks /$pattern/: $*"; cat "$work/stderr"; failures=$((failures + 1))
    fi
}
check() { # check DESCRIPTION CONDITION...
    what=$1; shift
    "$@" || { echo "FAIL ($what)"; failures=$((failures + 1)); }
}

tiny="--width 32 --height 24"
# Output targets: links followed, devices written in place, never replaced.
# What /dev/stdout is, as a link of the test's own (a regression must not replace /dev/stdout).
ln -s /proc/self/fd/1 "$work/stdout-link"
# shellcheck disable=SC2086
expect 0 "stats to stdout" "" "$gdr" render demo:instances=4 $tiny --stats "$work/stdout-link"
check "stats JSON on stdout" grep -q '"instances_total"' "$work/stdout"
check "the stdout link is still a link" test -L "$work/stdout-link"
echo old > "$work/target.json" && ln -s target.json "$work/link.json"
# shellcheck disable=SC2086
expect 0 "stats to a symlink" "" "$gdr" render demo:instances=4 $tiny --stats "$work/link.json"
check "the link is still a link" test -L "$work/link.json"
check "its target holds the statistics" grep -q '"instances_total"' "$work/target.json"
# Devices of the test's own (root can make them), so that a regression cannot replace /dev/null.
if mknod "$work/null" c 1 3 2>/dev/null && mknod "$work/full" c 1 7 2>/dev/null; then
    # shellcheck disable=SC2086
    expect 0 "image to a null device" "" "$gdr" render demo:instances=4 $tiny --out "$work/null"
    check "the null device is still a device" test -c "$work/null"
    # shellcheck disable=SC2086
    expect 1 "stats to a full device" "cannot write" "$gdr" render demo:instances=4 $tiny --stats "$work/full"
    check "the full device is still a device" test -c "$work/full"
fi
mkfifo "$work/fifo"
expect 1 "cache to a FIFO without a reader" "no reader" "$gdr" build demo:instances=4 -o "$work/fifo"
check "the FIFO is still a FIFO" test -p "$work/fifo"
ln -s built.gdrc "$work/cache-link.gdrc"
expect 0 "cache through a symlink" "" "$gdr" build demo:instances=4 -o "$work/cache-link.gdrc"
check "the cache link is still a link" test -L "$work/cache-link.gdrc"
expect 0 "the cache it wrote reads back" "" "$gdr" info "$work/built.gdrc"

# Usage errors: exit 2 with a message.
expect 2 "empty pipeline list" "no pipeline named" "$gdr" bench --pipelines ,
expect 2 "a built-in scene's option out of range" "instances=0" "$gdr" info demo:instances=0
expect 2 "budget of zero" "positive integer" "$gdr" info demo --budget triangles=0
expect 2 "unknown budget" "KEY=N" "$gdr" info demo --budget widgets=3

# Hostile files: exit 1 with a message naming the file and the place.
printf 'v 0x1p127 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n' > "$work/huge.obj"
expect 1 "huge coordinate" "huge.obj:1: v: .* limit on coordinates" "$gdr" info "$work/huge.obj" --no-cache
{
    printf '{"asset":{"version":"2.0"},"extras":'
    i=0; while [ $i -lt 1100 ]; do printf '['; i=$((i + 1)); done
} > "$work/deep.gltf"
expect 1 "deep JSON" "nested deeper than 1000" "$gdr" info "$work/deep.gltf" --no-cache
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n' > "$work/two.obj"
expect 1 "triangle budget" "budget of 1.*--budget triangles=N" "$gdr" info "$work/two.obj" --no-cache --budget triangles=1
expect 0 "triangle budget raised" "" "$gdr" info "$work/two.obj" --no-cache --budget triangles=2

# A buffer outside the scene's folder: refused unless --allow-outside-files.
printf 'AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA' | base64 -d > "$work/outside/secret.bin"
printf '{"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"../outside/secret.bin"}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}' > "$work/scene/escape.gltf"
expect 1 "URI outside the folder" "leaves the scene's folder.*--allow-outside-files" "$gdr" info "$work/scene/escape.gltf"
check "no cache written for the refused scene" test ! -e "$work/scene/escape.gltf.gdrc"
expect 0 "URI outside the folder, allowed" "" "$gdr" info "$work/scene/escape.gltf" --allow-outside-files --no-cache
check "one mesh" grep -q '^meshes: *1 ' "$work/stdout"

# Results files travel between machines: their strings reach gnuplot only as data. A pipeline name
# and pass names written as gnuplot code must neither run (no file made) nor stop the plot.
cat > "$work/evil.json" <<'EOF'
[{"pipeline":"mesh'.system('touch PWNED-pipeline').'","lod_error_px":1,"instances_total":10,
  "gpu_ms":{"cull'.system('touch PWNED-pass').'":0.5,"raster\"\n!touch PWNED-newline\n":0.25}},
 {"pipeline":"mesh'.system('touch PWNED-pipeline').'","lod_error_px":1,"instances_total":100,
  "gpu_ms":{"cull'.system('touch PWNED-pass').'":0.75,"raster\"\n!touch PWNED-newline\n":0.5}}]
EOF
cd "$work" || exit 1 # where gnuplot's system() would make its files
expect 0 "plot of a results file with code in its strings" "" \
    "$gdr" bench --plot-from "$work/evil.json" --plot "$work/evil.svg"
cd "$OLDPWD" || exit 1
check "no command ran from the results file" sh -c "! ls '$work' | grep -q PWNED"
check "the plot was drawn with the titles as text" grep -q 'system' "$work/evil.svg"

# A damaged page index: streaming refuses the cache as gdr info does, for a byte flipped in each of
# the index's first fields.
expect 0 "a paged cache" "" "$gdr" build demo:instances=4 -o "$work/paged.gdrc" --pages
# The PAGE section's offset, from the section table (32-byte entries after the 64-byte header).
sections=$(od -An -t u4 -j 16 -N 4 "$work/paged.gdrc" | tr -d ' ')
page_offset=""
i=0
while [ "$i" -lt "${sections:-0}" ]; do
    # shellcheck disable=SC2046
    set -- $(od -An -t u4 -j $((64 + 32 * i)) -N 12 "$work/paged.gdrc")
    [ "$1" = 1162297680 ] && page_offset=$3 # 'PAGE' as a little-endian u32; the offset's low half
    i=$((i + 1))
done
check "the paged cache has a PAGE section" test -n "$page_offset"
for at in 0 4 8 12 20 36; do
    cp "$work/paged.gdrc" "$work/mutant.gdrc"
    printf '\377' | dd of="$work/mutant.gdrc" bs=1 seek=$((${page_offset:-0} + 32 + at)) conv=notrunc 2>/dev/null
    # shellcheck disable=SC2086
    expect 1 "page index byte $at flipped, streamed" "mutant.gdrc.*PAGE" \
        "$gdr" render "$work/mutant.gdrc" --geometry-budget 8 $tiny --out "$work/mutant.png"
    check "no image for the damaged cache (index byte $at)" test ! -e "$work/mutant.png"
done
# The cache holds its geometry in its pages alone: rendered whole, rebuilt from or cut short, it is
# refused by name (exit 1), never read past its end, no image written.
# shellcheck disable=SC2086
expect 1 "pages alone rendered whole" "paged.gdrc: its geometry is in its pages alone" \
    "$gdr" render "$work/paged.gdrc" $tiny --out "$work/mutant.png"
expect 1 "pages alone rebuilt from" "paged.gdrc: its geometry is in its pages alone" \
    "$gdr" build "$work/paged.gdrc" -o "$work/rebuilt.gdrc"
check "nothing rebuilt from the pages alone" test ! -e "$work/rebuilt.gdrc"
size=$(wc -c <"$work/paged.gdrc")
for cut in 40 $((size / 2)) $((size - 1)); do
    head -c "$cut" "$work/paged.gdrc" >"$work/mutant.gdrc"
    # shellcheck disable=SC2086
    expect 1 "pages alone cut to $cut bytes, streamed" "mutant.gdrc: truncated" \
        "$gdr" render "$work/mutant.gdrc" --geometry-budget 8 $tiny --out "$work/mutant.png"
    expect 1 "pages alone cut to $cut bytes, info" "mutant.gdrc: truncated" "$gdr" info "$work/mutant.gdrc"
done
check "no image for a cut cache" test ! -e "$work/mutant.png"

# FIFOs as the program's own inputs: refused at once, never waited on (expect's timeout fails a hang).
mkfifo "$work/path.fifo"
# shellcheck disable=SC2086
expect 1 "camera path is a FIFO (render)" "path.fifo: not a regular file" \
    "$gdr" render demo:instances=4 $tiny --camera-path "$work/path.fifo"
# shellcheck disable=SC2086
expect 1 "camera path is a FIFO (bench)" "path.fifo: not a regular file" \
    "$gdr" bench --scene demo:instances=4 $tiny --frames 1 --camera-path "$work/path.fifo"
expect 1 "results file is a FIFO" "path.fifo: not a regular file" \
    "$gdr" bench --plot-from "$work/path.fifo" --plot "$work/fifo.svg"
# A bad camera path is reported before the scene is loaded (here a scene that does not exist).
printf 'gdr-camera-path 1\n0 0 0 0 0 0\n' > "$work/short.path"
# shellcheck disable=SC2086
expect 1 "camera path checked before the scene" "short.path:2: expected 7 numbers .*found 6" \
    "$gdr" render "$work/missing.obj" $tiny --camera-path "$work/short.path"
# Camera path messages that say what is wrong; a value too small for a float is a number like any.
printf 'gdr-camera-path 1\n0 0 5 0 0 0\0001\n' > "$work/nul.path"
# shellcheck disable=SC2086
expect 1 "a NUL byte in a camera path" "nul.path:2: a NUL byte at column 12" \
    "$gdr" render demo:instances=4 $tiny --camera-path "$work/nul.path"
printf 'gdr-camera-path 1\n0 0 5 0 0 1e39 1\n' > "$work/big.path"
# shellcheck disable=SC2086
expect 1 "a number beyond a float in a camera path" "big.path:2: number 6: '1e39' is not finite as a 32-bit float" \
    "$gdr" render demo:instances=4 $tiny --camera-path "$work/big.path"
printf 'gdr-camera-path 1\n0 0 5 0 0 1e-45 1\n' > "$work/tiny.path"
# shellcheck disable=SC2086
expect 0 "a denormal in a camera path" "" "$gdr" render demo:instances=4 $tiny --camera-path "$work/tiny.path"

# Command-line values: an unknown option is called so (not "needs a value"), a device the machine
# lacks is a bad value (exit 2, before the scene is loaded), an upload budget or a target size the
# device cannot back is refused with its numbers (not a raw vkCreateBuffer failure or a driver crash).
expect 2 "unknown render option" "unknown option '--bogus-option'" "$gdr" render demo --bogus-option
expect 2 "unknown bench option" "unknown option '--bogus-option'" "$gdr" bench --bogus-option
# shellcheck disable=SC2086
expect 2 "a device that does not exist" "device 99: there are" \
    "$gdr" render "$work/missing.obj" $tiny --device 99
# shellcheck disable=SC2086
expect 1 "an upload budget over the device's buffers" "upload budget of 4096 MiB needs 2 staging buffers" \
    "$gdr" render "$work/paged.gdrc" --geometry-budget 8 --upload-budget 4096 $tiny
# A CPU device's memory is the process's: under a 4 GiB address-space limit, a 16384^2 target (about
# 7.5 GiB) is refused before it is made.
expect 2 "a target larger than the device can back" "render size 16384x16384 needs about [0-9]+ MiB" \
    sh -c "ulimit -v 4194304 && exec '$gdr' render demo:instances=4 --width 16384 --height 16384 --out '$work/big.png'"
check "no image for the refused target" test ! -e "$work/big.png"

# A node scale of 3e38: every pipeline refuses the scene the same way, naming the file (the CPU
# pipeline said "cull view: a matrix has a NaN or infinity", the others drew nothing and exited 0).
printf '{"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0,"scale":[3e38,3e38,3e38]}],"scenes":[{"nodes":[0]}]}' > "$work/scaled.gltf"
for pipeline in cpu mesh indirect; do
    # shellcheck disable=SC2086
    expect 1 "a scene beyond the limit on coordinates ($pipeline)" "scaled.gltf: nodes\[0\].*limit on coordinates" \
        "$gdr" render "$work/scaled.gltf" --no-cache $tiny --pipeline $pipeline --out "$work/scaled.png"
done
check "no image for the scene beyond the limit" test ! -e "$work/scaled.png"

echo "test_hostile_cli: $failures failure(s)"
[ "$failures" = 0 ]
