#!/usr/bin/env bash
# Runs every libFuzzer target for RUNS iterations from the seed corpus; exits non-zero on any
# crash, leak, sanitizer report or broken round-trip property.
#
#   tests/fuzz/run_fuzz.sh [BUILD_DIR] [RUNS]      (defaults: build/fuzz, 100000)
#
# BUILD_DIR is configured with the `fuzz` preset (clang++, ECSIM_FUZZ=ON) when it has no
# CMakeCache.txt yet; only the fuzz targets are built. Seeds live in tests/fuzz/corpus/<target>
# (frame: real frames from ../shared/pcap plus SOEM's first frame; mailbox: the SyncManager
# buffers of those captures plus hand-built CoE/SDO-information messages) and are copied to a
# scratch directory, so the run never writes into the repository.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$repo/build/fuzz}
runs=${2:-100000}
targets=(fuzz_frame fuzz_mailbox fuzz_esc)

case $build in /*) ;; *) build=$PWD/$build ;; esac
if ! [[ $runs =~ ^[0-9]+$ ]]; then
  echo "usage: $0 [BUILD_DIR] [RUNS]" >&2
  exit 2
fi

if [[ ! -f $build/CMakeCache.txt ]]; then
  (cd "$repo" && cmake --preset fuzz -B "$build")
fi
cmake --build "$build" --target fuzz_targets

work=$(mktemp -d "${TMPDIR:-/tmp}/ecsim-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT

status=0
for target in "${targets[@]}"; do
  binary=$build/tests/fuzz/$target
  if [[ ! -x $binary ]]; then
    echo "run_fuzz: $binary was not built (is the compiler clang and ECSIM_FUZZ ON?)" >&2
    exit 1
  fi
  seeds=$repo/tests/fuzz/corpus/${target#fuzz_}
  corpus=$work/$target
  mkdir -p "$corpus" "$work/artifacts-$target"
  if [[ -d $seeds ]]; then cp "$seeds"/* "$corpus"/; fi
  log=$work/$target.log
  start=$SECONDS
  rc=0
  (cd "$work" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$binary" -runs="$runs" -max_len=2048 -seed=1 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts-$target/" "$corpus") >"$log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]] || grep -qE 'runtime error|ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)' "$log"; then
    echo "run_fuzz: $target FAILED (exit $rc); log tail:" >&2
    tail -n 40 "$log" >&2
    for artifact in "$work/artifacts-$target"/*; do
      [[ -e $artifact ]] || continue
      cp "$artifact" "$build/" && echo "run_fuzz: reproducer kept as $build/$(basename "$artifact")" >&2
    done
    status=1
  else
    echo "run_fuzz: $target ok: $(grep -E '^(Done|stat::number_of_executed_units)' "$log" | head -1)" \
      "in $((SECONDS - start)) s"
  fi
done
exit $status
