#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (run as root):
#   ./run.sh demo   install what is missing, build, run `ecsim demo`
#   ./run.sh test   install what is missing, build (default + asan presets), run every test
# Both are idempotent: packages already present are not reinstalled, builds are incremental.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

packages=(
  build-essential cmake ninja-build g++ clang libclang-rt-14-dev pkg-config
  libgtest-dev libgmock-dev libbenchmark-dev
  libtinyxml2-dev libpcap-dev libcli11-dev libfmt-dev libspdlog-dev nlohmann-json3-dev
  libeigen3-dev libre2-dev tshark gnuplot-nox iproute2 iputils-ping ethtool procps libxml2-utils
  file dpkg-dev pybind11-dev python3-dev python3-pytest
)

install_missing() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "run.sh: installing ${missing[*]}"
    if [ "$(id -u)" -ne 0 ]; then echo "run.sh: run as root to install packages" >&2; exit 1; fi
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
}

build() {  # build PRESET
  cmake --preset "$1" >/dev/null
  cmake --build --preset "$1"
}

# timed WHAT COMMAND...: runs COMMAND, then says how long it took (CI keeps the whole run
# under 40 minutes; these lines say where the time went).
timed() {
  local what=$1 start=$SECONDS
  shift
  "$@"
  echo "run.sh: $what took $((SECONDS - start)) s"
}

case "${1:-}" in
  demo)
    install_missing
    build default
    ./build/default/tools/ecsim/ecsim demo --out ecsim-demo
    ;;
  test)
    timed "installing" install_missing
    timed "the default build" build default
    timed "the default tests" ctest --preset default -j2
    timed "the asan build" build asan
    timed "the asan tests" env ASAN_OPTIONS=detect_leaks=1 ctest --preset asan -j2
    timed "fuzzing (build and runs)" bash tests/fuzz/run_fuzz.sh build/fuzz 100000
    ;;
  *)
    echo "usage: $0 demo|test" >&2
    exit 2
    ;;
esac
