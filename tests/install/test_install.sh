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
"$work/render_demo" "$work/out.png"
[ -s "$work/out.png" ] || { echo "FAIL: the example wrote no image"; exit 1; }
[ -x "$work/prefix/bin/gdr" ] || { echo "FAIL: the gdr program was not installed"; exit 1; }
echo "test_install: all checks passed"
