#!/bin/sh
# `make install` gives a library, headers and a pkg-config file that a program can build against:
# install the build into a temporary prefix, compile examples/render_demo.c with pkg-config, run it.
# usage: test_install.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1
source=$2
work=$3
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
pc=$(dirname "$(find "$work/prefix" -name gdr.pc | head -n 1)")
[ -n "$pc" ] || { echo "FAIL: no gdr.pc installed"; exit 1; }
export PKG_CONFIG_PATH="$pc"
libdir=$(pkg-config --variable=libdir gdr)
# shellcheck disable=SC2046
cc -std=c17 -Wall -Wextra -Werror "$source/examples/render_demo.c" $(pkg-config --cflags --libs gdr) \
   -Wl,-rpath,"$libdir" -o "$work/render_demo"
"$work/render_demo" "$work/out.png" >"$work/stdout"
[ -s "$work/out.png" ] || { echo "FAIL: the example wrote no image"; exit 1; }
grep -Eq '[1-9][0-9]* of [1-9][0-9]* instances visible, [1-9][0-9]* triangles' "$work/stdout" ||
    { echo "FAIL: the example read no statistics"; cat "$work/stdout"; exit 1; }
# Every installed header stands alone: it compiles as the only include of a file.
for header in "$work"/prefix/include/gdr/*.h; do
    name=$(basename "$header")
    # shellcheck disable=SC2046
    printf '#include <gdr/%s>\n' "$name" | cc -std=c17 -Wall -Wextra -Werror -fsyntax-only -x c - \
        $(pkg-config --cflags gdr) || { echo "FAIL: gdr/$name does not compile alone"; exit 1; }
done
# gdr.h names every installed header.
for header in "$work"/prefix/include/gdr/*.h; do
    name=$(basename "$header")
    [ "$name" = gdr.h ] && continue
    grep -q "#include \"gdr/$name\"" "$work/prefix/include/gdr/gdr.h" ||
        { echo "FAIL: gdr/gdr.h does not include gdr/$name"; exit 1; }
done
[ -x "$work/prefix/bin/gdr" ] || { echo "FAIL: the gdr program was not installed"; exit 1; }
echo "test_install: all checks passed"
