#!/bin/sh
# Writes the output of `gdr info --passes` (every frame configuration's passes, resource uses and
# derived barriers) into docs/PIPELINE.md between its two marker lines, so the document shows the
# frame exactly as the program builds it. tests/cli/test_pipeline_doc.sh fails when they differ.
#
#   scripts/update-pipeline-doc.sh [GDR [DOC]]
#
# GDR: the gdr program (default build/tools/gdr/gdr; `make pipeline-doc` builds it and runs this),
# DOC: the document (default docs/PIPELINE.md). The document is replaced through a rename.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
gdr=${1:-$root/build/tools/gdr/gdr}
doc=${2:-$root/docs/PIPELINE.md}
begin='<!-- gdr info --passes: begin -->'
end='<!-- gdr info --passes: end -->'

line_of() { grep -nxF -- "$1" "$doc" | cut -d: -f1; }
if [ ! -x "$gdr" ]; then
    echo "update-pipeline-doc: $gdr is not an executable gdr program (build it: make build)" >&2
    exit 1
fi
b=$(line_of "$begin")
e=$(line_of "$end")
case "$b $e" in
*[!0-9\ ]* | " "* | *" ") b=0 e=0 ;;
esac
if [ "$b" -eq 0 ] || [ "$e" -le "$b" ]; then
    echo "update-pipeline-doc: $doc needs one line '$begin' followed later by one line '$end'" >&2
    exit 1
fi

passes=$(mktemp)
new=$(mktemp "$doc.XXXXXX")
trap 'rm -f "$passes" "$new"' EXIT
"$gdr" info --passes >"$passes"
{
    head -n "$b" "$doc"
    cat "$passes"
    tail -n "+$e" "$doc"
} >"$new"
chmod 644 "$new"
mv "$new" "$doc"
