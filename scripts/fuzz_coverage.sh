#!/bin/sh
# Source coverage of a fuzz corpus (docs/SECURITY.md): builds one libFuzzer target with clang's
# coverage instrumentation (no sanitizers), replays the corpus once, and prints llvm-cov's line and
# branch coverage of the files it reaches in src/.
# usage: scripts/fuzz_coverage.sh gltf|obj|cache|image CORPUS_DIR [WORK_DIR]
set -eu
target=$1 corpus=$2 work=${3:-$(mktemp -d)}
root=$(cd "$(dirname "$0")/.." && pwd)
src=$root/src
mkdir -p "$work"
sources="$src/io/file.c $src/io/budget.c $src/io/mesh_clean.c $src/io/image.c $src/io/image_png.c
 $src/io/image_jpeg.c $src/io/gltf.c $src/io/gltf_buffers.c
 $src/io/obj.c $src/io/cache.c $src/io/cache_sections.c $src/io/cache_decode.c $src/scene/scene.c $(ls "$src"/geometry/*.c)
 $src/core/thread_pool.c $src/core/error.c $src/core/progress.c $src/core/output_file.c $src/math/vector.c
 $src/math/matrix.c $src/math/quaternion.c $src/math/projection.c $src/math/frustum.c $src/cull/pvs_blob.c
 $src/cull/pvs_query.c"
# shellcheck disable=SC2086
clang -std=c17 -O1 -g -fsanitize=fuzzer -fprofile-instr-generate -fcoverage-mapping -D_POSIX_C_SOURCE=200809L \
    -DGDR_VERSION_STRING='"coverage"' -I"$root/include" -I"$src" -I/usr/include/cjson $sources \
    "$root/tests/fuzz/fuzz_$target.c" -lcjson -lxxhash -lmeshoptimizer -lmetis -lstb -lzstd -lpng16 -ljpeg -lz -lpthread -lm \
    -o "$work/fuzz_$target.cov"
LLVM_PROFILE_FILE="$work/$target.profraw" "$work/fuzz_$target.cov" -runs=0 "$corpus" >/dev/null 2>&1 || true
llvm-profdata merge -sparse "$work/$target.profraw" -o "$work/$target.profdata"
echo "corpus: $(find "$corpus" -type f | wc -l) inputs"
llvm-cov report "$work/fuzz_$target.cov" -instr-profile="$work/$target.profdata" $sources | \
    sed "s|$root/||" | awk 'NR <= 2 || $4 != "100.00%" || 1' | grep -v "^-*$"
