// The master's side of a configuration file (config/master_config.hpp): the identity check
// of the scanned bus against the expected slaves, and the ENI init commands per transition.
// Master::start() and requestState() call these; they are free functions so tests and tools
// can run them on their own.
#pragma once

#include <vector>

#include "config/master_config.hpp"
#include "master/batch.hpp"
#include "master/pdo_config.hpp"
#include "master/process_image.hpp"
#include "master/slave_info.hpp"
#include "master/variables.hpp"
#include "protocol/al_status.hpp"

namespace ecsim::master {

// The configuration types live in config/ (the readers); the master uses them by these names.
using ecsim::ExpectedSlave;
using ecsim::loadMasterConfig;
using ecsim::MasterConfig;
using ecsim::parseMasterConfig;

// What checkIdentities compares. Vendor ID and product code always, the revision where the
// configuration gives one; the serial number only when asked, as IgH (a slave configuration
// names vendor and product) and TwinCAT (serial number check off unless enabled) do, so an
// ENI exported from one bus configures another bus of the same devices.
struct IdentityCheck {
  bool serial{false};
};

// Compares the bus with the configuration: kNotFound when the slave counts differ,
// kInvalidArgument naming each slave whose identity differs (position, station, what was
// expected and found, the configuration file and line).
Status checkIdentities(const MasterConfig& config, const std::vector<SlaveInfo>& slaves,
                       IdentityCheck check = {});

// The AL state letter an ENI transition uses (I, P, B, S, O).
char eniStateLetter(AlState state);

// The register init commands of `slave` for the transition from -> to, as datagrams added to
// `batch` (writes to AL control 0x0120 are left out: the master's state machine does them).
// Returns the number added; `lines` (if given) gets each added command's ENI line.
std::size_t addEniRegisterCmds(DatagramBatch& batch, const EniSlave& slave, char from, char to,
                               std::vector<int>* lines = nullptr);

// The CoE init commands of `slave` for the transition from -> to.
std::vector<const EniCoeCmd*> eniCoeCmds(const EniSlave& slave, char from, char to);

// ---- the ENI's cyclic frames (Config/Cyclic/Frame/Cmd) ------------------------------------
//
// A master configured from an ENI with <Cyclic> sends what the ENI says: each <Frame> one
// cached frame, each <Cmd> one datagram of its command (LRW/LRD/LWR, or APRD/FPRD/BRD/...,
// ARMW/FRMW for the DC reference) and address, DataLength bytes, checked against <Cnt>, sent
// only in the states its <State> list names. The result is the same ProcessImageLayout the
// master plans itself (master/process_image.hpp), so CyclicExchange runs both.
//
// Where the slaves' data lies: the master's image is the logical address space (outputs first,
// then inputs, from the lowest logical address an ENI slave uses); each slave's SMs go to the
// logical addresses of its <ProcessData> <Send>/<Recv> ranges. ENI process-image bit offsets
// (those ranges' BitStart, <Variable> BitOffs) are read one of two ways, decided for the whole
// file:
//   - ETG.2100 images: every logical Cmd's OutputOffs/InputOffs (bytes) plus its DataLength lie
//     within the <Outputs>/<Inputs> ByteSize: the images are copies of the Cmds' data at those
//     offsets (TwinCAT lays them out like the frames, so the first Cmd's data is at 26), and an
//     image bit maps through the Cmd that covers it to a logical address;
//   - logical images (ecsim's `ecmaster xml`, examples/eni): bit offsets are logical bit
//     addresses, and OutputOffs/InputOffs, when given, must be the data's offset in the frame.
// Errors name the ENI file and line: a Cmd the master cannot send, a frame overflowing, data
// outside the image, a <Cnt> that cannot be right (a logical Cmd's must be the ESC rule's sum:
// 2 per slave whose outputs it writes, 1 per slave whose inputs it reads; another Cmd's at
// most what the slaves it addresses can add).

// The ENI's layout when `config` is an ENI with <Cyclic>, else planProcessImage().
Result<ProcessImageLayout> planLayout(const std::optional<MasterConfig>& config,
                                      const std::vector<SlaveInfo>& slaves,
                                      const std::vector<SlaveProcessData>& processData,
                                      const LayoutOptions& options = {});
Result<ProcessImageLayout> planEniLayout(const EniConfig& eni, const std::vector<SlaveInfo>& slaves,
                                         const std::vector<SlaveProcessData>& processData,
                                         const LayoutOptions& options = {});

// Adds the ENI's <ProcessImage> variables under their ENI names ("Drive1.TxPDO.Statusword")
// to `variables` (the master's own names stay): typed like the PDO entry at the same bits, else
// by the ENI DataType. Variables outside logical data (ETG.2100 images) are left out.
Status addEniVariables(std::vector<VariableInfo>& variables, const EniConfig& eni,
                       const ProcessImageLayout& layout);

}  // namespace ecsim::master
