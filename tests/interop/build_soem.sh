#!/usr/bin/env bash
# Builds SOEM with the shared script, then the interop tests' own SOEM clients as separate
# programs: the ones given before --v1-only against each version's libsoem.a, into
# OUT/bin-v1/<name> and OUT/bin-v2/<name> (sdo_abort_client.c, SOEM's SDO calls; io_client.c,
# an IO master printing its process image; red_client.c, a cable-redundant master), the ones
# after it against v1.4.0 only into OUT/bin-v1/<name> (output_client.c, for `ecsim ctl get`;
# cia402_client.c, a CiA 402 enable sequence and CSP move). A missing script is a failure
# under CI=true only.
# usage: build_soem.sh SHARED_SCRIPT OUT_DIR CLIENT_SOURCE... [--v1-only V1_CLIENT_SOURCE...]
set -euo pipefail
script=$1 out=$2
shift 2
both=() v1only=()
while [ $# -gt 0 ] && [ "$1" != "--v1-only" ]; do both+=("$1"); shift; done
if [ $# -gt 0 ]; then shift; v1only=("$@"); fi
if [ ! -f "$script" ]; then
  if [ "${CI:-}" = "true" ]; then echo "missing $script (../shared)" >&2; exit 1; fi
  echo "shared SOEM build script not found: interop tests will skip"; exit 0
fi
bash "$script" "$out"
v1=$out/src-v1.4.0 v2=$out/src-v2.0.0
build_v1() {
  cc -O2 -Wall -Werror -I"$v1/soem" -I"$v1/osal" -I"$v1/osal/linux" -I"$v1/oshw/linux" \
     -o "$out/bin-v1/$(basename "$1" .c)" "$1" "$out/build-v1.4.0/libsoem.a" -lpthread -lrt
}
for source in "${both[@]}"; do
  build_v1 "$source"
  cc -O2 -Wall -Werror -DSOEM_V2 -I"$v2/include" -I"$out/build-v2.0.0/include" -I"$v2/osal" \
     -I"$v2/osal/linux" -I"$v2/oshw/linux" \
     -o "$out/bin-v2/$(basename "$source" .c)" "$source" "$out/build-v2.0.0/libsoem.a" \
     -lpthread -lrt
done
for source in "${v1only[@]}"; do build_v1 "$source"; done
echo "clients built: ${both[*]} in $out/bin-v1 and $out/bin-v2; ${v1only[*]} in $out/bin-v1"
