#!/bin/sh
# Regenerates the cache fuzz target's seeds (corpus/cache) with the current format: a flag byte 1
# (recompute checksums) and then the cache. Run it whenever the cache format version changes.
# usage: tests/fuzz/make_cache_seeds.sh GDR_BINARY
set -eu
gdr=$1
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seed() { # NAME: the flag byte, then WORK/NAME.gdrc
    { printf '\001'; cat "$work/$1.gdrc"; } >"$here/corpus/cache/$1.gdrc"
}
# A second build from the first cache drops the source paths (the seeds must not name this machine).
# Built from inside their folders: the warnings the caches keep name the files, not this machine's paths.
gdr=$(cd "$(dirname "$gdr")" && pwd)/$(basename "$gdr")
cd "$here/corpus/gltf" && "$gdr" build nodes.gltf -o "$work/a.gdrc" --no-progress >/dev/null 2>&1
"$gdr" build "$work/a.gdrc" -o "$work/nodes.gdrc" --no-progress >/dev/null 2>&1
cd "$here/corpus/obj" && "$gdr" build quad.obj -o "$work/b.gdrc" --no-progress >/dev/null 2>&1
"$gdr" build "$work/b.gdrc" -o "$work/quad.gdrc" --no-progress >/dev/null 2>&1
"$gdr" build tri.obj -o "$work/c.gdrc" --pvs --no-progress >/dev/null
"$gdr" build "$work/c.gdrc" -o "$work/pvs.gdrc" --no-progress >/dev/null
"$gdr" build unique-field:meshes=2,triangles=1000 -o "$work/paged.gdrc" --pages=4 --no-progress >/dev/null
# A smaller one with the whole geometry beside its pages (the one above has its pages alone: read
# for streaming only); under the fuzzer's 64 KiB inputs.
"$gdr" build unique-field:meshes=1,triangles=1000 -o "$work/paged-whole.gdrc" --pages=4 --whole-geometry \
    --no-progress >/dev/null
# A cache that keeps its import's warnings (section 'REPT'): an OBJ statement gdr ignores.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nbevel on\n' >"$work/warned.obj"
cd "$work" && "$gdr" build warned.obj -o "$work/d.gdrc" --no-progress >/dev/null 2>&1
"$gdr" build "$work/d.gdrc" -o "$work/warned.gdrc" --no-progress >/dev/null 2>&1
# Block-compressed textures (BC1 with partial blocks and levels below 4 x 4: 211 x 211).
models=/usr/share/assimp/models/glTF2/BoxTextured-glTF
cp "$models/BoxTextured.gltf" "$models/BoxTextured0.bin" "$models/CesiumLogoFlat.png" "$work/"
"$gdr" build "$work/BoxTextured.gltf" -o "$work/d.gdrc" --no-progress >/dev/null
"$gdr" build "$work/d.gdrc" -o "$work/textured.gdrc" --no-progress >/dev/null
for name in nodes quad pvs paged paged-whole warned textured; do seed $name; done
ls -l "$here/corpus/cache"
