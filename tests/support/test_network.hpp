// Test helpers: build frames, pass them through a Segment, look at the answer. Used by the
// simulator's component tests; the master is deliberately not involved.
#pragma once

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "protocol/frame.hpp"
#include "protocol/sii.hpp"
#include "tests/support/ci_mode.hpp"
#include "topology/segment.hpp"

namespace ecsim::testing {

// The configuration area (words 0-7) of a real Beckhoff EL2004 SII dump
// (../shared/eeprom/el2004-eeprom-dump.bin bytes 0x00-0x0F): PDI control 0x0104, checksum
// 0xD8 in word 7. Used so synthetic test images carry a checksum a real ESC accepts.
inline constexpr std::array<std::uint8_t, 16> kEl2004ConfigArea = {
    0x04, 0x01, 0x00, 0x00, 0x00, 0x00, 0x0f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xd8, 0x00};

// The SII image with ESC configuration 0x0141 = 0 (no device emulation: a slave with firmware,
// whose state machine checks the master's configuration) and its checksum fixed.
inline std::vector<std::uint8_t> withoutDeviceEmulation(std::vector<std::uint8_t> sii) {
  sii[1] = 0x00;
  sii[sii::kWordChecksum * 2] = siiChecksum(ConstBytes(sii.data(), sii::kChecksumCoveredBytes));
  return sii;
}

// One SyncManager channel (0x0800 + 8n) as a master writes it, enabled: start, length, control.
inline std::vector<std::uint8_t> smChannelBytes(std::uint16_t start, std::uint16_t length,
                                                std::uint8_t control) {
  std::vector<std::uint8_t> s(reg::kSmSize, 0);
  writeLe16(s, reg::sm::kPhysicalStart.address, start);
  writeLe16(s, reg::sm::kLength.address, length);
  s[reg::sm::kControl.address] = control;
  s[reg::sm::kActivate.address] = reg::sm::kActivateEnable;
  return s;
}

// A minimal SII image: EL2004 config area, the given identity, optional standard mailbox.
inline std::vector<std::uint8_t> makeSii(std::uint32_t vendor, std::uint32_t product,
                                         std::uint16_t mbxOut = 0, std::uint16_t mbxOutSize = 0,
                                         std::uint16_t mbxIn = 0, std::uint16_t mbxInSize = 0) {
  std::vector<std::uint8_t> sii(256, 0xFF);
  std::fill(sii.begin(), sii.begin() + 128, 0);
  std::copy(kEl2004ConfigArea.begin(), kEl2004ConfigArea.end(), sii.begin());
  auto w32 = [&](std::size_t word, std::uint32_t v) { writeLe32(sii, word * 2, v); };
  auto w16 = [&](std::size_t word, std::uint16_t v) { writeLe16(sii, word * 2, v); };
  w32(0x08, vendor);
  w32(0x0A, product);
  w32(0x0C, 0x00010000);
  w32(0x0E, 0x1234);
  w16(0x18, mbxOut);
  w16(0x19, mbxOutSize);
  w16(0x1A, mbxIn);
  w16(0x1B, mbxInSize);
  w16(0x1C, mbxOutSize ? 0x0004 : 0);
  w16(0x3E, 1);  // 2 kbit
  w16(0x3F, 1);
  w16(0x40, 0xFFFF);  // end category
  // A device with a mailbox has firmware (as config/sii_builder.cpp makes SII images).
  return mbxOutSize != 0 ? withoutDeviceEmulation(std::move(sii)) : sii;
}

inline std::unique_ptr<slavesim::Slave> makeSlave(std::string name, std::uint32_t product,
                                                  slavesim::SlaveProfile profile = {},
                                                  std::vector<std::uint8_t> sii = {}) {
  if (sii.empty()) sii = makeSii(0x0000ABCD, product);
  return std::make_unique<slavesim::Slave>(std::move(name), slavesim::kEt1100, std::move(sii),
                                           std::move(profile));
}

// A line of n generic slaves.
inline void buildLine(topology::Segment& seg, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    seg.addSlave(makeSlave("slave" + std::to_string(i), static_cast<std::uint32_t>(0x100 + i)));
  }
  seg.wireLine();
}

// Wire faults that only delay: every cable crossing takes `extra` longer.
struct FixedWireDelay : topology::WireFaults {
  SimTime extra{0};
  bool corrupts(std::size_t, unsigned, SimTime) override { return false; }
  SimTime extraDelay(std::size_t, unsigned, SimTime) override { return extra; }
};

struct DatagramSpec {
  Command command;
  std::uint32_t address;
  std::vector<std::uint8_t> data;
};

struct DatagramResult {
  Command command;
  std::uint16_t adp;
  std::uint16_t ado;
  std::uint32_t address;
  std::vector<std::uint8_t> data;
  std::uint16_t wkc;
  std::uint16_t irq;  // the ORed ECAT event requests of the ESCs passed (0x0200/0x0210)
};

// One Ethernet frame holding the given datagrams (indexes 0, 1, ...), broadcast.
inline std::vector<std::uint8_t> buildFrame(const std::vector<DatagramSpec>& specs) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat});
  std::uint8_t idx = 0;
  for (const auto& s : specs) {
    auto d = b.add(s.command, idx++, s.address, s.data);
    EXPECT_TRUE(d.ok());
  }
  auto len = b.finish();
  EXPECT_TRUE(len.ok());
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(len.ok() ? *len : 0)};
}

// Sends one frame with the given datagrams through the segment, runs the slaves' firmware
// (unless `firmware` is false: ESC only) and returns each datagram as it came back.
inline std::vector<DatagramResult> exchange(topology::Segment& seg,
                                            const std::vector<DatagramSpec>& specs, SimTime now = 0,
                                            bool firmware = true) {
  std::vector<std::uint8_t> buf = buildFrame(specs);
  auto outcome = seg.processFrame(std::span(buf.data(), buf.size()), now);
  EXPECT_TRUE(outcome.delivered);
  if (firmware) seg.pollSlaves(now);
  std::vector<DatagramResult> out;
  auto frame = EtherCatFrame::parse(std::span(buf.data(), buf.size()));
  EXPECT_TRUE(frame.ok());
  for (auto d : *frame) {
    out.push_back({d.command(), d.adp(), d.ado(), d.address(),
                   std::vector<std::uint8_t>(d.data().begin(), d.data().end()), d.wkc(), d.irq()});
  }
  return out;
}

inline DatagramResult one(topology::Segment& seg, Command c, std::uint32_t address,
                          std::vector<std::uint8_t> data, SimTime now = 0) {
  return exchange(seg, {{c, address, std::move(data)}}, now).at(0);
}

inline std::uint32_t phys(std::uint16_t adp, std::uint16_t ado) {
  return DatagramHeader::physical(adp, ado);
}

inline std::vector<std::uint8_t> le16(std::uint16_t v) {
  return {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)};
}

// Path to the shared test corpus; under CI=true a missing corpus is a failure.
inline std::filesystem::path sharedDir() {
  return std::filesystem::path(ECSIM_SHARED_DIR);
}

// In a test body: fail under CI=true, otherwise skip with a reason, when path is missing.
#define ECSIM_REQUIRE_SHARED(path)                                                      \
  do {                                                                                  \
    if (!std::filesystem::exists(path)) {                                               \
      if (::ecsim::testing::ciMode()) FAIL() << "shared test data missing: " << (path); \
      GTEST_SKIP() << "shared test data not found, skipping: " << (path);               \
    }                                                                                   \
  } while (false)

inline std::vector<std::uint8_t> readFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace ecsim::testing
