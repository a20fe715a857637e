#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Run one libFuzzer target with the project's options (used by ctest and `make fuzz`).
#   run_fuzzer.sh replay EXE CORPUS WORK
#       run EXE once on every file in CORPUS.
#   run_fuzzer.sh fuzz SECONDS EXE CORPUS WORK [--fresh] [libFuzzer options...]
#       fuzz for SECONDS from CORPUS, which is only read: new inputs go to WORK/corpus
#       (--fresh empties it first), the log to WORK/fuzz.log, and one line per run to the
#       ledger, $ICOAC_FUZZ_LEDGER or else WORK/ledger.tsv (the executions, coverage and exit
#       status, with ICOAC_FUZZ_SOURCES, the id of the C sources fuzzed), so runs resumed from
#       the corpus add up (tests/fuzz/ledger.py).
# Crash and contract-violation reproducers go to WORK/artifacts/. The exit status is non-zero
# on a crash, a sanitizer report, a contract violation, a timeout or an out-of-memory.
set -eu

: "${ASAN_OPTIONS:=detect_leaks=1}"
: "${UBSAN_OPTIONS:=print_stacktrace=1:halt_on_error=1}"
export ASAN_OPTIONS UBSAN_OPTIONS

usage() {
    echo "usage: $0 replay EXE CORPUS WORK | fuzz SECONDS EXE CORPUS WORK [--fresh] [options]" >&2
    exit 2
}

[ $# -ge 4 ] || usage
mode=$1
shift
if [ "$mode" = fuzz ]; then
    [ $# -ge 4 ] || usage
    seconds=$1
    shift
fi
exe=$1
corpus=$2
work=$3
shift 3
name=$(basename "$exe")
mkdir -p "$work/artifacts"
limits="-timeout=10 -rss_limit_mb=2048 -artifact_prefix=$work/artifacts/"

case $mode in
replay)
    # shellcheck disable=SC2086
    exec "$exe" $limits "$corpus"/*
    ;;
fuzz)
    if [ "${1:-}" = --fresh ]; then
        rm -rf "$work/corpus"
        shift
    fi
    mkdir -p "$work/corpus"
    log=$work/fuzz.log
    status=0
    echo "$name: fuzzing for ${seconds} s, log $log"
    # shellcheck disable=SC2086
    "$exe" $limits -max_total_time="$seconds" -print_final_stats=1 "$@" "$work/corpus" "$corpus" \
        >"$log" 2>&1 || status=$?
    ledger=${ICOAC_FUZZ_LEDGER:-$work/ledger.tsv}
    mkdir -p "$(dirname "$ledger")"
    [ -f "$ledger" ] || printf 'utc\tsources\tseconds\texecutions\tcov\tft\tcorpus\tstatus\n' >"$ledger"
    executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    last=$(grep -E '^#[0-9]+[[:space:]]+(DONE|pulse|NEW|REDUCE|INITED)' "$log" | tail -n 1)
    [ -n "$executions" ] || executions=$(echo "$last" | sed -n 's/^#\([0-9]*\).*/\1/p')
    cov=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
    ft=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "${ICOAC_FUZZ_SOURCES:-unknown}" \
        "$seconds" "${executions:-0}" "${cov:-0}" "${ft:-0}" "$(ls "$work/corpus" | wc -l)" "$status" >>"$ledger"
    if [ "$status" -eq 0 ]; then
        echo "$name: no failure in ${seconds} s (log $log)"
        grep -E '^#[0-9]+ +DONE|^stat::' "$log" || true
    else
        echo "$name: FAILED, exit status $status (log $log); last lines:"
        tail -n 60 "$log"
        echo "$name: reproducers in $work/artifacts/:"
        ls -l "$work/artifacts/"
    fi
    exit "$status"
    ;;
*)
    usage
    ;;
esac
