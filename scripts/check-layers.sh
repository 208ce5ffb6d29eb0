#!/bin/sh
# The include layers of docs/ARCHITECTURE.md, checked: every #include of a gdr header in src/,
# include/gdr/, tools/ and examples/ must name a module that the including file's module may use.
# A module may use the modules listed after it below (and itself); nothing else, so an include
# that crosses a layer upward, or sideways between modules beside each other, fails.
#   usage: check-layers.sh [REPOSITORY_ROOT]          exit 0: clean; 1: a violation (listed)
#          check-layers.sh --dot [REPOSITORY_ROOT]    the module graph as Graphviz dot, for the picture
set -u
dot=0
if [ "${1:-}" = "--dot" ]; then
    dot=1
    shift
fi
root=${1:-$(dirname "$0")/..}
cd "$root" || exit 2

# module: the modules it may include, bottom layer first. "public" is the set of installed headers
# that tools/ and examples/ may use (gdr.h, the umbrella, names every one of them).
allowed() {
    case $1 in
    core) echo "" ;;
    math) echo "core" ;;
    gpu_shared) echo "core math" ;;
    scene) echo "core math gpu_shared" ;;
    geometry) echo "core math gpu_shared scene" ;;
    cull) echo "core math gpu_shared scene" ;;
    procedural) echo "core math gpu_shared scene geometry" ;;
    io) echo "core math gpu_shared scene geometry cull procedural" ;;
    vk) echo "core math gpu_shared scene shaders" ;;
    stream) echo "core math gpu_shared scene io" ;;
    shaders) echo "math gpu_shared" ;;
    render) echo "core math gpu_shared scene geometry cull io vk stream shaders" ;;
    present) echo "core math gpu_shared scene render vk" ;;
    umbrella) echo "core math scene geometry cull procedural io render present" ;;
    tools | examples) echo "public" ;;
    *) echo "?" ;;
    esac
}

# The module an included name belongs to ("gdr/io.h" -> io, "stream/residency.h" -> stream).
module_of_include() {
    case $1 in
    gdr/gdr.h) echo umbrella ;;
    gdr/core.h | gdr/thread_pool.h | gdr/config.h) echo core ;;
    gdr/math.h) echo math ;;
    gdr/scene.h | gdr/mesh_clusters.h) echo scene ;;
    gdr/geometry.h) echo geometry ;;
    gdr/cull.h) echo cull ;;
    gdr/procedural.h) echo procedural ;;
    gdr/io.h | gdr/paged_cache.h) echo io ;;
    gdr/renderer.h | gdr/renderer_vulkan.h) echo render ;;
    gdr/present.h) echo present ;;
    gdr/*) echo "unknown-public" ;;
    */*) echo "${1%%/*}" ;;
    *) echo "" ;; # a header of the file's own folder, or a system header
    esac
}

# The module a file belongs to.
module_of_file() {
    case $1 in
    include/gdr/*) module_of_include "${1#include/}" ;;
    src/*) f=${1#src/}; echo "${f%%/*}" ;;
    tools/*) echo tools ;;
    examples/*) echo examples ;;
    esac
}

is_public() {
    case $1 in
    gdr/*) [ "$(module_of_include "$1")" != "unknown-public" ] ;;
    *) return 1 ;;
    esac
}

failures=0
edges=""
files=$(find include/gdr src tools examples -type f \( -name '*.c' -o -name '*.h' -o -name '*.glsl' \) | sort)
for file in $files; do
    from=$(module_of_file "$file")
    may=$(allowed "$from")
    # Quoted includes and, in tools/ and examples/, angle-bracket gdr/ includes.
    for name in $(sed -n -e 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' \
                        -e 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*<\(gdr\/[^>]*\)>.*/\1/p' "$file"); do
        to=$(module_of_include "$name")
        [ -z "$to" ] && continue
        case $from in
        tools | examples)
            if ! is_public "$name"; then
                echo "$file: includes \"$name\": $from/ may use the installed public headers (gdr/*.h) only"
                failures=$((failures + 1))
            fi
            continue ;;
        esac
        [ "$to" = "$from" ] && continue
        case " $may " in
        *" $to "*) edges="$edges$from $to
" ;;
        *)
            echo "$file: includes \"$name\": module '$from' may not use '$to' (it may use: ${may:-nothing})"
            failures=$((failures + 1)) ;;
        esac
    done
done

if [ "$dot" = 1 ]; then
    echo "digraph gdr_layers {"
    echo "  rankdir=BT; node [shape=box, fontname=\"sans-serif\"];"
    printf '%s' "$edges" | sort -u | while read -r a b; do
        [ -n "$a" ] && echo "  \"$a\" -> \"$b\";"
    done
    echo "}"
fi
if [ "$failures" != 0 ]; then
    echo "check-layers: $failures include(s) cross a layer (docs/ARCHITECTURE.md)" >&2
    exit 1
fi
[ "$dot" = 1 ] || echo "check-layers: every include follows the layers"
