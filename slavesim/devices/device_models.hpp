// Which device model a slave gets, and the way to reach it afterwards. The models are
// Applications of the slave's ProcessDataDevice (process_data.hpp), so the dictionary, the PDO
// binding and the CoE server stay as they are; the model only fills the inputs and reacts to
// the outputs.
//
//   ECS1008 (0x1008)            DigitalInputTerminal over 0x6000:01-08
//   ECS2008 (0x2008)            DigitalOutputTerminal over 0x7000:01-08
//   ECS3102 (0x3102)            AnalogInputTerminal, 2 channels
//   ECS7201 (0x7201)            Cia402Drive
//   ECS7211 (0x7211)            RobotDrive
//   ECS5001 (0x5001)            SsiEncoderTerminal (examples/esi/ecsim_encoders.xml)
// for the ecsim vendor id (0x00000E5C), and the Beckhoff EJ5002 (vendor 2, 0x138A2852), whose
// SSI channel layout the SsiEncoderTerminal follows. Any other device, of any vendor, gets a
// CiA 402 drive when its ESI says ProfileNo 402, or says no profile and its dictionary has the
// controlword 0x6040 and statusword 0x6041 (a device of another profile, e.g. 5001 MDP, may use
// 0x6040 for something else). The drive binds to the device's own objects and PDO entries; a
// device with further axes (0x6840/0x6841, 0x7040/0x7041, ...) gets one drive per axis
// (MultiAxisDrive). Any other device gets the encoder profile when its TxPDOs carry counter
// values (counterValueChannels, encoder_terminal.hpp), else, when its ESI gives no profile or
// MDP 5001, the analog profile when its PDOs map analog values and the io profile when they
// map digital entries (io_profile.hpp, chooseIoProfile); the rest keep the plain
// ProcessDataDevice. A topology's model="cia402|io|analog|encoder|loopback|none" overrides the
// choice (deviceModelByName).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/devices/cia402_drive.hpp"
#include "slavesim/devices/encoder_terminal.hpp"
#include "slavesim/devices/io_profile.hpp"
#include "slavesim/devices/io_terminals.hpp"
#include "slavesim/devices/multi_axis_drive.hpp"
#include "slavesim/devices/robot_drive.hpp"
#include "slavesim/process_data.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::slavesim::devices {

enum class DeviceModelKind : std::uint8_t {
  kNone,
  kDigitalInputs,
  kDigitalOutputs,
  kAnalogInputs,
  kCia402Drive,
  kRobotDrive,
  kSsiEncoder,
  kIo,        // io_profile.hpp: digital inputs and outputs of the device's own PDO entries
  kAnalog,    // analog inputs and outputs of the device's own PDO entries
  kLoopback,  // io, inputs following another slave's outputs (loopback.from)
  kEncoder,  // counter values of any device (SsiEncoderTerminal::createForCounters)
};

// hasDriveObjects: the device's dictionary has 0x6040 and 0x6041.
DeviceModelKind deviceModelFor(std::uint32_t vendorId, std::uint32_t productCode,
                               std::optional<std::uint32_t> profileNo = std::nullopt,
                               bool hasDriveObjects = false);

// For a device deviceModelFor() gives none: kAnalog, kIo or kNone from the PDO entries of its
// dictionary when its ESI gives no profile or MDP 5001 (io_profile.hpp), else kNone.
DeviceModelKind chooseIoProfile(coe::ObjectDictionary& od,
                                std::optional<std::uint32_t> profileNo = std::nullopt);

// The model a topology's model="NAME" names ("cia402", "io", "analog", "loopback", "none");
// nullopt for another name.
std::optional<DeviceModelKind> deviceModelByName(std::string_view name);
// The names deviceModelByName takes, for messages.
std::vector<std::string> deviceModelNames();

// The CiA 402 axes of a dictionary: axis n counts while 0x6040 + n * 0x800 and 0x6041 + n *
// 0x800 are both present (at most 8, up to 0x9FFF).
unsigned cia402AxisCount(const coe::ObjectDictionary& od);

struct DeviceModelOptions {
  std::filesystem::path stateFile;  // drives, encoders: where the shaft position is kept
  // Drives: motor, loops, encoder (stateFile above wins). Encoder terminals take its encoder
  // and initialShaftAngle.
  DriveParams drive;
  AnalogInputOptions analog;
  // drive.encoder.countsPerRevolution was chosen (and goes into 0x2011); otherwise a
  // dictionary with 0x2011 gives it.
  bool encoderResolutionSet{false};
  // The topology line of drive.mode (0: not from a file), for the error when the device's
  // supported drive modes 0x6502 do not list it (checked by attachDeviceModel).
  int driveModeLine{0};
  EmergencySink emergencies;  // drives: where their emergency messages go
  // Input terminals: scripted channels (1-based; digital on at >= 0.5, analog in volts,
  // encoder shaft in turns).
  std::vector<std::pair<unsigned, Signal>> scripts;
  // model="loopback": the slave whose digital outputs the inputs follow (loopback.from), and
  // the line of that <Param>; bound by the topology builder.
  std::string loopbackFrom;
  int loopbackLine{0};
};

// Attaches the model to `device` (kNone: removes any). Scripts for a model without scripted
// inputs, or for a channel it does not have, are an error. A previous model is destroyed first, so
// a drive saves its state file before its successor reads it (a simulated power cycle).
// Drives take the encoder resolution from 0x2011 when the dictionary has it.
Status attachDeviceModel(ProcessDataDevice& device, DeviceModelKind kind,
                         const DeviceModelOptions& options = {});

// A cold start after a power cycle (ProcessDataDevice::setRestart): re-creates the model of
// `kind` with `options`, carrying over what outlives the power: a drive's or an encoder's shaft
// angle (the shaft stays where it is; with a state file the old model writes it and the new
// reads it), a drive's emergency sink when `options` names none, input terminals' and
// encoders' scripts (the signals come from outside the device) and encoder faults (wiring and
// encoder supply are outside the terminal). Everything else starts as after power-up.
Status restartDeviceModel(ProcessDataDevice& device, DeviceModelKind kind,
                          const DeviceModelOptions& options);

// The model of a slave built by makeSlaveFromEsi (nullptr when it has another or none).
Application* deviceModelOf(Slave& slave);
Cia402Drive* driveOf(Slave& slave);  // also a RobotDrive; axis 0 of a multi-axis device
Cia402Drive* driveOf(Slave& slave, unsigned axis);  // nullptr when there is no such axis
RobotDrive* robotDriveOf(Slave& slave);
DigitalInputTerminal* digitalInputsOf(Slave& slave);
DigitalOutputTerminal* digitalOutputsOf(Slave& slave);
AnalogInputTerminal* analogInputsOf(Slave& slave);
SsiEncoderTerminal* encoderTerminalOf(Slave& slave);
AnalogOutputTerminal* analogOutputsOf(Slave& slave);

}  // namespace ecsim::slavesim::devices
