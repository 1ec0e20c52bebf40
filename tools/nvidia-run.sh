#!/usr/bin/env bash
# The run to make first when an NVIDIA GPU is lent (docs/PERFORMANCE.md, "GPU throughput"):
# the sylva-gpu test suite with CI=true, then every paper table on the GPU. Two halves:
#
#   tools/nvidia-run.sh pack                  here: release binaries, stripped and compressed
#                                             into .nvidia/ (ignored by git; carry it)
#   tools/nvidia-run.sh run OUT [tests|bench] there: unpack, run, leave at most four files
#                                             in OUT (gpu.txt, tests.log, bench.log, bench.tar.gz)
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
    } > "$out/gpu.txt" 2>&1
    if [ "$part" != bench ]; then
        local failed=0
        for t in "$bin"/bin/tests/*; do
            echo "== $(basename "$t")"
            (cd crates/sylva-gpu && "$t") || failed=1
        done > "$out/tests.log" 2>&1
        echo "tests: $([ $failed = 0 ] && echo passed || echo FAILED)" | tee -a "$out/gpu.txt"
    fi
    if [ "$part" != tests ]; then
        # shellcheck disable=SC2086
        "$bin/bin/sylva" bench all --backend gpu --out-dir "$bin/bench" ${SYLVA_BENCH_ARGS:-} > "$out/bench.log" 2>&1 \
            || echo "bench: FAILED" | tee -a "$out/gpu.txt"
        tar -czf "$out/bench.tar.gz" -C "$bin" bench
    fi
}

case "${1:-}" in
    pack) pack ;;
    run) run "${2:?usage: tools/nvidia-run.sh run OUT [tests|bench]}" "${3:-all}" ;;
    *) echo "usage: tools/nvidia-run.sh pack | run OUT [tests|bench]" >&2; exit 2 ;;
esac
