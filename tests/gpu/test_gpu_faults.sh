#!/bin/sh
# GPU faults (docs/SECURITY.md): device loss at every queue submission of a short render, and
# device memory running out at several sizes, injected by vk_fault_shim (LD_PRELOAD) where lavapipe
# cannot produce them. Each must end in a message and exit status 1: no crash, no hang, and no
# output file left (the PNG and the statistics are only written after a frame succeeded).
# usage: test_gpu_faults.sh GDR_BINARY SHIM WORK_DIR
set -u
gdr=$1 shim=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
failures=0 runs=0

# run DESCRIPTION PATTERN ENV... -- ARGS...
run() {
    what=$1 pattern=$2
    shift 2
    rm -f "$work/out.png" "$work/out.json"
    env LD_PRELOAD="$shim" "$@" --out "$work/out.png" --stats "$work/out.json" >"$work/stdout" 2>"$work/stderr"
    status=$?
    runs=$((runs + 1))
    if [ $status -ne 1 ]; then
        echo "FAIL ($what): exit status $status, expected 1 (>128: crashed, 124: hung)"; tail -5 "$work/stderr"
        failures=$((failures + 1))
    elif ! grep -Eq "^gdr: .*$pattern" "$work/stderr"; then
        echo "FAIL ($what): no message matching /$pattern/"; tail -5 "$work/stderr"; failures=$((failures + 1))
    elif [ -e "$work/out.png" ] || [ -e "$work/out.json" ] || ls "$work" | grep -q '\.tmp\.'; then
        echo "FAIL ($what): an output file was left"; ls "$work"; failures=$((failures + 1))
    fi
}

scene="demo:instances=200"
for pipeline in mesh indirect cpu; do
    # A clean run of 3 frames: how many submissions it makes and how much memory it allocates.
    env LD_PRELOAD="$shim" GDR_FAULT_COUNT_SUBMITS=1 timeout 60 "$gdr" render $scene --width 64 --height 48 \
        --frames 3 --pipeline $pipeline >/dev/null 2>"$work/count"
    count=$(sed -n 's/^vk_fault_shim: submissions: //p' "$work/count")
    bytes=$(sed -n 's/^vk_fault_shim: allocated: //p' "$work/count")
    if [ -z "$count" ] || [ "$count" -le 0 ] || [ -z "$bytes" ] || [ "$bytes" -le 0 ]; then
        echo "FAIL ($pipeline): the clean run was not counted"; failures=$((failures + 1)); continue
    fi
    # The device lost at every submission (the mesh pipeline) or at the first, a middle and the last.
    list=$(seq 1 "$count")
    [ $pipeline = mesh ] || list="1 $(((count + 1) / 2)) $count"
    for n in $list; do
        run "$pipeline: device lost at submission $n of $count" "DEVICE_LOST|device (was )?lost" \
            GDR_FAULT_DEVICE_LOST_AT=$n timeout 60 "$gdr" render $scene --width 64 --height 48 --frames 3 \
            --pipeline $pipeline
    done
    # Device memory that runs out at the first allocation, half way and at the last one.
    for limit in 1 $((bytes / 2)) $((bytes - 1)); do
        run "$pipeline: device memory limited to $limit of $bytes bytes" "device memory|OUT_OF_DEVICE_MEMORY" \
            GDR_FAULT_DEVICE_MEMORY=$limit timeout 60 "$gdr" render $scene --width 64 --height 48 --frames 3 \
            --pipeline $pipeline
    done
done
# A render target too large for the memory there is (a 16384^2 target needs over 2 GiB).
run "render target beyond device memory" "device memory|OUT_OF_DEVICE_MEMORY" \
    GDR_FAULT_DEVICE_MEMORY=536870912 timeout 60 "$gdr" render demo:instances=10 --width 16384 --height 16384

echo "test_gpu_faults: $runs runs, $failures failure(s)"
echo "$((runs - failures)) passed, $failures failed"
[ "$failures" = 0 ]
