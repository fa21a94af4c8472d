// The MII management interface (0x0510-0x0517, ESC datasheet section II; section I "MII
// management interface") and a simple PHY per MII port behind it, so that diagnostic tools that
// read link state over MDIO see what the topology says.
//
// A command written to 0x0511 (read or write, with PHY address 0x0512 and PHY register 0x0513)
// runs for one MDIO frame: 32 preamble bits and 32 frame bits at MDC no faster than 2.5 MHz
// (IEEE 802.3 clause 22.2.2.13/22.2.4.5), 25.6 us, during which 0x0510 shows busy (bit 15) with
// the command bits held and ECAT writes to 0x0510-0x0515 are ignored. A write command needs
// the write enable bit (0x0510 bit 0, cleared when a command completes) set; otherwise, or for the invalid command 11, the command error bit (14) is set. A read from a
// PHY address with no PHY behind it sets the read error bit (13) and reads all ones (MDIO is
// pulled up). A NOP command clears both error bits. While the PDI has the interface (0x0517
// bit 0) the ECAT side cannot write 0x0510-0x0515.
#include <algorithm>

#include "protocol/mii.hpp"
#include "slavesim/esc.hpp"
#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;
namespace {

constexpr SimTime kMdioFrameNs = 64 * 400;  // 64 MDC periods of 400 ns

// PHY identity: TI DP83848, the PHY the timing model takes for 100BASE-TX ports (esc_type.hpp);
// its PHYIDR1/PHYIDR2 reset values (DP83848 datasheet, registers 0x02/0x03).
constexpr std::uint16_t kPhyId1 = 0x2000;
constexpr std::uint16_t kPhyId2 = 0x5C90;
// Basic status abilities (IEEE 802.3 22.2.4.2): 100BASE-TX full/half duplex, 10BASE-T
// full/half duplex, auto-negotiation ability, extended capabilities.
constexpr std::uint16_t kStatusAbilities = 0x7809;
// Advertisement reset value: the same four modes, IEEE 802.3 selector field.
constexpr std::uint16_t kAdvertisementDefault = 0x01E1;
constexpr std::uint16_t kControlDefault =
    reg::phy::kControlSpeed100 | reg::phy::kControlAutoNegEnable | reg::phy::kControlFullDuplex;

constexpr std::uint16_t kMiiFirst = reg::kMiiControlStatus.address;

}  // namespace

void Esc::miiReset() {
  phys_.fill({kControlDefault, kAdvertisementDefault});
  miiPending_ = false;
  // The PHY address offset (pin configuration on the ET1100) is 0: port n's PHY at address n.
  writeLe16(memory_, kMiiFirst, 0);
}

bool Esc::phyPresent(std::uint8_t phyAddress, unsigned& port) const {
  const std::uint16_t control = reg16(kMiiFirst);
  const unsigned offset = (control & reg::mii::kPhyOffsetMask) >> reg::mii::kPhyOffsetShift;
  if (phyAddress < offset) return false;
  port = phyAddress - offset;
  if (port >= type_.maxPorts || port >= phys_.size()) return false;
  // Only MII ports have a PHY (port descriptor 0x0007: 11 = MII; EBUS ports have none).
  return ((memory_[reg::kPortDescriptor.address] >> (2 * port)) & 0x03) == 0x03;
}

std::uint16_t Esc::phyRead(unsigned port, std::uint8_t index) const {
  const PhyState& p = phys_[port];
  // Link as the topology has it: a cable connected at both ends and not cut by a fault
  // (Segment keeps 0x0110's physical link bits).
  const bool link = (reg16(reg::kDlStatus.address) & reg::dl_status::physicalLink(port)) != 0;
  switch (index) {
    case reg::phy::kControl:
      return p.control;
    case reg::phy::kStatus: {
      std::uint16_t status = kStatusAbilities;
      if (link) status |= reg::phy::kStatusLinkUp;
      if (link && (p.control & reg::phy::kControlAutoNegEnable) != 0) {
        status |= reg::phy::kStatusAutoNegComplete;
      }
      return status;
    }
    case reg::phy::kId1:
      return kPhyId1;
    case reg::phy::kId2:
      return kPhyId2;
    case reg::phy::kAdvertisement:
      return p.advertisement;
    case reg::phy::kLinkPartner:
      // The partner is another port like this one; nothing received without a link.
      return link ? static_cast<std::uint16_t>(reg::phy::kAcknowledge | kAdvertisementDefault) : 0;
    default:
      return 0;  // vendor and extended registers: not modelled
  }
}

void Esc::phyWrite(unsigned port, std::uint8_t index, std::uint16_t value) {
  PhyState& p = phys_[port];
  if (index == reg::phy::kControl) {
    // Reset (bit 15, self-clearing) returns the PHY registers to their defaults.
    if ((value & reg::phy::kControlReset) != 0) {
      p = {kControlDefault, kAdvertisementDefault};
    } else {
      p.control = value;
    }
  } else if (index == reg::phy::kAdvertisement) {
    p.advertisement = value;
  }  // the other registers are read-only
}

void Esc::miiRefresh() {
  if (!miiPending_ || now_ < miiDoneAt_) return;
  miiPending_ = false;
  std::uint16_t status = static_cast<std::uint16_t>(
      reg16(kMiiFirst) & ~(reg::mii::kBusy | reg::mii::kCommandMask | reg::mii::kWriteEnable));
  unsigned port = 0;
  const bool present = phyPresent(miiPendingPhy_, port);
  if (miiPendingCommand_ == reg::mii::kCommandRead) {
    writeLe16(memory_, reg::kPhyData.address,
              present ? phyRead(port, miiPendingRegister_) : std::uint16_t{0xFFFF});
    if (!present) status |= reg::mii::kReadError;
  } else if (present) {
    phyWrite(port, miiPendingRegister_, miiPendingData_);
  }
  writeLe16(memory_, kMiiFirst, status);
}

bool Esc::miiAcceptsEcatWrite() {
  miiRefresh();
  return !miiPending_ && (memory_[reg::kMiiPdiAccessState.address] & reg::mii::kPdiHasAccess) == 0;
}

void Esc::miiCommand() {
  // The table stored the command bits (and the write enable bit, PHY and register address,
  // data of the same access) unless the interface refused the write (miiAcceptsEcatWrite).
  if (!miiAcceptsEcatWrite()) return;
  std::uint16_t status = reg16(kMiiFirst);
  const std::uint16_t command = status & reg::mii::kCommandMask;
  const bool writeEnabled = (status & reg::mii::kWriteEnable) != 0;
  status = static_cast<std::uint16_t>(status & ~reg::mii::kCommandMask);
  if (command == reg::mii::kCommandNop) {
    status = static_cast<std::uint16_t>(status & ~reg::mii::kErrorBits);
  } else if (command == (reg::mii::kCommandRead | reg::mii::kCommandWrite) ||
             (command == reg::mii::kCommandWrite && !writeEnabled)) {
    status |= reg::mii::kCommandError;
  } else {
    status = static_cast<std::uint16_t>((status & ~reg::mii::kErrorBits) | reg::mii::kBusy |
                                        command);
    miiPending_ = true;
    miiPendingCommand_ = command;
    miiPendingPhy_ = memory_[reg::kPhyAddress.address] & reg::mii::kAddressMask;
    miiPendingRegister_ = memory_[reg::kPhyRegisterAddress.address] & reg::mii::kAddressMask;
    miiPendingData_ = read(reg::kPhyData);
    miiDoneAt_ = now_ + kMdioFrameNs;
  }
  writeLe16(memory_, kMiiFirst, status);
}

}  // namespace ecsim::slavesim
