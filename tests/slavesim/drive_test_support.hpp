// Helpers for the drive tests: the ECS7201/ECS7211 dictionaries as examples/esi/ecsim_devices.xml
// defines them, and a bench that steps a Cia402Drive over one of them directly (the
// dictionary-level view a PDO binding gives the drive), with a 1 ms cycle by default.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "config/esi.hpp"
#include "slavesim/devices/cia402.hpp"
#include "slavesim/devices/cia402_drive.hpp"
#include "slavesim/devices/robot_drive.hpp"
#include "slavesim/esi_slave.hpp"

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

}  // namespace ecsim::testing
