#!/bin/sh
# The Debian package as a user meets it (issue #19): `cpack -G DEB` of this build tree, its
# control fields checked (Depends names packages of this Debian system, installed size), then
# unpacked into a scratch root (dpkg-deb -x: the system is not touched) and used with the source
# and build trees hidden, in a private mount and network namespace: `ecsim --version`,
# `ecsim demo`, `ecsim replay` of the installed capture, `ecsim serve --veth` answering the
# package's own `ecmaster`, and the installed examples/user-project built against the unpacked
# headers and CMake package.
# Needs root (namespaces); under CI=true a missing capability is a failure, otherwise a skip
# (exit 77). Usage: deb_test.sh BUILD_DIR SOURCE_DIR VERSION
set -eu
build=$1 source=$2 version=$3
fail() { echo "deb_test: $*" >&2; exit 1; }
if [ "$(id -u)" != 0 ] || ! command -v unshare >/dev/null; then
  [ "${CI:-}" = true ] && fail "CI=true and the package test needs root and unshare"
  echo "deb_test: needs root and unshare: skipped"; exit 77
fi
work=$(mktemp -d /tmp/ecsim-deb.XXXXXX)
trap 'rm -rf "$work"' EXIT INT TERM

# The package, from what this build tree installs.
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/pkg" >"$work/cpack.log" 2>&1 ||
  { cat "$work/cpack.log"; fail "cpack failed"; }
deb="$work/pkg/ecsim_${version}_amd64.deb"
[ -f "$deb" ] || fail "no $deb (found: $(ls "$work/pkg"))"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
# Every dependency is a Debian package present here (the tools run on this system).
for p in $(echo "$depends" | tr ',' '\n' | sed 's/(.*)//; s/|.*//' | tr -d ' '); do
  dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q "install ok installed" ||
    fail "Depends names $p, which is not an installed Debian package"
done
for p in libc6 libfmt9 libtinyxml2-9 libpcap0.8; do
  echo "$depends" | grep -q "$p" || fail "Depends lacks $p: $depends"
done
size=$(dpkg-deb -f "$deb" Installed-Size)
echo "Installed-Size: $size KiB"
[ "$size" -lt 61440 ] || fail "installed size $size KiB is not under 60 MB"
dpkg-deb -x "$deb" "$work/root"
usr="$work/root/usr"
file "$usr/bin/ecsim" | grep -q ", stripped" || fail "bin/ecsim is not stripped"

# Hidden trees: the build tree first (it may lie inside the source tree).
cat >"$work/inside.sh" <<'INSIDE'
set -eu
usr=$1 work=$2
"$usr/bin/ecsim" --version
"$usr/bin/ecmaster" --version
"$usr/bin/ecsim" demo --out "$work/demo" | tail -1
[ -s "$work/demo/demo.pcap" ]
# The installed capture against the installed demo topology (the replay's default).
"$usr/bin/ecsim" replay --ignore-dc-time "$usr/share/ecsim/captures/soem-slaveinfo-demo.pcap" \
  >"$work/replay.log" 2>&1 || { cat "$work/replay.log"; exit 1; }
tail -2 "$work/replay.log"
ip link set lo up
"$usr/bin/ecsim" serve --veth debt >"$work/serve.log" 2>&1 &
serve=$!
i=0
until grep -q "ecsim: serving" "$work/serve.log"; do
  i=$((i + 1)); [ $i -lt 200 ] || { cat "$work/serve.log"; exit 1; }
  sleep 0.05
done
"$usr/bin/ecmaster" --iface debt slaves >"$work/slaves.txt" 2>&1 || { cat "$work/slaves.txt"; exit 1; }
kill -INT $serve; wait $serve
cat "$work/slaves.txt"
grep -q "Drive1\|ECS7201" "$work/slaves.txt"
cp -r "$usr/share/ecsim/examples/user-project" "$work/user-project"
cmake -S "$work/user-project" -B "$work/user-build" -DCMAKE_PREFIX_PATH="$usr" \
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >"$work/user.log" 2>&1 &&
  cmake --build "$work/user-build" >>"$work/user.log" 2>&1 &&
  ctest --test-dir "$work/user-build" --output-on-failure >>"$work/user.log" 2>&1 ||
  { cat "$work/user.log"; exit 1; }
echo "user project against the package: ok"
# The Python module from the package, its pytest fixtures on the installed demo network.
printf '%s\n' 'def test_installed(ecsim_network, ecsim_master):' \
  '    assert ecsim_network.slave("DO1").state == "OP"' >"$work/test_installed.py"
cd "$work" && PYTHONPATH="$usr/lib/python3/dist-packages" PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m pytest \
  -p ecsim.pytest_plugin -p no:cacheprovider -q "$work/test_installed.py"
INSIDE
unshare --mount --net --propagation private sh -c '
  mount -t tmpfs ecsim-hidden "$1" && mount -t tmpfs ecsim-hidden "$2" && exec sh "$3" "$4" "$5"' \
  hide "$build" "$source" "$work/inside.sh" "$usr" "$work" || fail "the unpacked package failed (above)"
echo "deb_test: ok"
