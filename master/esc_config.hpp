// What the master writes to configure an ESC's SyncManager and FMMU channels (ESC datasheet
// section II, 0x0600 FMMU and 0x0800 SyncManager channels). The channels are the value types of
// protocol/esc_blocks.hpp; this file builds them from what the master knows (SII, layout) and
// batches the writes.
#pragma once

#include <cstdint>

#include "master/batch.hpp"
#include "master/slave_info.hpp"
#include "protocol/esc_blocks.hpp"

namespace ecsim::master {

// The SM channel for an area of the slave's memory with the SII/ESI control byte, activated
// or not (status and PDI control are the ESC's; a master writes them as 0, as SOEM does).
SyncManagerBlock syncManagerChannel(std::uint16_t start, std::uint16_t length, std::uint8_t control,
                                    bool enable);

// SM0 and SM1 of a mailbox slave, from its SII: both switched off (a 16-byte FPWR of zeros),
// then configured and enabled (one 16-byte FPWR, as SOEM writes them). An SM's start, length
// and control take an ECAT write only while it is disabled (ESC datasheet section II
// 0x0800-0x0805), and a slave back from BOOT still has the bootstrap layout enabled (its
// firmware deactivates it through the PDI only): SOEM zeroes 0x0800 before configuring, IgH
// clears the SMs at INIT. Does nothing for a slave without mailbox.
void addMailboxSetup(DatagramBatch& batch, const SlaveInfo& slave);

}  // namespace ecsim::master
