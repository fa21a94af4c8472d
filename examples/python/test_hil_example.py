"""A HIL-style test of a master application in Python with ecsim's pytest fixtures
(docs/python.md). Run: python3 -m pytest -p ecsim.pytest_plugin examples/python"""


def test_output_reaches_the_terminal_and_a_pulled_cable_is_noticed(ecsim_network, ecsim_master):
    do1 = ecsim_network.slave("DO1")           # the simulated terminal, seen from its side
    assert do1.state == "OP"                   # ecsim_master started: every slave in OP

    ecsim_master["DO1.Output 3"] = True        # the application sets an output
    for _ in range(2):
        ecsim_master.cycle(check=True)         # 1 ms cycles on virtual time
    assert do1["Output 3"] is True             # the terminal drives it

    ecsim_network.slave("DI1")["Input 1"] = True   # a sensor switches
    ecsim_master.cycle(check=True)
    ecsim_master.cycle(check=True)
    assert ecsim_master["DI1.Input 1"] is True

    ecsim_network.fault("link-down slave=Drive2 port=0")   # pull the cable in front of Drive2
    for _ in range(50):
        ecsim_master.cycle()
    assert any("'Drive2') lost" in event for event in ecsim_master.events)
