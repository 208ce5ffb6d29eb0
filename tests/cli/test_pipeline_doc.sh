#!/bin/sh
# docs/PIPELINE.md holds the output of `gdr info --passes` between two marker lines: fails, showing
# the difference and how to regenerate it, when the document no longer matches the program.
#   test_pipeline_doc.sh GDR DOC UPDATER
set -eu
gdr=$1
doc=$2
updater=$3
copy=$(mktemp)
trap 'rm -f "$copy"' EXIT
cp "$doc" "$copy"
if ! sh "$updater" "$gdr" "$copy"; then
    echo "FAIL: $doc: the marked section of 'gdr info --passes' output could not be updated" >&2
    exit 1
fi
if ! diff -u "$doc" "$copy"; then
    echo "FAIL: $doc differs from 'gdr info --passes' (above: what the program prints now)." >&2
    echo "Regenerate it with: make pipeline-doc   (or: scripts/update-pipeline-doc.sh $gdr)" >&2
    exit 1
fi
echo "ok: $doc matches 'gdr info --passes'"
