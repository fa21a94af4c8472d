"""SOEM v1.4.0's slaveinfo over a veth pair against a network served from Python: the served
network is made and watched in this process (net.serve on the simulator's end, inside a private
network namespace), SOEM runs on the master's end under `ip netns exec`. SOEM's samples exit 0
whatever happens, so the checks are what the slaves saw: slaveinfo maps the process data and
asks for SAFE_OP (ec_config_map, ec_statecheck), and SOEM gives slave n the configured station
address 0x1000 + n, n from 1 (EC_NODEOFFSET; ESC datasheet section II, register 0x0010).

Needs root (netns, veth, raw sockets) and SOEM built by the soem_build test (ECSIM_SOEM_DIR);
without them the test skips, and fails under CI=true."""
import os
import shutil
import struct
import subprocess
import time

import pytest

import ecsim
from conftest import ci_mode

MASTER_FIFO = 70  # below the serving thread's 80, as tests/interop/soem_support.hpp
SERVER_FIFO = 80


def _missing(why):
    if ci_mode():
        pytest.fail(f"CI=true and {why}")
    pytest.skip(why)


def _slaveinfo():
    soem = os.environ.get("ECSIM_SOEM_DIR", "")
    path = os.path.join(soem, "bin-v1", "slaveinfo")
    if not os.path.exists(path):
        _missing(f"SOEM not built: no {path} (ctest's soem_build, ../shared/tools/build-soem.sh)")
    return path


def test_soem_slaveinfo_brings_the_python_served_network_to_safeop(ecsim_topology):
    slaveinfo = _slaveinfo()
    net = ecsim.Network(ecsim_topology, real_time=True)
    try:
        veth = ecsim.VethNamespace()
    except RuntimeError as e:
        _missing(f"no network namespace: {e}")
    rt = ["chrt", "-f", str(MASTER_FIFO)] if shutil.which("chrt") else []
    seen = set()
    with veth, net.serve(iface=veth.simulator_iface, netns=veth.name, rt_priority=SERVER_FIFO):
        proc = subprocess.Popen(["ip", "netns", "exec", veth.name, *rt, slaveinfo,
                                 veth.master_iface], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
        try:
            deadline = time.monotonic() + 60
            while proc.poll() is None and time.monotonic() < deadline:
                seen.add(net.slave("Drive1").state)
                time.sleep(0.0005)
        finally:
            if proc.poll() is None:
                proc.kill()
            out = proc.communicate()[0]
        stations = [struct.unpack("<H", net.slave(i).read_registers(0x0010, 2))[0]
                    for i in range(net.slave_count)]
    assert f"{net.slave_count} slaves found and configured" in out, out
    assert "SAFEOP" in seen, (seen, out)
    assert stations == [0x1001 + i for i in range(net.slave_count)], out
