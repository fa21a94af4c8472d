// Helpers for the drive tests: the ECS7201/ECS7211 dictionaries as examples/esi/ecsim_devices.xml
// defines them, and a bench that steps a Cia402Drive over one of them directly (the
// dictionary-level view a PDO binding gives the drive), with a 1 ms cycle by default.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "slavesim/devices/cia402.hpp"
#include "slavesim/devices/cia402_drive.hpp"
#include "slavesim/devices/robot_drive.hpp"
#include "slavesim/esi_slave.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {

namespace dev = slavesim::devices;
namespace c402 = slavesim::devices::cia402;
using slavesim::devices::cia402::State;

inline constexpr std::uint32_t kEcs7201 = 0x00007201;
inline constexpr std::uint32_t kEcs7211 = 0x00007211;

inline std::filesystem::path examplesEsiPath() {
  return std::filesystem::path(ECSIM_SOURCE_DIR) / "examples" / "esi" / "ecsim_devices.xml";
}

inline const EsiFile& examplesEsi() {
  static const EsiFile file = [] {
    auto f = loadEsiFile(examplesEsiPath());
    EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message());
    return f.ok() ? std::move(f).value() : EsiFile{};
  }();
  return file;
}

inline const EsiDevice* examplesDevice(std::uint32_t product) {
  for (const auto& d : examplesEsi().devices) {
    if (d.hasProductCode && d.productCode == product) return &d;
  }
  return nullptr;
}

// A slave of ours built as makeSlaveFromEsi builds it.
inline std::unique_ptr<slavesim::Slave> makeExampleSlave(std::uint32_t product,
                                                         slavesim::EsiSlaveOptions options = {}) {
  const EsiDevice* device = examplesDevice(product);
  EXPECT_NE(device, nullptr) << std::hex << product;
  if (device == nullptr) return nullptr;
  auto slave = slavesim::makeSlaveFromEsi(examplesEsi(), *device, device->type, options);
  EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
  return slave.ok() ? std::move(slave).value() : nullptr;
}

// Motor and loops for the bench: the defaults, with Coulomb friction off unless asked (the
// analytic comparisons want a linear plant).
inline dev::DriveParams benchParams() {
  dev::DriveParams p;
  p.motor.coulombFriction = 0.0;
  return p;
}

struct DriveBench {
  std::unique_ptr<slavesim::Slave> slave;  // owns the dictionary
  slavesim::coe::ObjectDictionary* od{nullptr};
  std::unique_ptr<dev::Cia402Drive> drive;
  dev::RobotDrive* robot{nullptr};
  SimTime now{0};
  AlState al{AlState::kOp};

  explicit DriveBench(const dev::DriveParams& params = benchParams(),
                      std::uint32_t product = kEcs7201) {
    slavesim::EsiSlaveOptions options;
    options.deviceModels = false;  // the bench owns the model
    slave = makeExampleSlave(product, options);
    od = slavesim::objectDictionaryOf(*slave);
    if (product == kEcs7211) {
      auto r = dev::RobotDrive::create(*od, params);
      EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
      if (!r.ok()) return;
      robot = r->get();
      drive = std::move(r).value();
    } else {
      auto d = dev::Cia402Drive::create(*od, params);
      EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message());
      if (d.ok()) drive = std::move(d).value();
    }
  }

  // Steps the drive every `tick` for `duration` (at least one step).
  void run(SimTime duration, SimTime tick = kNsPerMs) {
    const SimTime end = now + duration;
    do {
      now += tick;
      drive->step(*od, al, now);
    } while (now < end);
  }
  void tick() { run(kNsPerMs); }

  template <typename T>
  void set(std::uint16_t index, std::uint8_t sub, T value) {
    ASSERT_TRUE(od->set<T>(index, sub, value).ok()) << std::hex << index << ":" << int(sub);
  }
  template <typename T>
  T get(std::uint16_t index, std::uint8_t sub = 0) const {
    auto r = od->get<T>(index, sub);
    EXPECT_TRUE(r.ok()) << std::hex << index << ":" << int(sub);
    return r.ok() ? *r : T{};
  }
  void controlword(std::uint16_t cw) { set<std::uint16_t>(c402::obj::kControlword, 0, cw); }
  void mode(std::int8_t m) { set<std::int8_t>(c402::obj::kModesOfOperation, 0, m); }
  std::uint16_t statusword() const { return get<std::uint16_t>(c402::obj::kStatusword); }
  std::int32_t position() const { return get<std::int32_t>(c402::obj::kPositionActualValue); }
  std::int32_t velocity() const { return get<std::int32_t>(c402::obj::kVelocityActualValue); }
  std::int16_t torque() const { return get<std::int16_t>(c402::obj::kTorqueActualValue); }
  std::uint16_t errorCode() const { return get<std::uint16_t>(c402::obj::kErrorCode); }
  State state() const {
    auto s = c402::stateFromStatusword(statusword());
    EXPECT_TRUE(s.has_value()) << std::hex << statusword();
    return s.value_or(State::kNotReadyToSwitchOn);
  }

  // Shutdown, then enable operation (transitions 2, 3 + 4), one cycle each, with the target
  // position at the actual one first (as a CSP master does).
  void enable() {
    set<std::int32_t>(c402::obj::kTargetPosition, 0, position());
    controlword(0x0006);
    tick();
    controlword(0x000F);
    tick();
    EXPECT_EQ(state(), State::kOperationEnabled) << std::hex << statusword();
  }
};

// ---- through frames -------------------------------------------------------------------------

struct ProcessDataSm {
  unsigned sm{2};
  bool outputs{true};
  std::uint16_t length{0};
};

struct OpSlave {
  std::uint16_t outBytes{0};  // outputs at logical 0 ...
  std::uint16_t inBytes{0};   // ... inputs right after them
  std::unique_ptr<MailboxMaster> mailbox;
};

// Brings segment slave 0 (station kStation) to OP with frames the way a master does: station
// address, SII read through the EEPROM registers, mailbox SMs from the SII, INIT->PREOP,
// `inPreOp` (SDO configuration), the given process-data SMs (start and control byte from the
// SII) with one FMMU each (outputs first from logical 0, then inputs), PREOP->SAFEOP, one LRW,
// SAFEOP->OP. All at time `now`.
inline OpSlave bringToOp(topology::Segment& seg, const std::vector<ProcessDataSm>& sms,
                         SimTime now = 0,
                         const std::function<void(MailboxMaster&)>& inPreOp = nullptr) {
  OpSlave out;
  auto at = [&](Command c, std::uint32_t address, std::vector<std::uint8_t> data) {
    return one(seg, c, address, std::move(data), now);
  };
  at(Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
  auto image = SiiImage::parseLenient(readSiiThroughFrames(seg, kStation, now));
  EXPECT_TRUE(image.ok());
  if (!image.ok()) return out;
  const SiiContents& sii = image->contents();
  const SiiMailbox& mbx = sii.standardMailbox;
  if (mbx.receiveSize > 0) {
    const std::uint16_t inSize = mbx.sendSize != 0 ? mbx.sendSize : mbx.receiveSize;
    out.mailbox = std::make_unique<MailboxMaster>(seg, kStation, mbx.receiveOffset, mbx.receiveSize,
                                                  mbx.sendOffset, inSize);
    at(Command::kFpwr, phys(kStation, reg::smChannel(0)),
       smRegisterBytes(mbx.receiveOffset, mbx.receiveSize, sii.syncManagers.at(0).control));
    at(Command::kFpwr, phys(kStation, reg::smChannel(1)),
       smRegisterBytes(mbx.sendOffset, inSize, sii.syncManagers.at(1).control));
  }
  at(Command::kFpwr, phys(kStation, reg::kAlControl.address), le16(0x0002));
  EXPECT_EQ(readLe16(at(Command::kFprd, phys(kStation, reg::kAlStatus.address), {0, 0}).data, 0),
            0x0002);
  if (inPreOp && out.mailbox) inPreOp(*out.mailbox);
  std::uint32_t logical = 0;
  unsigned fmmu = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const ProcessDataSm& pd : sms) {
      if (pd.outputs != (pass == 0) || pd.length == 0) continue;
      const auto& smInfo = sii.syncManagers.at(pd.sm);
      at(Command::kFpwr, phys(kStation, reg::smChannel(pd.sm)),
         smRegisterBytes(smInfo.startAddress, pd.length, smInfo.control));
      at(Command::kFpwr, phys(kStation, reg::fmmuChannel(fmmu++)),
         fmmuRegisterBytes(logical, pd.length, smInfo.startAddress, pd.outputs ? 2 : 1));
      logical += pd.length;
      (pd.outputs ? out.outBytes : out.inBytes) += pd.length;
    }
  }
  at(Command::kFpwr, phys(kStation, reg::kAlControl.address), le16(0x0004));
  EXPECT_EQ(readLe16(at(Command::kFprd, phys(kStation, reg::kAlStatus.address), {0, 0}).data, 0),
            0x0004);
  if (logical > 0) at(Command::kLrw, 0, std::vector<std::uint8_t>(logical, 0));
  at(Command::kFpwr, phys(kStation, reg::kAlControl.address), le16(0x0008));
  EXPECT_EQ(readLe16(at(Command::kFprd, phys(kStation, reg::kAlStatus.address), {0, 0}).data, 0),
            0x0008);
  return out;
}

// The cyclic exchange of one slave: each cycle runs the firmware at the cycle's time (the
// device tick, where a SYNC0 event would sample the inputs) and then one LRW over outputs and
// inputs.
struct CyclicExchange {
  topology::Segment& seg;
  std::uint16_t outBytes{0};
  std::uint16_t inBytes{0};
  SimTime now{0};
  std::vector<std::uint8_t> out = std::vector<std::uint8_t>(outBytes, 0);
  std::vector<std::uint8_t> in = std::vector<std::uint8_t>(inBytes, 0);
  std::uint16_t wkc{0};

  void cycle(SimTime period = kNsPerMs) {
    now += period;
    seg.pollSlaves(now);
    std::vector<std::uint8_t> image(out);
    image.resize(outBytes + inBytes, 0);
    auto r = one(seg, Command::kLrw, 0, image, now);
    wkc = r.wkc;
    in.assign(r.data.begin() + outBytes, r.data.end());
  }
  void put8(std::size_t at, std::uint8_t v) { out.at(at) = v; }
  void put16(std::size_t at, std::uint16_t v) { writeLe16(out, at, v); }
  void put32(std::size_t at, std::int32_t v) { writeLe32(out, at, static_cast<std::uint32_t>(v)); }
  std::uint8_t in8(std::size_t at) const { return in.at(at); }
  std::uint16_t in16(std::size_t at) const { return readLe16(in, at); }
  std::int32_t in32(std::size_t at) const { return static_cast<std::int32_t>(readLe32(in, at)); }
};

}  // namespace ecsim::testing
