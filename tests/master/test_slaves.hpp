// Simulated slaves for the master tests, built with protocol/sii.hpp's encodeSii so that every
// SII field the master reads is known to the test:
//   - ioSii(): a digital/analog I/O terminal without mailbox whose process data is described
//     only by the SII (SM category: SM0 outputs 3-buffer 0x1000, SM1 inputs 3-buffer 0x1100;
//     FMMU category; RxPDO 0x1600 with one entry per output byte, TxPDO 0x1A00 with 16-bit
//     entries) - what an EL2004/EL1004 class device looks like to a master;
//   - makeIoSlave(): such a slave whose firmware expects exactly those SM lengths at
//     PREOP->SAFEOP (a master that maps wrongly gets AL status 0x001D/0x001E).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "protocol/sii.hpp"
#include "slavesim/coe/coe_server.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/esc_type.hpp"
#include "slavesim/generic_slave.hpp"
#include "slavesim/process_data.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::testing {

inline constexpr std::uint32_t kTestVendor = 0x00000E5C;
inline constexpr std::uint16_t kIoOutputSm = 0x1000;
inline constexpr std::uint16_t kIoInputSm = 0x1100;

// outputs: `outBytes` 8-bit entries 0x7000:1..n; inputs: `inWords` 16-bit entries 0x6000:1..n.
inline SiiContents ioSii(const std::string& name, std::uint32_t product, std::uint16_t outBytes,
                         std::uint16_t inWords, std::uint32_t serial = 0) {
  SiiContents c;
  c.config.pdiControl = 0x0004;  // digital I/O PDI
  c.identity = {kTestVendor, product, 0x00020000, serial};
  // 16 Kbit; a large image's PDO list needs a 128 Kbit EEPROM.
  c.sizeField = siiSizeFieldForBytes(outBytes > 200 ? 16384 : 2048);
  c.strings = {name, "Outputs", "Inputs", "Out", "In"};
  SiiGeneral g;
  g.nameIndex = 1;
  g.physicalPorts = 0x0011;
  c.general = g;
  c.fmmus = {SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs};
  SiiSyncManager out{
      kIoOutputSm, outBytes, 0x64, 0, SiiSyncManagerEnable::kEnable, SiiSyncManagerType::kOutputs};
  SiiSyncManager in{
      kIoInputSm, static_cast<std::uint16_t>(2 * inWords), 0x20,
      0,          SiiSyncManagerEnable::kEnable,           SiiSyncManagerType::kInputs};
  c.syncManagers = {out, in};
  // One 8-bit entry per output byte; an SII PDO holds at most 255 entries, so large images
  // use 0x1600, 0x1601, ... with up to 200 entries each.
  for (std::uint16_t first = 0; first < outBytes; first = static_cast<std::uint16_t>(first + 200)) {
    SiiPdo rx;
    rx.index = static_cast<std::uint16_t>(0x1600 + first / 200);
    rx.syncManager = 0;
    rx.nameIndex = 2;
    for (std::uint16_t i = first; i < outBytes && i < first + 200; ++i) {
      rx.entries.push_back({static_cast<std::uint16_t>(0x7000 + i / 200),
                            static_cast<std::uint8_t>(i % 200 + 1), 4, 0x05, 8, 0});
    }
    c.rxPdos.push_back(rx);
  }
  if (inWords > 0) {
    SiiPdo tx;
    tx.index = 0x1A00;
    tx.syncManager = 1;
    tx.nameIndex = 3;
    for (std::uint16_t i = 0; i < inWords; ++i) {
      tx.entries.push_back({0x6000, static_cast<std::uint8_t>(i + 1), 5, 0x06, 16, 0});
    }
    c.txPdos.push_back(tx);
  }
  return c;
}

inline std::unique_ptr<slavesim::Slave> makeSiiSlave(
    const std::string& name, const SiiContents& contents, slavesim::SlaveProfile profile = {},
    const slavesim::EscType& esc = slavesim::kEt1100) {
  auto image = encodeSii(contents);
  EXPECT_TRUE(image.ok()) << (image.ok() ? "" : image.error().message());
  return std::make_unique<slavesim::Slave>(
      name, esc, image.ok() ? *image : std::vector<std::uint8_t>{}, std::move(profile));
}

inline std::unique_ptr<slavesim::Slave> makeIoSlave(
    const std::string& name, std::uint32_t product, std::uint16_t outBytes, std::uint16_t inWords,
    const slavesim::EscType& esc = slavesim::kEt1100) {
  slavesim::SlaveProfile profile;
  if (outBytes > 0) profile.processData.push_back({0, true, outBytes});
  if (inWords > 0) {
    profile.processData.push_back({1, false, static_cast<std::uint16_t>(2 * inWords)});
  }
  return makeSiiSlave(name, ioSii(name, product, outBytes, inWords), std::move(profile), esc);
}

// A CoE slave of our own: standard mailbox 0x1000/128 (out) and 0x1080/128 (in), process-data
// SMs 0x1100 (outputs, SM2) and 0x1180 (inputs, SM3) of length 0 in the SII, no SII PDOs: the
// master must take the mapping from the dictionary (0x1C00, 0x1C12/0x1C13, 0x16xx/0x1Axx).
inline SiiContents coeSii(const std::string& name, std::uint32_t product) {
  SiiContents c = ioSii(name, product, 0, 0);
  c.standardMailbox = {0x1000, 128, 0x1080, 128};
  c.mailboxProtocols = SiiMailboxProtocol::kCoe;
  c.general->coeDetails = static_cast<std::uint8_t>(SiiCoeDetails::kSdo | SiiCoeDetails::kSdoInfo |
                                                    SiiCoeDetails::kSdoCompleteAccess);
  c.syncManagers = {{0x1000, 128, 0x26, 0, 1, SiiSyncManagerType::kMailboxOut},
                    {0x1080, 128, 0x22, 0, 1, SiiSyncManagerType::kMailboxIn},
                    {0x1100, 0, 0x64, 0, 1, SiiSyncManagerType::kOutputs},
                    {0x1180, 0, 0x20, 0, 1, SiiSyncManagerType::kInputs}};
  c.fmmus = {SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs, SiiFmmuUsage::kSyncManagerStatus};
  c.rxPdos.clear();
  c.txPdos.clear();
  return c;
}

inline std::unique_ptr<slavesim::Slave> makeCoeSlave(
    const std::string& name, std::uint32_t product,
    std::shared_ptr<slavesim::coe::ObjectDictionary> od, slavesim::SlaveProfile profile = {},
    slavesim::coe::CoeServerOptions options = {}) {
  auto slave = makeSiiSlave(name, coeSii(name, product), std::move(profile));
  slave->setMailboxServer(std::make_unique<slavesim::coe::CoeServer>(std::move(od), options));
  return slave;
}

// A dictionary with `outWords` UINT outputs (0x7000:n in RxPDO 0x1600 on SM2) and `inWords`
// UINT inputs (0x6000:n in TxPDO 0x1A00 on SM3), assigned in 0x1C12 / 0x1C13.
inline std::shared_ptr<slavesim::coe::ObjectDictionary> coeIoDictionary(std::uint32_t product,
                                                                        std::uint8_t outWords,
                                                                        std::uint8_t inWords) {
  namespace coe = slavesim::coe;
  auto od = std::make_shared<coe::ObjectDictionary>();
  coe::addIdentityObject(*od, {kTestVendor, product, 1, 0});
  const std::uint8_t types[] = {1, 2, 3, 4};
  coe::addSyncManagerTypes(*od, types);
  od->addArray(0x7000, "Outputs", 0x0006, 16, outWords,
               coe::access::kReadWrite | coe::access::kRxMappable);
  od->addArray(0x6000, "Inputs", 0x0006, 16, inWords,
               coe::access::kReadOnly | coe::access::kTxMappable);
  coe::PdoMappingSpec rx{0x1600, "Out", {}, {}, outWords, true};
  for (std::uint8_t i = 1; i <= outWords; ++i) rx.entries.push_back({0x7000, i, 16});
  coe::PdoMappingSpec tx{0x1A00, "In", {}, {}, inWords, true};
  for (std::uint8_t i = 1; i <= inWords; ++i) tx.entries.push_back({0x6000, i, 16});
  coe::addPdoMapping(*od, rx);
  coe::addPdoMapping(*od, tx);
  const std::uint16_t rxPdos[] = {0x1600};
  const std::uint16_t txPdos[] = {0x1A00};
  coe::addPdoAssignment(*od, 2, rxPdos, 1, false);
  coe::addPdoAssignment(*od, 3, txPdos, 1, false);
  return od;
}

// A CoE slave of ours with the dictionary above and the simulator's process-data device:
// its firmware checks the SM lengths at PREOP->SAFEOP and copies process data.
inline std::unique_ptr<slavesim::Slave> makeCoeIoSlave(const std::string& name,
                                                       std::uint32_t product, std::uint8_t outWords,
                                                       std::uint8_t inWords) {
  auto od = coeIoDictionary(product, outWords, inWords);
  slavesim::SlaveProfile profile;
  profile.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
  auto slave = makeCoeSlave(name, product, od, profile);
  slave->setDevice(std::make_unique<slavesim::ProcessDataDevice>(od));
  return slave;
}

}  // namespace ecsim::testing
