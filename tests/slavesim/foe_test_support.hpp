// The SOES demo slave of ../shared/esi/SOES_lan9252demo_slave.xml (Mailbox/FoE, BootStrap
// 0010800080108000 at line 686: bootstrap mailbox 0x1000/128 out, 0x1080/128 in) on a Segment,
// reached only through frames as SOEM's firm_update reaches it: the SII bootstrap words, the
// SMs written from them, INIT->BOOT, FoE write / read with the packet numbering of SOEM's
// ecx_FOEwrite / ecx_FOEread. Shared by the FoE server and FoE folder tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "config/esi.hpp"
#include "protocol/foe.hpp"
#include "slavesim/esi_slave.hpp"
#include "slavesim/foe/foe_files.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {

inline constexpr std::uint16_t kInit = 0x0001;
inline constexpr std::uint16_t kBoot = 0x0003;

struct FoeReply {
  FoeOpcode opcode{FoeOpcode::kError};
  std::uint32_t value{0};
  std::vector<std::uint8_t> data;
  MailboxType type{MailboxType::kFoe};
  std::uint16_t mailboxError{0};
};

class FoeSlave {
 public:
  // options: e.g. a stateFile, whose folder keeps the files (slavesim/foe/foe_folder.hpp).
  explicit FoeSlave(slavesim::EsiSlaveOptions options = {}) {
    const auto path = sharedDir() / "esi" / "SOES_lan9252demo_slave.xml";
    if (!std::filesystem::exists(path)) return;
    auto file = loadEsiFile(path);
    EXPECT_TRUE(file.ok());
    auto slave = slavesim::makeSlaveFromEsi(*file, file->devices.at(0), "soes", options);
    EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
    if (!slave.ok()) return;
    seg.addSlave(std::move(slave).value());
    one(seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
    // The bootstrap mailbox as firm_update takes it: SII words 0x14/0x15 (receive offset,
    // size) and 0x16/0x17 (send offset, size).
    const auto sii = readSiiThroughFrames(seg, kStation);
    bootOut = readLe16(sii, 2 * sii::kWordBootstrapMailbox);
    bootOutSize = readLe16(sii, 2 * sii::kWordBootstrapMailbox + 2);
    bootIn = readLe16(sii, 2 * sii::kWordBootstrapMailbox + 4);
    bootInSize = readLe16(sii, 2 * sii::kWordBootstrapMailbox + 6);
    master =
        std::make_unique<MailboxMaster>(seg, kStation, bootOut, bootOutSize, bootIn, bootInSize);
  }
  bool ready() const { return master != nullptr; }

  FoeReply transact(FoeOpcode opcode, std::uint32_t value, ConstBytes data = {}) {
    auto m = encodeFoeMailbox(opcode, value, data);
    m[5] = static_cast<std::uint8_t>(m[5] | (master->nextCounter() << 4));
    auto r = master->transact(m);
    FoeReply out;
    EXPECT_TRUE(r.has_value()) << "no answer to " << toString(opcode);
    if (!r) return out;
    auto mbx = decodeMailbox(*r);
    EXPECT_TRUE(mbx.ok());
    out.type = mbx->header.type;
    if (out.type == MailboxType::kError) {
      out.mailboxError = MailboxErrorReply::decode(mbx->payload)->detail;
      return out;
    }
    auto p = decodeFoe(mbx->payload);
    EXPECT_TRUE(p.ok());
    out.opcode = p->opcode;
    out.value = p->value;
    out.data.assign(p->data.begin(), p->data.end());
    return out;
  }
  FoeReply transact(FoeOpcode opcode, std::uint32_t value, std::string_view text) {
    return transact(opcode, value,
                    ConstBytes(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  }

  // ecx_FOEwrite: WRQ, then DATA 1.. of (SM0 length - 12) bytes; a final empty packet when the
  // last one was full. Returns the opcode/value of the first answer that is not the expected ACK.
  FoeReply write(const std::string& name, const std::vector<std::uint8_t>& file,
                 std::uint32_t password = 0) {
    FoeReply r = transact(FoeOpcode::kWrite, password, name);
    if (r.opcode != FoeOpcode::kAck || r.value != 0) return r;
    const std::size_t per = foeDataPerPacket(bootOutSize);
    std::size_t offset = 0;
    std::uint32_t packet = 0;
    for (;;) {
      const std::size_t n = std::min(per, file.size() - offset);
      r = transact(FoeOpcode::kData, ++packet, ConstBytes(file).subspan(offset, n));
      if (r.opcode != FoeOpcode::kAck || r.value != packet) return r;
      offset += n;
      if (n < per) return r;
    }
  }

  // ecx_FOEread: RRQ, DATA n answered with ACK n until a packet shorter than (SM1 - 12).
  std::vector<std::uint8_t> read(const std::string& name, FoeReply* failure = nullptr) {
    std::vector<std::uint8_t> bytes;
    FoeReply r = transact(FoeOpcode::kRead, 0, name);
    for (std::uint32_t expected = 1;; ++expected) {
      if (r.opcode != FoeOpcode::kData || r.value != expected) {
        if (failure != nullptr) *failure = r;
        return bytes;
      }
      bytes.insert(bytes.end(), r.data.begin(), r.data.end());
      if (r.data.size() < foeDataPerPacket(bootInSize)) {
        master->send([&] {
          auto ack = encodeFoeMailbox(FoeOpcode::kAck, expected);
          ack[5] = static_cast<std::uint8_t>(ack[5] | (master->nextCounter() << 4));
          return ack;
        }());
        seg.pollSlaves(0);
        return bytes;
      }
      r = transact(FoeOpcode::kAck, expected);
    }
  }

  void toBoot() {
    master->configureSyncManagers();
    requestState(seg, kStation, kBoot);
  }

  topology::Segment seg;
  std::unique_ptr<MailboxMaster> master;
  std::uint16_t bootOut{0}, bootOutSize{0}, bootIn{0}, bootInSize{0};
};

inline std::vector<std::uint8_t> firmwareImage(std::size_t size, std::string_view version) {
  std::vector<std::uint8_t> image(size);
  for (std::size_t i = 0; i < size; ++i) image[i] = static_cast<std::uint8_t>(i * 7 + 3);
  const std::string marker =
      std::string(slavesim::foe::kSoftwareVersionMarker) + std::string(version) + '\0';
  std::copy(marker.begin(), marker.end(), image.begin() + static_cast<std::ptrdiff_t>(size / 2));
  return image;
}

}  // namespace ecsim::testing
