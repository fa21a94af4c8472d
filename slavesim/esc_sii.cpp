// The SII EEPROM interface (0x0500-0x050F) and what the ESC loads from the EEPROM at power-on
// (datasheet section I §11, section II 0x0500).
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;
namespace {

// The SII words the ESC loads into registers at power-on (datasheet section I §11.1).
constexpr std::size_t kSiiPdiControlWord = 0x00;
constexpr std::size_t kSiiPdiConfigWord = 0x01;
constexpr std::size_t kSiiSyncPulseWord = 0x02;
constexpr std::size_t kSiiExtendedPdiWord = 0x03;
constexpr std::size_t kSiiAliasWord = 0x04;
constexpr std::size_t kSiiChecksumWord = 0x07;

std::uint8_t siiCrc(const std::vector<std::uint8_t>& sii) {
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < 14 && i < sii.size(); ++i) {
    crc ^= sii[i];
    for (int b = 0; b < 8; ++b) {
      crc = static_cast<std::uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x07 : (crc << 1));
    }
  }
  return crc;
}

std::uint16_t siiWord(const std::vector<std::uint8_t>& sii, std::size_t word) {
  std::size_t at = 2 * word;
  if (at + 1 >= sii.size()) return 0xFFFF;
  return static_cast<std::uint16_t>(sii[at] | (sii[at + 1] << 8));
}

}  // namespace

void Esc::loadFromSii() {
  siiPending_ = false;  // power-on or reload: no command in progress
  std::uint16_t status = type_.siiRead8Bytes ? reg::sii::kReadSize8Bytes : 0;
  if (sii_.size() > 2048) status |= reg::sii::kTwoAddressBytes;  // > 16 kbit
  std::uint16_t dl = reg16(reg::kDlStatus.address);
  if (sii_.size() >= 16 && (siiCrc(sii_) == (siiWord(sii_, kSiiChecksumWord) & 0xFF) ||
                            siiWord(sii_, kSiiChecksumWord) == 0x88A4)) {
    std::uint16_t pdi = siiWord(sii_, kSiiPdiControlWord);
    memory_[reg::kPdiControl.address] = static_cast<std::uint8_t>(pdi);
    memory_[reg::kEscConfiguration.address] = static_cast<std::uint8_t>(pdi >> 8);
    writeLe16(memory_, reg::kPdiConfiguration.address, siiWord(sii_, kSiiPdiConfigWord));
    writeLe16(memory_, reg::kSyncPulseLength.address, siiWord(sii_, kSiiSyncPulseWord));
    writeLe16(memory_, reg::kExtendedPdiConfiguration.address, siiWord(sii_, kSiiExtendedPdiWord));
    writeLe16(memory_, reg::kConfiguredStationAlias.address, siiWord(sii_, kSiiAliasWord));
    dl = static_cast<std::uint16_t>(dl | reg::dl_status::kPdiOperational);
  } else {
    // Checksum error: the ESC does not load the configuration and the PDI stays off.
    status |= reg::sii::kChecksumError;
    dl = static_cast<std::uint16_t>(dl & ~reg::dl_status::kPdiOperational);
  }
  writeLe16(memory_, reg::kSiiControlStatus.address, status);
  writeLe16(memory_, reg::kDlStatus.address, dl);
  refreshAddressing();  // the alias (and a reset's zeroed registers)
}

void Esc::siiCommand(std::uint16_t control) {
  // While busy (section II 0x0502 bit 15) the interface takes no new command and keeps its
  // address and data: the table's byte rule kSiiLocked refused the bytes and the command is not
  // started. The datasheet says no more about writes during busy; masters never make them
  // (SOEM waits for busy to clear before every command, ecx_readeepromFP).
  if (!siiAcceptsWrite()) return;
  std::uint16_t status = reg16(reg::kSiiControlStatus.address);
  status = static_cast<std::uint16_t>(
      status & ~(reg::sii::kCommandMask | reg::sii::kBusy | reg::sii::kWriteEnable));
  const std::uint16_t command = control & reg::sii::kCommandMask;
  switch (command) {
    case reg::sii::kCommandNop:
      // A NOP clears the error bits (datasheet section II, 0x0502 description).
      status = static_cast<std::uint16_t>(status &
                                          ~(reg::sii::kCommandError | reg::sii::kWriteEnableError));
      break;
    case reg::sii::kCommandWrite:
      if ((control & reg::sii::kWriteEnable) == 0) {
        status |= reg::sii::kWriteEnableError;  // refused at once, the EEPROM is not accessed
        break;
      }
      [[fallthrough]];
    case reg::sii::kCommandRead:
    case reg::sii::kCommandReload:
      // The I2C transfer runs: busy with the command bits held until it is done (a real
      // EK1100 answers 0x8140 while reading: ../shared/pcap/replay-dc.pcapng frames 106, 108,
      // then 0x0040 in frame 110). Address and data are taken now.
      siiPending_ = true;
      siiPendingCommand_ = command;
      siiPendingWord_ = reg32(reg::kSiiAddress.address);
      siiPendingData_ = reg16(reg::kSiiData.address);
      siiDoneAt_ = now_ + static_cast<SimTime>(type_.siiBusyNs);
      status = static_cast<std::uint16_t>(status | reg::sii::kBusy | command);
      break;
    default:
      status |= reg::sii::kCommandError;  // two command bits at once: invalid
      break;
  }
  writeLe16(memory_, reg::kSiiControlStatus.address, status);
}

void Esc::siiRefresh() {
  if (!siiPending_ || now_ < siiDoneAt_) return;
  siiPending_ = false;
  siiExecute(siiPendingCommand_, siiPendingWord_, siiPendingData_);
}

void Esc::siiExecute(std::uint16_t command, std::uint32_t word, std::uint16_t data) {
  std::uint16_t status = static_cast<std::uint16_t>(
      reg16(reg::kSiiControlStatus.address) & ~(reg::sii::kCommandMask | reg::sii::kBusy));
  // An I2C EEPROM ignores the address bits above its size, so addresses beyond the end wrap
  // around to its start (section I §11.3.3.2: the wrap-around is the application's business,
  // the ESC knows nothing of it). The image is the EEPROM: its size is the device's.
  const std::size_t words = sii_.size() / 2;
  switch (command) {
    case reg::sii::kCommandRead: {
      const unsigned count = type_.siiRead8Bytes ? 4 : 2;
      for (unsigned i = 0; i < count; ++i) {
        const std::uint16_t value =
            words == 0 ? 0xFFFF : siiWord(sii_, (static_cast<std::size_t>(word) + i) % words);
        writeLe16(memory_, static_cast<std::uint16_t>(reg::kSiiData.address + 2 * i), value);
      }
      status = static_cast<std::uint16_t>(status & ~reg::sii::kCommandError);
      break;
    }
    case reg::sii::kCommandWrite:
      if (words == 0) {
        status |= reg::sii::kCommandError;  // no EEPROM: no acknowledge
      } else {
        writeLe16(sii_, 2 * (word % words), data);
      }
      break;
    case reg::sii::kCommandReload:
      loadFromSii();
      status = reg16(reg::kSiiControlStatus.address);
      events_.eepromReloaded = true;
      noteEvent();
      break;
    default:
      break;
  }
  writeLe16(memory_, reg::kSiiControlStatus.address, status);
}

}  // namespace ecsim::slavesim
