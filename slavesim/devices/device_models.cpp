#include "slavesim/devices/device_models.hpp"

#include "slavesim/generic_slave.hpp"

namespace ecsim::slavesim::devices {
namespace {

constexpr std::uint32_t kProductDigitalInputs = 0x00001008;
constexpr std::uint32_t kProductDigitalOutputs = 0x00002008;
constexpr std::uint32_t kProductAnalogInputs = 0x00003102;
constexpr std::uint32_t kProductDrive = 0x00007201;
constexpr std::uint32_t kProductRobotDrive = 0x00007211;
constexpr std::uint32_t kProfileDrive = 402;
constexpr std::uint16_t kEncoderResolution = 0x2011;

template <typename T>
Status install(ProcessDataDevice& device, Result<std::unique_ptr<T>> model) {
  if (!model.ok()) return model.takeError();
  device.setApplication(std::move(model).value());
  return okStatus();
}

}  // namespace

DeviceModelKind deviceModelFor(std::uint32_t vendorId, std::uint32_t productCode,
                               std::optional<std::uint32_t> profileNo) {
  if (vendorId != kEcsimVendorId) return DeviceModelKind::kNone;
  switch (productCode) {
    case kProductDigitalInputs:
      return DeviceModelKind::kDigitalInputs;
    case kProductDigitalOutputs:
      return DeviceModelKind::kDigitalOutputs;
    case kProductAnalogInputs:
      return DeviceModelKind::kAnalogInputs;
    case kProductDrive:
      return DeviceModelKind::kCia402Drive;
    case kProductRobotDrive:
      return DeviceModelKind::kRobotDrive;
    default:
      break;
  }
  if (profileNo && *profileNo == kProfileDrive) return DeviceModelKind::kCia402Drive;
  return DeviceModelKind::kNone;
}

Status attachDeviceModel(ProcessDataDevice& device, DeviceModelKind kind,
                         const DeviceModelOptions& options) {
  device.setApplication(nullptr);  // the old model goes first (and saves its state)
  coe::ObjectDictionary& od = device.dictionary();
  DriveParams drive = options.drive;
  if (!options.stateFile.empty()) drive.stateFile = options.stateFile;
  if (const auto cpr = od.get<std::uint32_t>(kEncoderResolution, 0); cpr.ok() && *cpr > 0) {
    drive.encoder.countsPerRevolution = *cpr;
  }
  switch (kind) {
    case DeviceModelKind::kNone:
      return okStatus();
    case DeviceModelKind::kDigitalInputs:
      return install(device, DigitalInputTerminal::create(od));
    case DeviceModelKind::kDigitalOutputs:
      return install(device, DigitalOutputTerminal::create(od));
    case DeviceModelKind::kAnalogInputs:
      return install(device, AnalogInputTerminal::create(od, 2, options.analog));
    case DeviceModelKind::kCia402Drive:
      return install(device, Cia402Drive::create(od, drive));
    case DeviceModelKind::kRobotDrive:
      return install(device, RobotDrive::create(od, drive));
  }
  return okStatus();
}

Application* deviceModelOf(Slave& slave) {
  auto* pd = dynamic_cast<ProcessDataDevice*>(slave.device());
  return pd == nullptr ? nullptr : pd->application();
}

Cia402Drive* driveOf(Slave& slave) {
  return dynamic_cast<Cia402Drive*>(deviceModelOf(slave));
}

RobotDrive* robotDriveOf(Slave& slave) {
  return dynamic_cast<RobotDrive*>(deviceModelOf(slave));
}

DigitalInputTerminal* digitalInputsOf(Slave& slave) {
  return dynamic_cast<DigitalInputTerminal*>(deviceModelOf(slave));
}

DigitalOutputTerminal* digitalOutputsOf(Slave& slave) {
  return dynamic_cast<DigitalOutputTerminal*>(deviceModelOf(slave));
}

AnalogInputTerminal* analogInputsOf(Slave& slave) {
  return dynamic_cast<AnalogInputTerminal*>(deviceModelOf(slave));
}

}  // namespace ecsim::slavesim::devices
