#!/usr/bin/env bash
# The run to make first when an NVIDIA GPU is lent (docs/PERFORMANCE.md, "GPU throughput"):
# the sylva-gpu test suite with CI=true, then every paper table on the GPU. Two halves:
#
#   tools/nvidia-run.sh pack                  here: release binaries, stripped and compressed
#                                             into .nvidia/ (ignored by git; carry it)
#   tools/nvidia-run.sh run OUT [PART]        there: unpack, run, leave at most six files in
#                                             OUT (gpu.txt, leaves.log, tests.log, bench.log,
#                                             bench.tar.gz, clocks.csv); PART is leaves, bench, tests or all
#
# `leaves` renders the default scene on the GPU with leaf motion on and off (five runs each,
# interleaved) and prints the GPU time of simulation + meshing per frame (issue: leaf motion
# adds at most 10 % there).
#
# With the device tool: run `pack`, then one call with carry [".nvidia", ".gl"] and the
# command `bash tools/nvidia-run.sh run $OUT`. `.gl` holds the Vulkan loader packages the
# device README says to download; they are unpacked when present. SYLVA_BENCH_ARGS adds
# options to `sylva bench` (e.g. `--quick` for a trial of the script on lavapipe).
set -euo pipefail
cd "$(dirname "$0")/.."
here=$PWD

pack() {
    rm -rf .nvidia && mkdir -p .nvidia/bin/tests
    cargo build --release -p sylva-cli
    strip -o .nvidia/bin/sylva target/release/sylva
    # The test binaries cargo names ("Executable tests/hsm.rs (target/release/deps/hsm-…)").
    cargo test --release -p sylva-gpu --no-run 2>&1 \
        | sed -n 's/.*Executable \(tests\/[a-z_]*\)\.rs (\(target\/release\/deps\/[^)]*\)).*/\1 \2/p' \
        | while read -r name path; do strip -o ".nvidia/bin/$name" "$path"; done
    (cd .nvidia && tar -cJf bin.tar.xz bin && rm -rf bin)
    # Tests find their golden images under the path they were built at.
    echo "$here" > .nvidia/built-at
    du -h .nvidia/bin.tar.xz
}

run() {
    local out=$1 part=${2:-all}
    mkdir -p "$out"
    if compgen -G ".gl/*.deb" > /dev/null; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    fi
    local bin
    bin=$(mktemp -d)
    tar -xJf .nvidia/bin.tar.xz -C "$bin"
    local built
    built=$(cat .nvidia/built-at)
    if [ "$built" != "$here" ] && [ ! -e "$built" ]; then
        mkdir -p "$(dirname "$built")" && ln -s "$here" "$built"
    fi
    export WGPU_BACKEND=vulkan CI=true RUST_BACKTRACE=0
    {
        date -u +%FT%TZ
        nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem,memory.total --format=csv || true
        "$bin/bin/sylva" --version
    } >> "$out/gpu.txt" 2>&1
    if [ "$part" = all ] || [ "$part" = leaves ]; then
        sed 's/^method = .*/&\nleaf_motion = { strength = 0.0 }/' presets/scenes/default.toml > "$bin/off.toml"
        for i in 1 2 3 4 5; do
            for s in on off; do
                local scene=presets/scenes/default.toml
                [ $s = off ] && scene="$bin/off.toml"
                echo "== leaves $s ($i)"
                "$bin/bin/sylva" render "$scene" --backend gpu --seconds 6 --no-mp4 --no-png --out-dir "$bin/render" 2>&1 \
                    | grep -v '^wrote' || true
            done
        done > "$out/leaves.log" 2>&1
    fi
    if [ "$part" = all ] || [ "$part" = tests ]; then
        local failed=0
        for t in "$bin"/bin/tests/*; do
            echo "== $(basename "$t")"
            (cd crates/sylva-gpu && "$t") || failed=1
        done > "$out/tests.log" 2>&1
        echo "tests: $([ $failed = 0 ] && echo passed || echo FAILED)" | tee -a "$out/gpu.txt"
    fi
    if [ "$part" = all ] || [ "$part" = bench ]; then
        # The card's clocks, power and load through the bench, five times a second.
        local smi=""
        if command -v nvidia-smi > /dev/null; then
            nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu,power.draw \
                --format=csv -lms 200 > "$out/clocks.csv" 2>&1 &
            smi=$!
        fi
        # shellcheck disable=SC2086
        "$bin/bin/sylva" bench all --backend gpu --out-dir "$bin/bench" ${SYLVA_BENCH_ARGS:-} > "$out/bench.log" 2>&1 \
            || echo "bench: FAILED" | tee -a "$out/gpu.txt"
        if [ -n "$smi" ]; then kill "$smi" 2> /dev/null || true; fi
        tar -czf "$out/bench.tar.gz" -C "$bin" bench
    fi
}

case "${1:-}" in
    pack) pack ;;
    run) run "${2:?usage: tools/nvidia-run.sh run OUT [leaves|bench|tests|all]}" "${3:-all}" ;;
    *) echo "usage: tools/nvidia-run.sh pack | run OUT [leaves|bench|tests|all]" >&2; exit 2 ;;
esac
