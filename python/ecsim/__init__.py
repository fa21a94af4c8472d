"""ecsim: a simulated EtherCAT network in Python (docs/python.md).

    net = ecsim.Network("demo.xml")            # in process, on virtual time
    master = ecsim.Master(net); master.start() # ecsim's master, in process
    master["DO1.Output 3"] = True; master.cycle()
    assert net.slave("DO1")["Output 3"] is True
    net.fault("link-down slave=Drive2 port=0")  # any scenario fault action

    net = ecsim.Network("demo.xml", real_time=True)
    with ecsim.VethNamespace() as ns, net.serve(iface=ns.simulator_iface, netns=ns.name):
        ...                                     # a master on ns.master_iface inside ns.name
"""
from ._ecsim import Master, Network, Serving, Slave, VethNamespace

__all__ = ["Master", "Network", "Serving", "Slave", "VethNamespace"]
