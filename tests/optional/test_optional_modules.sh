#!/bin/sh
# A build without the optional modules (docs/ARCHITECTURE.md, "Optional modules") links and works.
# Configures a second tree with -DGDR_EXCLUDE_MODULES="cull;present" and builds only the library, the
# gdr program and render_demo (Debug: no optimiser, so the build stays short and every call the
# code names must link), then checks:
#   - CMake refuses a module that is not optional, and tests with modules left out, naming why;
#   - libgdr.so leaves no gdr_ symbol undefined and defines every GDR_API function of the headers
#     it installs; gdr/cull.h and gdr/present.h are not installed, gdr/config.h says 0 for both, and
#     examples/render_demo.c and lean_api.c compile against the installed tree (gdr/gdr.h without
#     them);
#   - gdr renders demo:instances=10 with the mesh pipeline to a PNG, render_demo runs, and lean_api
#     checks the library's answers without the culling module (lean_api.c says which);
#   - --pipeline cpu, --pvs on, build --pvs, bench --pipelines cpu and gdr view exit 2 with the
#     message, and no view_demo target exists;
#   - with FULL_GDR (a gdr program with every module): the lean build renders the demo as the full
#     build does, byte for byte; a cache holding a PVS loads in the lean build (its PVIS section
#     skipped) and renders the image the full build renders with --pvs off; the lean build writes
#     it back without the section.
# usage: test_optional_modules.sh SOURCE_DIR WORK_DIR [FULL_GDR]     (JOBS: parallel build jobs)
set -u
source=$(cd "$1" && pwd)
work=$2
full=${3:-}
[ -z "$full" ] || full=$(cd "$(dirname "$full")" && pwd)/$(basename "$full")
jobs=${JOBS:-$(nproc)}
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd)
XDG_CACHE_HOME=$work/cache-home; export XDG_CACHE_HOME # caches of the sources here, not in the home
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
message="built without the culling module (GDR_EXCLUDE_MODULES)"

# expect STATUS DESCRIPTION COMMAND...: the exit status; stdout and stderr kept in $work.
expect() {
    want=$1; shift
    what=$1; shift
    "$@" >"$work/stdout" 2>"$work/stderr"
    got=$?
    [ "$got" = "$want" ] || { fail "($what): exit $got, expected $want: $*"; cat "$work/stderr"; }
}
# stderr_has DESCRIPTION TEXT: the last command's stderr holds TEXT.
stderr_has() { grep -qF -- "$2" "$work/stderr" || fail "($1): no '$2' in: $(cat "$work/stderr")"; }

# --- configure: what may be left out ----------------------------------------------------------
expect 1 "exclude io" cmake -S "$source" -B "$work/refused" -DGDR_EXCLUDE_MODULES=io -DGDR_BUILD_TESTS=OFF
stderr_has "exclude io" "'io' is not an optional module"
expect 1 "exclude with tests" cmake -S "$source" -B "$work/refused" -DGDR_EXCLUDE_MODULES=cull -DGDR_BUILD_TESTS=ON
stderr_has "exclude with tests" "-DGDR_BUILD_TESTS=OFF"

build=$work/build
if ! cmake -S "$source" -B "$build" -DCMAKE_BUILD_TYPE=Debug -DGDR_WERROR=ON -DGDR_EXCLUDE_MODULES="cull;present" \
        -DGDR_BUILD_TESTS=OFF >"$work/configure.log" 2>&1; then
    cat "$work/configure.log"; echo "FAIL: configuring without cull and present"; exit 1
fi
if ! cmake --build "$build" -j "$jobs" --target gdr gdr_cli render_demo >"$work/build.log" 2>&1; then
    tail -n 40 "$work/build.log"; echo "FAIL: building without cull and present"; exit 1
fi
cmake --build "$build" --target help | grep -q view_demo && fail "view_demo is a target without the present module"

# --- the library and its installed headers ------------------------------------------------------
lib=$build/libgdr.so
undefined=$(nm -D --undefined-only "$lib" | awk '{print $NF}' | grep '^gdr_')
[ -z "$undefined" ] || fail "libgdr.so leaves gdr_ symbols undefined: $undefined"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1 || { cat "$work/install.log"; fail "install"; }
headers=$prefix/include/gdr
for h in cull.h present.h; do [ ! -e "$headers/$h" ] || fail "gdr/$h installed without its module"; done
grep -q '^#define GDR_HAVE_CULL 0$' "$headers/config.h" || fail "gdr/config.h: GDR_HAVE_CULL is not 0"
grep -q '^#define GDR_HAVE_PRESENT 0$' "$headers/config.h" || fail "gdr/config.h: GDR_HAVE_PRESENT is not 0"
# Every function the installed headers declare with GDR_API, defined (exported) by the library.
grep -hv '^#' "$headers"/*.h | tr '\n' ' ' | grep -o 'GDR_API[^(;]*(' | sed 's/[[:space:]]*($//' | awk '{print $NF}' |
    tr -d '*' | sort -u >"$work/declared"
nm -D --defined-only "$lib" | awk '{print $3}' | sort -u >"$work/defined"
[ "$(wc -l <"$work/declared")" -gt 50 ] || fail "found only $(wc -l <"$work/declared") GDR_API declarations"
missing=$(comm -23 "$work/declared" "$work/defined")
[ -z "$missing" ] || fail "declared in the installed headers, not in libgdr.so: $missing"
pc=$(dirname "$(find "$prefix" -name gdr.pc | head -n 1)")
flags=$(PKG_CONFIG_PATH=$pc pkg-config --cflags --libs gdr)
libdir=$(PKG_CONFIG_PATH=$pc pkg-config --variable=libdir gdr)
for program in "$source/examples/render_demo.c" "$source/tests/optional/lean_api.c"; do
    # shellcheck disable=SC2086
    cc -std=c17 -Wall -Wextra -Werror "$program" $flags -Wl,-rpath,"$libdir" -o "$work/$(basename "$program" .c)" \
        2>"$work/stderr" || fail "$(basename "$program") against the installed headers: $(cat "$work/stderr")"
done

# --- the program and the example ---------------------------------------------------------------
gdr=$build/tools/gdr/gdr
cd "$work" || exit 1
small="--width 160 --height 96"
# shellcheck disable=SC2086
expect 0 "render mesh" "$gdr" render demo:instances=10 --pipeline mesh $small --out "$work/lean.png" --stats "$work/lean.json"
[ "$(head -c 8 "$work/lean.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "render wrote no PNG"
visible=$(sed -n 's/^[[:space:]]*"instances_visible":[[:space:]]*\([0-9]*\),$/\1/p' "$work/lean.json")
[ "${visible:-0}" -gt 0 ] || fail "nothing drawn: instances_visible '$visible'"
grep -q '"pvs":[[:space:]]*"none"' "$work/lean.json" || fail "the statistics do not say pvs none"
expect 0 "render_demo" "$work/render_demo" "$work/render_demo.png"
[ -s "$work/render_demo.png" ] || fail "render_demo wrote no image"

# shellcheck disable=SC2086
expect 2 "pipeline cpu" "$gdr" render demo:instances=10 --pipeline cpu $small
stderr_has "pipeline cpu" "--pipeline cpu: $message"
# shellcheck disable=SC2086
expect 2 "pvs on" "$gdr" render demo:instances=10 --pvs on $small
stderr_has "pvs on" "--pvs on: $message"
expect 2 "build --pvs" "$gdr" build demo:instances=10 --pvs -o "$work/never.gdrc"
stderr_has "build --pvs" "--pvs: $message"
[ ! -e "$work/never.gdrc" ] || fail "build --pvs wrote a cache"
expect 2 "bench cpu" "$gdr" bench --sizes 10 --pipelines mesh,cpu --frames 1
stderr_has "bench cpu" "--pipelines cpu: $message"
expect 2 "view" "$gdr" view demo:instances=10
stderr_has "view" "this build has no presenter"

# --- a cache with a PVS, written by the full build ----------------------------------------------
if [ -n "$full" ]; then
    # shellcheck disable=SC2086
    expect 0 "full render" "$full" render demo:instances=10 --pipeline mesh $small --out "$work/full.png"
    cmp -s "$work/lean.png" "$work/full.png" || fail "the lean build's demo image differs from the full build's"
    expect 0 "full build --pvs" "$full" build demo:instances=10 --pvs --pvs-samples 1 --no-progress -o "$work/pvs.gdrc"
    expect 0 "full info" "$full" info "$work/pvs.gdrc"
    grep -q '^pvs: *[1-9][0-9]* cells, [1-9][0-9]* objects' "$work/stdout" || fail "the full build's cache holds no PVS"
    expect 0 "lean info" "$gdr" info "$work/pvs.gdrc"
    grep -q "^pvs: *not read: $message" "$work/stdout" || fail "lean info: $(grep pvs "$work/stdout")"
    # shellcheck disable=SC2086
    expect 0 "lean render of a cache with a PVS" "$gdr" render "$work/pvs.gdrc" --pipeline mesh $small --out "$work/lean-pvs.png"
    # shellcheck disable=SC2086
    expect 0 "full render, pvs off" "$full" render "$work/pvs.gdrc" --pipeline mesh --pvs off $small --out "$work/full-pvs.png"
    cmp -s "$work/lean-pvs.png" "$work/full-pvs.png" || fail "the lean build's image differs from the full build's"
    expect 0 "lean rebuild" "$gdr" build "$work/pvs.gdrc" --no-progress -o "$work/rebuilt.gdrc"
    expect 0 "full info of the rebuilt cache" "$full" info "$work/rebuilt.gdrc"
    grep -q '^pvs: *none$' "$work/stdout" || fail "the lean build wrote a PVS: $(grep pvs "$work/stdout")"
fi

# The library's own answers, through the API (a cache with a PVS when the full build made one).
pvs_cache=
[ -s "$work/pvs.gdrc" ] && pvs_cache=$work/pvs.gdrc
# shellcheck disable=SC2086
expect 0 "lean_api" "$work/lean_api" "$work" $pvs_cache
cat "$work/stderr"

if [ "$failures" != 0 ]; then
    echo "test_optional_modules: $failures failure(s)"
    exit 1
fi
echo "test_optional_modules: all checks passed"
