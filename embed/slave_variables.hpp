// The process-data entries of the simulated slaves by name, as a master names them
// (master/variables.hpp: "<slave>.<entry>", "DO1.Output 8"), for `ecsim serve`'s control
// socket and status and for the Python module. Taken from each slave's own PDO mapping (the layout its firmware copies,
// slavesim/process_data.hpp), the topology's slave names and the dictionary's entry names:
// a master configured from the same ESI names the same entries the same way.
#pragma once

#include <vector>

#include "master/variables.hpp"
#include "topology/segment.hpp"

namespace ecsim::embed {

// Every mapped entry of every slave in bus order (topology::busOrder); `position` is the bus
// position, `bitOffset` the entry's offset in its SyncManager. An entry name two PDOs of the
// slave share is "<pdo name>.<entry>" as in master::nameVariables; slaves of the same name
// are "<name>_<position>".
std::vector<master::VariableInfo> slaveVariables(topology::Segment& segment);

}  // namespace ecsim::embed
