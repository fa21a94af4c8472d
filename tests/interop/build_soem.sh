#!/usr/bin/env bash
# Builds SOEM with the shared script, then the interop tests' own SOEM client
# (sdo_abort_client.c) against each version's libsoem.a, as a separate program in
# OUT/bin-v1 and OUT/bin-v2, and the tests' v1.4.0-only masters given after it (output_client.c,
# for `ecsim ctl get`; cia402_client.c, a CiA 402 enable sequence and CSP move) into
# OUT/bin-v1/<name>. A missing script is a failure under CI=true only.
# usage: build_soem.sh SHARED_SCRIPT OUT_DIR CLIENT_SOURCE [V1_CLIENT_SOURCE...]
set -euo pipefail
script=$1 out=$2 client=$3
shift 3
if [ ! -f "$script" ]; then
  if [ "${CI:-}" = "true" ]; then echo "missing $script (../shared)" >&2; exit 1; fi
  echo "shared SOEM build script not found: interop tests will skip"; exit 0
fi
bash "$script" "$out"
v1=$out/src-v1.4.0 v2=$out/src-v2.0.0
cc -O2 -Wall -Werror -I"$v1/soem" -I"$v1/osal" -I"$v1/osal/linux" -I"$v1/oshw/linux" \
   -o "$out/bin-v1/sdo_abort_client" "$client" "$out/build-v1.4.0/libsoem.a" -lpthread -lrt
cc -O2 -Wall -Werror -DSOEM_V2 -I"$v2/include" -I"$out/build-v2.0.0/include" -I"$v2/osal" \
   -I"$v2/osal/linux" -I"$v2/oshw/linux" \
   -o "$out/bin-v2/sdo_abort_client" "$client" "$out/build-v2.0.0/libsoem.a" -lpthread -lrt
for source in "$@"; do
  cc -O2 -Wall -Werror -I"$v1/soem" -I"$v1/osal" -I"$v1/osal/linux" -I"$v1/oshw/linux" \
     -o "$out/bin-v1/$(basename "$source" .c)" "$source" "$out/build-v1.4.0/libsoem.a" -lpthread -lrt
done
echo "sdo_abort_client built: $out/bin-v1 $out/bin-v2; v1.4.0 clients: $*"
