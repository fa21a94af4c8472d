"""ecsim's Python module against the demo network (examples/topologies/demo.xml: Coupler, DI1,
DO1, AI1, Drive1, Drive2), in process on virtual time with our master (fixtures from
ecsim.pytest_plugin, as embed/testing/network_fixture.hpp pairs them)."""
import struct

import pytest

import ecsim


def test_slaves_are_named_in_bus_order(ecsim_network):
    assert ecsim_network.slave_names() == ["Coupler", "DI1", "DO1", "AI1", "Drive1", "Drive2"]
    assert ecsim_network.slave("DO1").position == 2
    assert ecsim_network.slave(2).name == "DO1"
    assert ecsim_network.slave("DO1").state == "INIT"  # power-up state (ETG.1000.6 ESM)


def test_virtual_time_advances_only_when_run(ecsim_network):
    before = ecsim_network.now_ns
    ecsim_network.run_for(2.0)
    assert ecsim_network.now_ns - before == 2_000_000


def test_master_output_reaches_the_slave(ecsim_network, ecsim_master):
    do1 = ecsim_network.slave("DO1")
    assert do1.state == "OP"
    assert do1["Output 3"] is False
    ecsim_master["DO1.Output 3"] = True
    ecsim_master.cycle(check=True)
    ecsim_master.cycle(check=True)
    assert do1["Output 3"] is True
    assert do1["Output 2"] is False  # only the bit written (LRW image, ETG.1000.4 bit order)
    assert do1["0x7000:03"] is True  # the same entry by index (the demo DO: 0x7000:ch)


def test_slave_input_reaches_the_master(ecsim_network, ecsim_master):
    ecsim_network.slave("DI1")["Input 3"] = True
    ecsim_master.cycle(check=True)
    ecsim_master.cycle(check=True)
    assert ecsim_master["DI1.Input 3"] is True
    assert ecsim_master["DI1.Input 4"] is False


def test_dictionary_registers_and_sdo_agree(ecsim_network, ecsim_master):
    drive = ecsim_network.slave("Drive1")
    ecsim_master.cycle(check=True)
    statusword = drive.read_entry(0x6041, 0)
    assert ecsim_master["Drive1.Statusword"] == statusword == drive["Statusword"]
    assert ecsim_master.sdo_read(4, 0x6041, 0) == struct.pack("<H", statusword)
    # SDO download, seen in the slave's dictionary (0x6065 following error window, CiA 402).
    assert drive.read_entry(0x6065, 0) != 4321
    ecsim_master.sdo_write(4, 0x6065, 0, struct.pack("<I", 4321))
    assert drive.read_entry(0x6065, 0) == 4321
    # Registers (ESC datasheet section II): AL status 0x0130 says OP (8); our master gave the
    # slave the configured station address 0x1001 + position (0x0010).
    al_status = struct.unpack("<H", drive.read_registers(0x0130, 2))[0]
    assert al_status & 0x0F == 8
    assert struct.unpack("<H", drive.read_registers(0x0010, 2))[0] == 0x1001 + 4


def test_link_down_is_noticed_by_the_master(ecsim_network, ecsim_master):
    assert ecsim_network.fault("link-down slave=Drive2 port=0") == "link down at Drive2 port 0"
    for _ in range(50):
        ecsim_master.cycle()
    assert any("'Drive2') lost" in e for e in ecsim_master.events), ecsim_master.events


def test_every_fault_verb_parses_and_the_al_error_reaches_the_slave(ecsim_network, ecsim_master):
    assert {"link-down", "power-cycle", "al-error", "sdo-abort", "input"} <= set(
        ecsim.Network.fault_verbs())
    ecsim_network.fault("al-error slave=DO1 code=0x001B state=SAFEOP")
    ecsim_network.run_for(1.0)
    do1 = ecsim_network.slave("DO1")
    assert do1.state == "SAFEOP"
    assert do1.al_status_code == 0x001B  # sync manager watchdog (ETG.1000.6 Table 11)


def test_unknown_names_say_the_closest(ecsim_network, ecsim_master):
    with pytest.raises(KeyError, match="closest: Output 3"):
        ecsim_network.slave("DO1")["Outptu 3"]
    with pytest.raises(KeyError, match="closest: DO1.Output 3"):
        ecsim_master["DO1.Outptu 3"]
    with pytest.raises(KeyError, match="DO7"):
        ecsim_network.slave("DO7")
    with pytest.raises(ValueError, match="did you mean 'link-down'"):
        ecsim_network.fault("link-dwn slave=DO1 port=0")
    with pytest.raises(ValueError, match="did you mean 'DO1'"):
        ecsim_network.fault("power-off slave=DOO1")


def test_a_missing_topology_names_the_file():
    with pytest.raises(Exception, match="/nonexistent/net.xml"):
        ecsim.Network("/nonexistent/net.xml")


def test_serving_needs_real_time(ecsim_network):
    with pytest.raises(RuntimeError, match="real_time=True"):
        ecsim_network.serve(iface="lo")
