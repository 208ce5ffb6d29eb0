#!/bin/sh
# The Khronos glTF validator as an oracle: over the assimp glTF2 corpus, glTF files written by the
# test suite and the fuzz corpora, a file the validator calls valid must load (`gdr info` exit 0,
# or a refusal that names an unsupported feature); a file it calls invalid must load or be refused
# with a message (exit 1, "gdr: ..."), never crash (a signal) or hang (10 s).
# usage: test_gltf_validator.sh GDR SOURCE_DIR BUILD_DIR
set -u
gdr=$1 source=$2 build=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
GLTF_VALIDATOR_ROOT=${GLTF_VALIDATOR_ROOT:-$(npm root -g 2>/dev/null)}
export GLTF_VALIDATOR_ROOT
if ! command -v node >/dev/null 2>&1 || ! [ -d "$GLTF_VALIDATOR_ROOT/gltf-validator" ]; then
    echo "test_gltf_validator: node or the npm package gltf-validator is missing: run scripts/install-deps.sh" >&2
    exit 1
fi

# The files: every .gltf/.glb of the assimp corpus and the seeds, then at most 200 of the files the
# suite and the fuzzers wrote (copied with a .gltf or .glb name as their first bytes say).
{
    find /usr/share/assimp/models/glTF2 "$source/tests/fuzz/corpus/gltf" -type f \( -name '*.gltf' -o -name '*.glb' \) 2>/dev/null
    find "$build/tests/io" -type f \( -name '*.gltf' -o -name '*.glb' \) 2>/dev/null | head -50
} | sort > "$work/list"
n=0
for f in $(find "$build/tests/fuzz/corpus_gltf" -type f 2>/dev/null | sort | head -150); do
    n=$((n + 1))
    if [ "$(head -c 4 "$f")" = "glTF" ]; then ext=glb; else ext=gltf; fi
    cp "$f" "$work/fuzz$n.$ext"
    echo "$work/fuzz$n.$ext" >> "$work/list"
done

node "$source/tests/io/gltf_validate.mjs" $(cat "$work/list") > "$work/verdicts" || {
    echo "test_gltf_validator: the validator failed to run" >&2
    exit 1
}

failures=0 valid=0 invalid=0 loaded=0 refused=0 unsupported=0
while IFS="$(printf '\t')" read -r verdict errors file; do
    timeout 10 "$gdr" info "$file" --no-cache > "$work/out" 2> "$work/err"
    status=$?
    message=$(grep -a '^gdr: ' "$work/err" | grep -av '^gdr: warning:' | head -1) # -a: a message may quote bytes that are not text
    if [ "$verdict" = valid ]; then valid=$((valid + 1)); else invalid=$((invalid + 1)); fi
    if [ $status -eq 0 ]; then
        loaded=$((loaded + 1))
    elif [ $status -eq 1 ] && [ -n "$message" ]; then
        if [ "$verdict" = valid ]; then
            case "$message" in
            *"not supported"*|*"is not usable"*|*"only glTF 2.x"*)
                echo "unsupported: $file: $message"
                unsupported=$((unsupported + 1)) ;;
            *) echo "FAIL: valid by the validator, refused: $file: $message" >&2; failures=$((failures + 1)) ;;
            esac
        else
            refused=$((refused + 1))
        fi
    else
        echo "FAIL: $verdict ($errors errors), exit status $status (124: hung; >128: crashed): $file" >&2
        sed 's/^/    /' "$work/err" | tail -5 >&2
        failures=$((failures + 1))
    fi
done < "$work/verdicts"

echo "test_gltf_validator: $((valid + invalid)) files, $valid valid and $invalid invalid by the validator;" \
     "$loaded loaded, $refused invalid ones refused with a message, $unsupported valid ones unsupported"
echo "$((valid + invalid - failures)) passed, $failures failed"
[ $failures -eq 0 ]
