// An ENI (config/eni.hpp) describing the bus a master has scanned and configured: identity,
// station addresses, mailboxes, process data (SMs, PDOs, bit ranges in the logical image),
// wiring (PreviousPort), DC, the cyclic LRW frames and the process image variables. What
// `ecmaster xml` writes; the master reads it back with loadConfig (round trip).
#pragma once

#include "config/eni.hpp"
#include "master/master.hpp"

namespace ecsim::master {

// `master` must have scanned; with process data configured (configureProcessData or start)
// the ENI also has ProcessData, Cyclic and ProcessImage.
EniConfig eniFromMaster(const Master& master);

// The port of slave `position`'s parent it is connected to: the parent's open ports other than
// 0 are taken by its children in position order, in the processing order 3, 1, 2. nullopt for
// the first slave (its parent is the master) or when the ports do not add up.
std::optional<unsigned> parentPort(const std::vector<SlaveInfo>& slaves, std::size_t position);

}  // namespace ecsim::master
