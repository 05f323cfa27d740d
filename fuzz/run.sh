#!/usr/bin/env bash
# Runs Arbor's fuzz targets (see docs/robustness.md). Installs cargo-fuzz itself when it is missing, so a
# fresh machine with only Rust needs nothing else.
#
#   fuzz/run.sh list                       the targets
#   fuzz/run.sh build                      build every target
#   fuzz/run.sh run TARGET [RUNS [FLAGS]]  run TARGET for RUNS executions (default 10^7) or until a failure;
#                                          prints libFuzzer's final stats; exit code non-zero on a failure;
#                                          FLAGS go to libFuzzer (e.g. -max_total_time=1800)
#   fuzz/run.sh all [RUNS]                 every target in turn
#   fuzz/run.sh replay TARGET FILE...      run TARGET on the given inputs only (crash files, corpora)
#
# Environment: FUZZ_SANITIZER (address | none; default none: no unsafe code is fuzzed, and without
# AddressSanitizer the parsers run 2-4x faster, so 10^7 executions take minutes), FUZZ_JOBS (parallel
# jobs; default 1), FUZZ_MAX_LEN (bytes; default 8192). Debug assertions are always on (`-a`).
set -euo pipefail
cd "$(dirname "$0")"

CARGO_FUZZ_VERSION=0.13.2
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "installing cargo-fuzz $CARGO_FUZZ_VERSION (once, about 5 minutes)" >&2
    cargo install cargo-fuzz --version "$CARGO_FUZZ_VERSION" --locked
fi

# cargo-fuzz passes nightly-only flags; the machine has stable Rust, which accepts them with this.
export RUSTC_BOOTSTRAP=1
SAN="${FUZZ_SANITIZER:-none}"
FLAGS=(-a -s "$SAN")

run_one() {
    local target=$1 runs=${2:-10000000}
    shift 2 || shift $#
    mkdir -p "corpus/$target"
    echo "== $target: $runs executions (sanitizer $SAN)" >&2
    # `-jobs` makes libFuzzer write each job's output to fuzz-N.log instead of the terminal: only with >1.
    local jobs=()
    if [ "${FUZZ_JOBS:-1}" -gt 1 ]; then jobs=(-jobs="$FUZZ_JOBS" -workers="$FUZZ_JOBS"); fi
    cargo fuzz run "${FLAGS[@]}" "$target" "corpus/$target" "seeds/$target" -- \
        -runs="$runs" -rss_limit_mb=1024 -timeout=10 -max_len="${FUZZ_MAX_LEN:-8192}" \
        "${jobs[@]}" -print_final_stats=1 "$@"
}

case "${1:-}" in
    list) cargo fuzz list ;;
    build) cargo fuzz build "${FLAGS[@]}" ;;
    run)
        shift
        run_one "${1:?target}" "${2:-10000000}" "${@:3}"
        ;;
    all)
        for t in $(cargo fuzz list); do run_one "$t" "${2:-10000000}"; done
        ;;
    replay)
        target=${2:?target}
        shift 2
        cargo fuzz run "${FLAGS[@]}" "$target" "$@" -- -rss_limit_mb=1024 -timeout=10
        ;;
    *)
        sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
        exit 2
        ;;
esac
