#!/usr/bin/env bash
# Runs libFuzzer targets for RUNS iterations each from their seed corpora; exits non-zero on any
# crash, leak, sanitizer report, timeout or broken round-trip property.
#
#   tests/fuzz/run_fuzz.sh [BUILD_DIR] [RUNS] [TARGET...]    (defaults: build/fuzz, 100000, all)
#
# BUILD_DIR is configured with the `fuzz` preset (clang++, ECSIM_FUZZ=ON) when it has no
# CMakeCache.txt yet; only the targets named are built (none with ECSIM_FUZZ_NO_BUILD=1).
# docs/fuzzing.md says what each target reads and how to run a long campaign.
#
# Seeds are gathered at run time into a scratch directory (the run never writes into the
# repository or ../shared): the repository's own ones in tests/fuzz/corpus/<target> (frames,
# mailboxes, control lines, a master configuration), the project's examples, scenarios and
# topologies, and the real files of ECSIM_SHARED (default: ../shared next to the repository:
# esi/, eeprom/, pcap/). Files longer than the target's max_len are left out for the XML
# targets (a cut XML file only tests the parser's first error), cut by libFuzzer otherwise.
# The targets run side by side, one per core (ECSIM_FUZZ_JOBS=N sets how many at a time).
# The XML targets get a dictionary: tests/fuzz/xml.dict plus the element and attribute names
# of their seeds.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$repo/build/fuzz}
runs=${2:-100000}
shift $(($# < 2 ? $# : 2))
all_targets=(fuzz_frame fuzz_mailbox fuzz_esc fuzz_esi fuzz_topology fuzz_eni fuzz_scenario
             fuzz_master_config fuzz_control fuzz_sii fuzz_pcap fuzz_esc_blocks)
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then targets=("${all_targets[@]}"); fi
shared=${ECSIM_SHARED:-$repo/../shared}

case $build in /*) ;; *) build=$PWD/$build ;; esac
if ! [[ $runs =~ ^[0-9]+$ ]]; then
  echo "usage: $0 [BUILD_DIR] [RUNS] [TARGET...]" >&2
  exit 2
fi
for target in "${targets[@]}"; do
  if ! [[ " ${all_targets[*]} " == *" $target "* ]]; then
    echo "run_fuzz: unknown target '$target' (targets: ${all_targets[*]})" >&2
    exit 2
  fi
done
if [[ ! -d $shared ]]; then
  echo "run_fuzz: $shared not found: the real ESI, EEPROM and capture seeds are left out" >&2
fi

# The targets run side by side, ECSIM_FUZZ_JOBS at a time (default: one per core; each run is
# one process on one core), and report in the order given.
parallel=${ECSIM_FUZZ_JOBS:-$(nproc)}
if ! [[ $parallel =~ ^[1-9][0-9]*$ ]]; then
  echo "run_fuzz: ECSIM_FUZZ_JOBS must be a positive number, not '$parallel'" >&2
  exit 2
fi

# ECSIM_FUZZ_NO_BUILD=1 runs what is built: for campaigns of several targets at once in one
# build folder (two builds at once in one folder would race).
if [[ ${ECSIM_FUZZ_NO_BUILD:-0} != 1 ]]; then
  if [[ ! -f $build/CMakeCache.txt ]]; then
    (cd "$repo" && cmake --preset fuzz -B "$build")
  fi
  cmake --build "$build" --target "${targets[@]}"
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/ecsim-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT

# Per target: the largest input, whether it is XML (dictionary, whole seed files only), and
# its seed files besides tests/fuzz/corpus/<name>.
# The lengths keep each target near 1,000 runs a second or more (an XML file costs in proportion
# to its length): the ESI target takes the real files up to 16 KiB (six of them), the ENI
# target the 24 KiB example, the master-configuration target its own small seeds (the ENI
# reader has its own target).
max_len() {
  case $1 in
    fuzz_frame | fuzz_mailbox | fuzz_esc) echo 2048 ;;
    fuzz_master_config) echo 4096 ;;
    fuzz_esc_blocks) echo 64 ;;  # an SM and an FMMU channel and the fields of one of each
    fuzz_control) echo 512 ;;  # a few lines: each costs a verb's work on the network
    fuzz_sii | fuzz_scenario) echo 8192 ;;
    fuzz_esi | fuzz_topology | fuzz_pcap) echo 16384 ;;
    fuzz_eni) echo 32768 ;;
  esac
}
is_xml() {
  case $1 in
    fuzz_esi | fuzz_topology | fuzz_eni | fuzz_scenario | fuzz_master_config) return 0 ;;
  esac
  return 1
}
seed_files() {
  case $1 in
    fuzz_esi) ls "$repo"/examples/esi/*.xml "$shared"/esi/*.xml ;;
    fuzz_topology) ls "$repo"/examples/topologies/*.xml "$repo"/examples/topologies/*/*.xml \
                      "$repo"/tests/interop/*.xml ;;
    fuzz_eni) ls "$repo"/examples/eni/*.xml ;;
    fuzz_scenario) ls "$repo"/scenarios/*.xml "$repo"/scenarios/*/*.xml ;;
    fuzz_sii) ls "$shared"/eeprom/*.bin "$shared"/eeprom/*.hex ;;
    fuzz_pcap) ls "$shared"/pcap/*.pcap "$shared"/pcap/*.pcapng ;;
  esac 2>/dev/null || true
}

# One target's run; its verdict goes to stdout/stderr, its exit status says whether it passed.
fuzz_one() {
  local target=$1
  binary=$build/tests/fuzz/$target
  if [[ ! -x $binary ]]; then
    echo "run_fuzz: $binary was not built (is the compiler clang and ECSIM_FUZZ ON?)" >&2
    return 1
  fi
  len=$(max_len "$target")
  corpus=$work/$target
  mkdir -p "$corpus" "$work/artifacts-$target"
  own=$repo/tests/fuzz/corpus/${target#fuzz_}
  if [[ -d $own ]]; then cp "$own"/* "$corpus"/; fi
  while IFS= read -r seed; do
    [[ -f $seed ]] || continue
    if is_xml "$target" && [[ $(stat -c %s "$seed") -gt $len ]]; then continue; fi
    cp "$seed" "$corpus/$(basename "$(dirname "$seed")")-$(basename "$seed")"
  done < <(seed_files "$target")
  options=()
  if is_xml "$target"; then
    dict=$work/$target.dict
    cp "$repo/tests/fuzz/xml.dict" "$dict"
    cat "$corpus"/* | grep -aoE '<[A-Za-z_][A-Za-z0-9_.:-]*|[A-Za-z_][A-Za-z0-9_.:-]*="' |
      sort -u | sed 's/"/\\"/g; s/.*/"&"/' >>"$dict"
    options+=(-dict="$dict")
  elif [[ $target == fuzz_control ]]; then
    # Its network lives across inputs by design, so nearly every input leaves allocations
    # behind and libFuzzer's per-input leak check (the input run again, then a LeakSanitizer
    # scan) would halve the speed for nothing; leaks are still reported when the run ends.
    options+=(-dict="$repo/tests/fuzz/control.dict" -detect_leaks=0)
  fi
  log=$work/$target.log
  start=$SECONDS
  rc=0
  (cd "$work" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$binary" -runs="$runs" -max_len="$len" -seed=7 -timeout=60 -print_final_stats=1 \
    "${options[@]}" -artifact_prefix="$work/artifacts-$target/" "$corpus") >"$log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]] || grep -qE 'runtime error|ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)' "$log"; then
    echo "run_fuzz: $target FAILED (exit $rc); log tail:" >&2
    tail -n 40 "$log" >&2
    for artifact in "$work/artifacts-$target"/*; do
      [[ -e $artifact ]] || continue
      cp "$artifact" "$build/" && echo "run_fuzz: reproducer kept as $build/$(basename "$artifact")" >&2
    done
    return 1
  else
    echo "run_fuzz: $target ok: $(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}')" \
      "runs, $(grep -E '^stat::peak_rss_mb' "$log" | awk '{print $2}') MB peak, $(ls "$corpus" | wc -l)" \
      "corpus files, in $((SECONDS - start)) s"
  fi
}

# The targets run side by side (ECSIM_FUZZ_JOBS, above) and report in the order given.
pids=()
for target in "${targets[@]}"; do
  while [[ $(jobs -rp | wc -l) -ge $parallel ]]; do wait -n || true; done
  fuzz_one "$target" >"$work/$target.out" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!targets[@]}"; do
  rc=0
  wait "${pids[$i]}" || rc=$?
  cat "$work/${targets[$i]}.out"
  [[ $rc -eq 0 ]] || status=1
done
exit $status
