#!/usr/bin/env bash
# Runs every cargo-fuzz target of fuzz/ for a fixed time, one after the other, and records the
# figures (the results table is in docs/reliability.md).
#
#   scripts/fuzz_all.sh SECONDS [TARGET ...]
#
# Needs a nightly toolchain and cargo-fuzz (`rustup toolchain install nightly`,
# `cargo install cargo-fuzz`). Each target starts from a seed corpus: fuzz/seeds/<target>/
# (small files written by the library's own writers) plus the matching files of fixtures/ and
# tests/bad_inputs/. The growing corpus lives in fuzz/corpus/<target>/, crash inputs in
# fuzz/artifacts/<target>/, logs in fuzz/logs/<target>.log (all git-ignored).
#
# NO_BUILD=1 skips the build (use the binaries already in fuzz/target). An input running longer
# than 120 s is reported as a hang (libFuzzer -timeout; the `mesh` target meshes up to 415 cells).
#
# Output: one line per target in fuzz/logs/summary.tsv and on stdout:
#   target  seconds (wall time of the run)  total_execs  execs_per_s  crashes  exit_code  command
# The script exits non-zero if any target crashed.
set -u
cd "$(dirname "$0")/../fuzz"
secs=${1:?usage: scripts/fuzz_all.sh SECONDS [TARGET ...]}
shift
all=(geojson shapefile con xy red msh vtk_legacy vtk_xml plot3d decomposition_json region mesh)
[ $# -gt 0 ] && targets=("$@") || targets=("${all[@]}")
# Build once (cargo-fuzz default: release with debug assertions, AddressSanitizer).
[ -n "${NO_BUILD:-}" ] || cargo +nightly fuzz build >logs-build.txt 2>&1 || { cat logs-build.txt; exit 2; }
mkdir -p logs
bin=target/x86_64-unknown-linux-gnu/release
summary=logs/summary.tsv
[ -f "$summary" ] || printf 'target\tseconds\ttotal_execs\texecs_per_s\tcrashes\texit_code\tcommand\n' >"$summary"
status=0
for t in "${targets[@]}"; do
    corpus=corpus/$t
    seeds=logs/seeds-$t
    mkdir -p "$corpus" "$seeds" "artifacts/$t"
    rm -f "$seeds"/*
    [ -d "seeds/$t" ] && cp seeds/"$t"/* "$seeds"/ 2>/dev/null
    case $t in
        geojson) cp ../fixtures/regions/*.geojson ../tests/bad_inputs/*.geojson "$seeds"/ 2>/dev/null ;;
        decomposition_json) cp ../tests/bad_inputs/*decomposition*.json "$seeds"/ 2>/dev/null ;;
        msh) cp ../tests/bad_inputs/*.msh "$seeds"/ 2>/dev/null ;;
        vtk_legacy) cp ../tests/bad_inputs/*.vtk "$seeds"/ 2>/dev/null ;;
        con) cp ../tests/bad_inputs/*.con "$seeds"/ 2>/dev/null ;;
        shapefile) cp ../tests/bad_inputs/*.shp ../crates/unamalla-io/tests/data/pyshp/*.shp "$seeds"/ 2>/dev/null ;;
    esac
    before=$(find "artifacts/$t" -type f ! -name "slow-unit-*" | wc -l)
    # The binary cargo-fuzz built, run directly (equivalent to `cargo +nightly fuzz run $t
    # $corpus $seeds -- <flags>` without a rebuild check between targets).
    cmd="$bin/$t $corpus $seeds -max_total_time=$secs -max_len=8192 -rss_limit_mb=2048 -timeout=120 -print_final_stats=1 -artifact_prefix=artifacts/$t/"
    echo "== $t: $cmd" >&2
    t0=$SECONDS
    $cmd >"logs/$t.log" 2>&1
    rc=$?
    wall=$((SECONDS - t0))
    after=$(find "artifacts/$t" -type f ! -name "slow-unit-*" | wc -l)
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' | tail -1)
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' | tail -1)
    crashes=$((after - before))
    line=$(printf '%s\t%s\t%s\t%s\t%s\t%s\t%s' "$t" "$wall" "${execs:-?}" "${rate:-?}" "$crashes" "$rc" "$cmd")
    echo "$line" >>"$summary"
    echo "$line"
    if [ "$rc" -ne 0 ] || [ "$crashes" -ne 0 ]; then
        status=1
    fi
done
exit $status
