#!/bin/sh
# The include layers (docs/ARCHITECTURE.md): the tree follows them, and the check catches an include
# that goes up a layer, one that goes sideways between modules beside each other, and a tool that
# reaches past the public headers (each in a copy of the tree, so that the check is seen to fail).
# usage: test_layers.sh SOURCE_DIR WORK_DIR
set -u
source_dir=$1
work=$2
check="$source_dir/scripts/check-layers.sh"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

sh "$check" "$source_dir" || fail "the tree crosses a layer"

# expect_refused DESCRIPTION FILE LINE: FILE (relative) with LINE added is refused, naming FILE.
expect_refused() {
    what=$1 file=$2 line=$3
    rm -rf "$work" && mkdir -p "$work"
    cp -r "$source_dir/include" "$source_dir/src" "$source_dir/tools" "$source_dir/examples" "$work/"
    printf '%s\n' "$line" >>"$work/$file"
    if sh "$check" "$work" >"$work/out" 2>&1; then
        fail "$what: not refused"
    elif ! grep -q "^$file: includes" "$work/out"; then
        fail "$what: the refusal does not name $file"; cat "$work/out"
    fi
}
expect_refused "the scene model using the renderer" src/scene/scene.c '#include "render/renderer_internal.h"'
expect_refused "the scene model using an importer" src/scene/scene.c '#include "gdr/io.h"'
expect_refused "geometry using the culling library beside it" src/geometry/meshlets.c '#include "gdr/cull.h"'
expect_refused "a public header using a higher one" include/gdr/scene.h '#include "gdr/geometry.h"'
expect_refused "the program using an internal header" tools/gdr/main.c '#include "io/io_internal.h"'
expect_refused "an example using an internal header" examples/render_demo.c '#include "render/renderer_internal.h"'

rm -rf "$work"
echo "test_layers: $failures failure(s)"
[ "$failures" = 0 ]
