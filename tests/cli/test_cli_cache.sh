#!/bin/sh
# The scene cache from the command line (docs/CACHE_FORMAT.md): it never hides a change of the files
# an import looked for, it says the import's warnings on every run (--strict: exit 4), it lives in
# the per-user cache folder unless told otherwise, and that folder keeps within its size limit.
# usage: test_cli_cache.sh GDR_BINARY WORK_DIR
set -u
gdr=$1
work=$2
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd)
failures=0
XDG_CACHE_HOME=$work/xdg
export XDG_CACHE_HOME
corpus=/usr/share/assimp/models/glTF2
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect STATUS DESCRIPTION COMMAND...: the exit status, and a message on stderr when it fails.
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

small="--width 96 --height 64 --validate"
# same_as_uncached DIR WHAT [OPTIONS]: the cached render of DIR's box equals a --no-cache render of
# the same files, and it warns exactly as the import does.
same_as_uncached() {
    # shellcheck disable=SC2086
    expect 0 "$2: cached render" "$gdr" render "$1/BoxTextured.gltf" $small ${3:-} --out "$work/cached.png"
    grep 'warning' "$work/stderr" >"$work/cached.warnings"
    # shellcheck disable=SC2086
    expect 0 "$2: uncached render" "$gdr" render "$1/BoxTextured.gltf" $small --no-cache --out "$work/plain.png"
    grep 'warning' "$work/stderr" >"$work/plain.warnings"
    cmp -s "$work/cached.png" "$work/plain.png" || fail "$2: the cached render differs from the --no-cache one"
    cmp -s "$work/cached.warnings" "$work/plain.warnings" ||
        fail "$2: warnings differ: cached '$(cat "$work/cached.warnings")', plain '$(cat "$work/plain.warnings")'"
}

# A texture missing, then added, removed and changed: each render is that of the files as they are.
cp -r "$corpus/BoxTextured-glTF" "$work/box"
logo=$work/box/CesiumLogoFlat.png
cp "$logo" "$work/logo.png"
rm "$logo"
same_as_uncached "$work/box" "texture missing"
grep -q 'texture left out' "$work/cached.warnings" || fail "no warning for the missing texture"
same_as_uncached "$work/box" "texture still missing (from the cache)"
grep -q 'texture left out' "$work/cached.warnings" || fail "the cached run did not repeat the warning"
cp "$work/cached.png" "$work/without.png"
cp "$work/logo.png" "$logo"
same_as_uncached "$work/box" "texture added"
cmp -s "$work/cached.png" "$work/without.png" && fail "texture added: the image did not change"
[ -s "$work/cached.warnings" ] && fail "texture added: still warned: $(cat "$work/cached.warnings")"
rm "$logo"
same_as_uncached "$work/box" "texture removed"
cp "$corpus/ClearCoat-glTF/PartialCoating.png" "$logo"
same_as_uncached "$work/box" "texture changed"
cp "$corpus/ClearCoat-glTF/RibsNormal.png" "$logo"
same_as_uncached "$work/box" "texture changed again"

# The cache is in $XDG_CACHE_HOME/gdr (mode 0700), and gdr info says where.
ls "$XDG_CACHE_HOME/gdr/"BoxTextured.gltf-*.gdrc >/dev/null 2>&1 || fail "no cache in \$XDG_CACHE_HOME/gdr"
[ "$(stat -c %a "$XDG_CACHE_HOME/gdr")" = 700 ] || fail "cache folder mode $(stat -c %a "$XDG_CACHE_HOME/gdr")"
[ -e "$work/box/BoxTextured.gltf.gdrc" ] && fail "a cache was written next to the asset"
expect 0 "info says where" "$gdr" info "$work/box/BoxTextured.gltf"
grep -q "^cached in: *$XDG_CACHE_HOME/gdr/BoxTextured.gltf-[0-9a-f]*\.gdrc (read)$" "$work/stdout" ||
    fail "info: $(grep cached "$work/stdout")"
# Without XDG_CACHE_HOME: ~/.cache/gdr; --cache-dir DIR and '.' (next to the source) on request.
mkdir -p "$work/home"
env -u XDG_CACHE_HOME HOME="$work/home" "$gdr" info "$work/box/BoxTextured.gltf" >"$work/stdout" 2>&1 ||
    fail "info with HOME only: $(cat "$work/stdout")"
ls "$work/home/.cache/gdr/"BoxTextured.gltf-*.gdrc >/dev/null 2>&1 || fail "no cache in \$HOME/.cache/gdr"
expect 0 "--cache-dir" "$gdr" info "$work/box/BoxTextured.gltf" --cache-dir "$work/mine"
ls "$work/mine/"BoxTextured.gltf-*.gdrc >/dev/null 2>&1 || fail "no cache in --cache-dir"
expect 0 "--cache-dir ." "$gdr" info "$work/box/BoxTextured.gltf" --cache-dir .
[ -s "$work/box/BoxTextured.gltf.gdrc" ] || fail "--cache-dir . wrote no cache next to the source"
grep -q "^cached in: *$work/box/BoxTextured.gltf.gdrc (written)$" "$work/stdout" || fail "info: $(grep cached "$work/stdout")"
expect 0 "--no-cache" "$gdr" info "$work/box/BoxTextured.gltf" --no-cache
grep -q "^cached in: *none (--no-cache)$" "$work/stdout" || fail "info --no-cache: $(grep cached "$work/stdout")"

# A folder copied with its .gdrc (next to the source), then changed there: checked against the
# files beside its new place.
cp "$work/logo.png" "$logo"
rm -f "$logo"
same_as_uncached "$work/box" "next to the source, texture missing" "--cache-dir ."
cp -r "$work/box" "$work/copy"
[ -s "$work/copy/BoxTextured.gltf.gdrc" ] || fail "the copy has no cache"
same_as_uncached "$work/copy" "copied, unchanged" "--cache-dir ."
cp "$work/logo.png" "$work/copy/CesiumLogoFlat.png"
same_as_uncached "$work/copy" "copied, texture added" "--cache-dir ."
cp "$corpus/ClearCoat-glTF/PartialCoating.png" "$work/copy/CesiumLogoFlat.png"
same_as_uncached "$work/copy" "copied, texture changed" "--cache-dir ."

# --strict: every warning (the cached run's too) is an error with exit status 4; a clean file passes.
expect 4 "render --strict" "$gdr" render "$work/box/BoxTextured.gltf" $small --strict --out "$work/strict.png"
grep -q 'gdr: error: .*texture left out' "$work/stderr" || fail "render --strict: $(cat "$work/stderr")"
[ -e "$work/strict.png" ] && fail "render --strict wrote an image"
expect 4 "render --strict, uncached" "$gdr" render "$work/box/BoxTextured.gltf" $small --strict --no-cache
expect 4 "info --strict" "$gdr" info "$work/box/BoxTextured.gltf" --strict
# (the viewer refuses before it opens a window, so no display is needed)
expect 4 "view --strict" env -u DISPLAY -u WAYLAND_DISPLAY "$gdr" view "$work/box/BoxTextured.gltf" --strict --frames 1
expect 4 "build --strict" "$gdr" build "$work/box/BoxTextured.gltf" -o "$work/strict.gdrc" --strict
[ -e "$work/strict.gdrc" ] && fail "build --strict wrote a cache"
expect 0 "render --strict, clean" "$gdr" render "$work/copy/BoxTextured.gltf" $small --strict
expect 0 "info --strict, clean" "$gdr" info "$work/copy/BoxTextured.gltf" --strict
# gdr build keeps the warnings in the cache it writes: rendering that file says them again.
expect 0 "build with a warning" "$gdr" build "$work/box/BoxTextured.gltf" -o "$work/built.gdrc"
expect 4 "render the built cache --strict" "$gdr" render "$work/built.gdrc" $small --strict
grep -q 'texture left out' "$work/stderr" || fail "the built cache did not keep the warning"
expect 0 "build with pages" "$gdr" build "$work/box/BoxTextured.gltf" -o "$work/paged.gdrc" --pages
expect 4 "render streamed --strict" "$gdr" render "$work/paged.gdrc" $small --geometry-budget 16 --strict
grep -q 'texture left out' "$work/stderr" || fail "the streamed read did not say the kept warning"

# --camera-index counts every camera the file places (here one perspective, one orthographic).
expect 2 "camera index beyond" "$gdr" render "$corpus/cameras/Cameras.gltf" $small --camera-index 2
grep -q 'has 2 camera(s)' "$work/stderr" || fail "camera count: $(cat "$work/stderr")"

# The size limit: least recently used caches go first, the newest stays, others' files stay.
# Each cache must be a good part of the 1 MiB limit: the box's texture is replaced by a 1024 x 1024
# image (gdr's own render), about 0.7 MB of BC1 blocks with its mips.
mkdir -p "$work/limit"
expect 0 "a large texture" "$gdr" render "$work/copy/BoxTextured.gltf" --width 1024 --height 1024 \
    --no-cache --out "$work/large.png"
for i in 1 2 3 4 5 6; do
    cp -r "$work/copy" "$work/limit/box$i"
    rm -f "$work/limit/box$i/BoxTextured.gltf.gdrc"
    cp "$work/large.png" "$work/limit/box$i/CesiumLogoFlat.png"
done
mkdir -p "$work/lru" && echo "my notes" >"$work/lru/notes.gdrc"
for i in 1 2 3 4 5 6; do
    expect 0 "fill $i" "$gdr" info "$work/limit/box$i/BoxTextured.gltf" --cache-dir "$work/lru" --cache-max 1
    sleep 0.05
done
count=$(ls "$work/lru/"*-*.gdrc | wc -l)
size=$(cat "$work/lru/"*-*.gdrc | wc -c)
[ "$size" -le 1048576 ] || fail "the folder's caches hold $size bytes, over the 1 MiB limit"
[ "$count" -ge 1 ] && [ "$count" -lt 6 ] || fail "$count caches after the limit"
expect 0 "newest kept" "$gdr" info "$work/limit/box6/BoxTextured.gltf" --cache-dir "$work/lru" --cache-max 1
grep -q '(read)$' "$work/stdout" || fail "the newest cache was evicted"
expect 0 "oldest evicted" "$gdr" info "$work/limit/box1/BoxTextured.gltf" --cache-dir "$work/lru" --cache-max 1
grep -q '(written)$' "$work/stdout" || fail "the oldest cache was kept"
[ -s "$work/lru/notes.gdrc" ] || fail "eviction removed a file gdr did not write"
# GDR_CACHE_MAX_MIB sets the limit too.
GDR_CACHE_MAX_MIB=1 "$gdr" info "$work/limit/box2/BoxTextured.gltf" --cache-dir "$work/lru" >/dev/null 2>&1
size=$(cat "$work/lru/"*-*.gdrc | wc -c)
[ "$size" -le 1048576 ] || fail "GDR_CACHE_MAX_MIB: $size bytes"

# gdr cache list and clear: only the caches gdr wrote (the one left: box2's, the last written).
expect 0 "cache list" "$gdr" cache list --cache-dir "$work/lru"
grep -q "box2/BoxTextured.gltf)$" "$work/stdout" || fail "cache list: $(cat "$work/stdout")"
grep -q notes "$work/stdout" && fail "cache list shows a file gdr did not write"
expect 0 "cache clear" "$gdr" cache clear --cache-dir "$work/lru"
ls "$work/lru/"*-*.gdrc >/dev/null 2>&1 && fail "cache clear left caches"
[ -s "$work/lru/notes.gdrc" ] || fail "cache clear removed a file gdr did not write"
expect 2 "cache without an action" "$gdr" cache

# Concurrent gdr processes on the same sources and folder, with eviction: every one succeeds and
# what is left reads back.
pids=""
for i in 1 2 3 4 5 6 7 8; do
    n=$(( (i % 3) + 1 ))
    ( "$gdr" info "$work/limit/box$n/BoxTextured.gltf" --cache-dir "$work/race" --cache-max 1 >"$work/race$i.out" 2>&1
      echo $? >"$work/race$i.rc" ) &
    pids="$pids $!"
done
# shellcheck disable=SC2086
wait $pids
for i in 1 2 3 4 5 6 7 8; do
    [ "$(cat "$work/race$i.rc")" = 0 ] || fail "concurrent run $i: $(cat "$work/race$i.out")"
    grep -q 'warning' "$work/race$i.out" && fail "concurrent run $i warned: $(cat "$work/race$i.out")"
done
for n in 1 2 3; do
    expect 0 "after the race $n" "$gdr" info "$work/limit/box$n/BoxTextured.gltf" --cache-dir "$work/race" --strict
done
ls "$work/race" | grep -v '\.gdrc$' && fail "temporary files left in the cache folder"

if [ "$failures" -ne 0 ]; then
    echo "test_cli_cache: $failures failure(s)"
    exit 1
fi
echo "test_cli_cache: all checks passed"
