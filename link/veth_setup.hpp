// `ecsim net up/down`: a named veth pair for an EtherCAT master application to use, with the
// settings EtherCAT traffic needs (up, IPv6 off so the kernel sends nothing of its own, no
// offloads that could alter frames, MTU for 1514-byte frames), optionally inside a network
// namespace of its own. What was created is recorded in a state file, so `down` removes
// exactly that, and a later `up` of the same name cleans up after a run that was killed.
// Privileged set-up only: nothing here is used by the simulation itself.
#pragma once

#include <filesystem>
#include <string>

#include "protocol/result.hpp"

namespace ecsim {

struct VethSetup {
  std::string name;                // the pair's name; the master's interface is called `name`
  std::string masterInterface;     // for the application: `name`
  std::string simulatorInterface;  // for `ecsim serve --iface`: `name` + "s"
  std::string netns;               // namespace holding both ends ("" = the current one)
};

struct VethSetupOptions {
  bool ownNamespace{false};  // --netns: create namespace "ecsim-<name>" for both ends
  std::filesystem::path stateDir{"/run/ecsim"};
};

// Names are 1-14 characters of [A-Za-z0-9_-] (interface names are at most 15).
Result<VethSetup> vethUp(const std::string& name, const VethSetupOptions& options = {});
// Removes what vethUp(name) created; kNotFound when nothing is recorded under that name.
Status vethDown(const std::string& name, const VethSetupOptions& options = {});

}  // namespace ecsim
