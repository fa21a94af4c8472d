"""pytest fixtures for ecsim (docs/python.md). Load with `python3 -m pytest -p ecsim.pytest_plugin`.

ecsim_topology  the topology file: $ECSIM_TOPOLOGY, else the installed demo network
ecsim_network   ecsim.Network(ecsim_topology), in process on virtual time, fresh per test
ecsim_master    ecsim's master on ecsim_network, started (every slave in OP)
"""
import os
import pathlib

import pytest

import ecsim


def _installed_demo():
    # /usr/lib/python3/dist-packages/ecsim -> /usr/share/ecsim/topologies/demo.xml
    return pathlib.Path(__file__).resolve().parents[4] / "share" / "ecsim" / "topologies" / "demo.xml"


@pytest.fixture
def ecsim_topology():
    path = os.environ.get("ECSIM_TOPOLOGY") or str(_installed_demo())
    if not os.path.exists(path):
        raise FileNotFoundError(f"ecsim_topology: no topology file {path} (set ECSIM_TOPOLOGY)")
    return path


@pytest.fixture
def ecsim_network(ecsim_topology):
    return ecsim.Network(ecsim_topology)


@pytest.fixture
def ecsim_master(ecsim_network):
    master = ecsim.Master(ecsim_network)
    master.start()
    return master
