#!/bin/sh
# File cameras: a camera keeps its vertical field of view and takes the image's aspect (glTF's rule
# when aspectRatio differs from the viewport's: no stretching); the assimp corpus's Cameras.gltf
# (a square seen by a perspective camera of aspectRatio 1.0) rendered at 16:9 must equal the same
# file without aspectRatio, whose camera takes the viewport's aspect by definition.
# usage: test_cli_cameras.sh GDR_BINARY ASSIMP_GLTF2_DIR WORK_DIR
set -u
gdr=$1
models=$2
work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

cp "$models/cameras/Cameras.gltf" "$models/cameras/simpleSquare.bin" "$work/"
sed '/"aspectRatio"/d' "$work/Cameras.gltf" >"$work/NoAspect.gltf"
grep -q aspectRatio "$work/NoAspect.gltf" && fail "the copy without aspectRatio still has it"

for size in "160 90" "90 160" "120 120"; do
    set -- $size
    for file in Cameras NoAspect; do
        "$gdr" render "$work/$file.gltf" --no-cache --camera-index 0 --width "$1" --height "$2" \
            --out "$work/$file.png" >"$work/out" 2>&1 || { fail "$file at $1x$2: $(cat "$work/out")"; }
    done
    cmp -s "$work/Cameras.png" "$work/NoAspect.png" ||
        fail "at $1x$2 the camera of aspectRatio 1.0 gives another image than the viewport's aspect"
done

echo "test_cli_cameras: $failures failure(s)"
[ "$failures" = 0 ]
