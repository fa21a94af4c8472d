// The master's side of a configuration file (config/master_config.hpp): the identity check
// of the scanned bus against the expected slaves, and the ENI init commands per transition.
// Master::start() and requestState() call these; they are free functions so tests and tools
// can run them on their own.
#pragma once

#include <vector>

#include "config/master_config.hpp"
#include "master/batch.hpp"
#include "master/slave_info.hpp"
#include "protocol/al_status.hpp"

namespace ecsim::master {

// The configuration types live in config/ (the readers); the master uses them by these names.
using ecsim::ExpectedSlave;
using ecsim::loadMasterConfig;
using ecsim::MasterConfig;
using ecsim::parseMasterConfig;

// Compares the bus with the configuration: kNotFound when the slave counts differ,
// kInvalidArgument naming each slave whose identity differs (position, station, what was
// expected and found, the configuration file and line).
Status checkIdentities(const MasterConfig& config, const std::vector<SlaveInfo>& slaves);

// The AL state letter an ENI transition uses (I, P, B, S, O).
char eniStateLetter(AlState state);

// The register init commands of `slave` for the transition from -> to, as datagrams added to
// `batch` (writes to AL control 0x0120 are left out: the master's state machine does them).
// Returns the number added; `lines` (if given) gets each added command's ENI line.
std::size_t addEniRegisterCmds(DatagramBatch& batch, const EniSlave& slave, char from, char to,
                               std::vector<int>* lines = nullptr);

// The CoE init commands of `slave` for the transition from -> to.
std::vector<const EniCoeCmd*> eniCoeCmds(const EniSlave& slave, char from, char to);

}  // namespace ecsim::master
