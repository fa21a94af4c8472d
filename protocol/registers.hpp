// The ESC register map, 0x0000-0x0FFF, named as in the Beckhoff ESC datasheet section II
// ("EtherCAT Slave Controller Register Description", ET1100/ET1200/IP core) and ETG.1000.4.
// Master and simulator both use it; nowhere else in the code does a register address appear
// as a bare number.
//
// Each register is a Reg<T>: its address, its width (sizeof T) and its datasheet name. FMMU and
// SyncManager channels are repeated blocks addressed through fmmuChannel(n) / smChannel(n).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace ecsim::reg {

template <typename T>
struct Reg {
  using Value = T;
  std::uint16_t address;
  std::string_view name;
  static constexpr std::uint16_t width = sizeof(T);
  constexpr std::uint16_t end() const { return static_cast<std::uint16_t>(address + width); }
};

// The bytes from `first` through `last` (one read that covers several registers, e.g. AL
// status through AL status code).
template <typename T, typename U>
constexpr std::uint16_t spanWidth(Reg<T> first, Reg<U> last) {
  return static_cast<std::uint16_t>(last.end() - first.address);
}

// Register r in `bytes` that hold the register space from address `base` on (little-endian,
// as on the wire). The bytes must cover r.
template <typename T>
T valueIn(Reg<T> r, std::span<const std::uint8_t> bytes, std::uint16_t base) {
  std::uint64_t v = 0;
  for (unsigned i = 0; i < sizeof(T); ++i)
    v |= static_cast<std::uint64_t>(bytes[r.address - base + i]) << (8 * i);
  return static_cast<T>(v);
}
template <typename T>
void putIn(Reg<T> r, std::span<std::uint8_t> bytes, std::uint16_t base, T value) {
  const auto v = static_cast<std::uint64_t>(value);
  for (unsigned i = 0; i < sizeof(T); ++i)
    bytes[r.address - base + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// A register block that is not a scalar (e.g. 0x0508 SII data, 4 or 8 bytes).
struct Block {
  std::uint16_t address;
  std::uint16_t width;
  std::string_view name;
};

// ESC information
inline constexpr Reg<std::uint8_t> kType{0x0000, "Type"};
inline constexpr Reg<std::uint8_t> kRevision{0x0001, "Revision"};
inline constexpr Reg<std::uint16_t> kBuild{0x0002, "Build"};
inline constexpr Reg<std::uint8_t> kFmmusSupported{0x0004, "FMMUs supported"};
inline constexpr Reg<std::uint8_t> kSyncManagersSupported{0x0005, "SyncManagers supported"};
inline constexpr Reg<std::uint8_t> kRamSize{0x0006, "RAM Size"};
inline constexpr Reg<std::uint8_t> kPortDescriptor{0x0007, "Port Descriptor"};
inline constexpr Reg<std::uint16_t> kEscFeatures{0x0008, "ESC Features supported"};

// Station address
inline constexpr Reg<std::uint16_t> kConfiguredStationAddress{0x0010, "Configured Station Address"};
inline constexpr Reg<std::uint16_t> kConfiguredStationAlias{0x0012, "Configured Station Alias"};

// Write protection and reset
inline constexpr Reg<std::uint8_t> kRegisterWriteEnable{0x0020, "Register Write Enable"};
inline constexpr Reg<std::uint8_t> kRegisterWriteProtection{0x0021, "Register Write Protection"};
inline constexpr Reg<std::uint8_t> kEscWriteEnable{0x0030, "ESC Write Enable"};
inline constexpr Reg<std::uint8_t> kEscWriteProtection{0x0031, "ESC Write Protection"};
inline constexpr Reg<std::uint8_t> kEscResetEcat{0x0040, "ESC Reset ECAT"};
inline constexpr Reg<std::uint8_t> kEscResetPdi{0x0041, "ESC Reset PDI"};

// Data link layer
inline constexpr Reg<std::uint32_t> kDlControl{0x0100, "ESC DL Control"};
inline constexpr Reg<std::uint16_t> kPhysicalRwOffset{0x0108, "Physical Read/Write Offset"};
inline constexpr Reg<std::uint16_t> kDlStatus{0x0110, "ESC DL Status"};

// Application layer
inline constexpr Reg<std::uint16_t> kAlControl{0x0120, "AL Control"};
inline constexpr Reg<std::uint16_t> kAlStatus{0x0130, "AL Status"};
inline constexpr Reg<std::uint16_t> kAlStatusCode{0x0134, "AL Status Code"};
inline constexpr Reg<std::uint8_t> kRunLedOverride{0x0138, "RUN LED Override"};
inline constexpr Reg<std::uint8_t> kErrLedOverride{0x0139, "ERR LED Override"};

// PDI
inline constexpr Reg<std::uint8_t> kPdiControl{0x0140, "PDI Control"};
inline constexpr Reg<std::uint8_t> kEscConfiguration{0x0141, "ESC Configuration"};
inline constexpr Reg<std::uint16_t> kPdiInformation{0x014E, "PDI Information"};
inline constexpr Reg<std::uint8_t> kPdiConfiguration{0x0150, "PDI Configuration"};
inline constexpr Reg<std::uint8_t> kSyncLatchPdiConfiguration{0x0151,
                                                              "Sync/Latch[1:0] PDI Configuration"};
inline constexpr Reg<std::uint16_t> kExtendedPdiConfiguration{0x0152, "Extended PDI Configuration"};

// Interrupts
inline constexpr Reg<std::uint16_t> kEcatEventMask{0x0200, "ECAT Event Mask"};
inline constexpr Reg<std::uint32_t> kPdiAlEventMask{0x0204, "PDI0 AL Event Mask"};
inline constexpr Reg<std::uint16_t> kEcatEventRequest{0x0210, "ECAT Event Request"};
inline constexpr Reg<std::uint32_t> kAlEventRequest{0x0220, "AL Event Request"};

// Error counters (0x0300-0x0313); a write to any of them clears it (datasheet section II §2.9)
inline constexpr Reg<std::uint8_t> kInvalidFrameCounterPort0{0x0300,
                                                             "Invalid Frame Counter of Port 0"};
inline constexpr Reg<std::uint8_t> kRxErrorCounterPort0{0x0301, "RX Error Counter of Port 0"};
constexpr std::uint16_t rxErrorCounters(unsigned port) {  // 2 bytes: invalid frame, RX error
  return static_cast<std::uint16_t>(0x0300 + 2 * port);
}
constexpr std::uint16_t forwardedRxErrorCounter(unsigned port) {
  return static_cast<std::uint16_t>(0x0308 + port);
}
inline constexpr Reg<std::uint8_t> kEcatProcessingUnitErrorCounter{
    0x030C, "ECAT Processing Unit Error Counter"};
inline constexpr Reg<std::uint8_t> kPdiErrorCounter{0x030D, "PDI Error Counter"};
inline constexpr Reg<std::uint8_t> kPdiErrorCode{0x030E, "PDI Error Code"};
constexpr std::uint16_t lostLinkCounter(unsigned port) {
  return static_cast<std::uint16_t>(0x0310 + port);
}
inline constexpr std::uint16_t kErrorCountersBegin = 0x0300;
inline constexpr std::uint16_t kErrorCountersEnd = 0x0314;

// Watchdogs
inline constexpr Reg<std::uint16_t> kWatchdogDivider{0x0400, "Watchdog Divider"};
inline constexpr Reg<std::uint16_t> kWatchdogTimePdi{0x0410, "Watchdog Time PDI"};
inline constexpr Reg<std::uint16_t> kWatchdogTimeProcessData{0x0420, "Watchdog Time Process Data"};
inline constexpr Reg<std::uint16_t> kWatchdogStatusProcessData{0x0440,
                                                               "Watchdog Status Process Data"};
inline constexpr Reg<std::uint8_t> kWatchdogCounterProcessData{0x0442,
                                                               "Watchdog Counter Process Data"};
inline constexpr Reg<std::uint8_t> kWatchdogCounterPdi{0x0443, "Watchdog Counter PDI"};

// SII EEPROM interface
inline constexpr Reg<std::uint8_t> kSiiConfiguration{0x0500, "EEPROM Configuration"};
inline constexpr Reg<std::uint8_t> kSiiPdiAccessState{0x0501, "EEPROM PDI Access State"};
inline constexpr Reg<std::uint16_t> kSiiControlStatus{0x0502, "EEPROM Control/Status"};
inline constexpr Reg<std::uint32_t> kSiiAddress{0x0504, "EEPROM Address"};
inline constexpr Block kSiiData{0x0508, 8, "EEPROM Data"};

// MII management interface
inline constexpr Reg<std::uint16_t> kMiiControlStatus{0x0510, "MII Management Control/Status"};
inline constexpr Reg<std::uint8_t> kPhyAddress{0x0512, "PHY Address"};
inline constexpr Reg<std::uint8_t> kPhyRegisterAddress{0x0513, "PHY Register Address"};
inline constexpr Reg<std::uint16_t> kPhyData{0x0514, "PHY Data"};
inline constexpr Reg<std::uint8_t> kMiiEcatAccessState{0x0516, "MII Management ECAT Access State"};
inline constexpr Reg<std::uint8_t> kMiiPdiAccessState{0x0517, "MII Management PDI Access State"};

// FMMUs: 16 channels of 16 bytes from 0x0600
inline constexpr std::uint16_t kFmmuBase = 0x0600;
inline constexpr std::uint16_t kFmmuSize = 16;
inline constexpr unsigned kMaxFmmus = 16;
namespace fmmu {  // offsets within one FMMU channel
inline constexpr Reg<std::uint32_t> kLogicalStart{0x0, "Logical Start Address"};
inline constexpr Reg<std::uint16_t> kLength{0x4, "Length"};
inline constexpr Reg<std::uint8_t> kLogicalStartBit{0x6, "Logical Start bit"};
inline constexpr Reg<std::uint8_t> kLogicalStopBit{0x7, "Logical Stop bit"};
inline constexpr Reg<std::uint16_t> kPhysicalStart{0x8, "Physical Start Address"};
inline constexpr Reg<std::uint8_t> kPhysicalStartBit{0xA, "Physical Start bit"};
inline constexpr Reg<std::uint8_t> kType{0xB, "Type"};
inline constexpr Reg<std::uint8_t> kActivate{0xC, "Activate"};
inline constexpr std::uint8_t kTypeRead = 0x01;   // ECAT read access (inputs)
inline constexpr std::uint8_t kTypeWrite = 0x02;  // ECAT write access (outputs)
inline constexpr std::uint8_t kActivateEnable = 0x01;
inline constexpr std::uint8_t kBitMask = 0x07;  // start/stop bit registers: bits 2:0
inline constexpr Block kReserved{0xD, 3, "Reserved"};
}  // namespace fmmu
constexpr std::uint16_t fmmuChannel(unsigned n) {
  return static_cast<std::uint16_t>(kFmmuBase + kFmmuSize * n);
}

// SyncManagers: 16 channels of 8 bytes from 0x0800
inline constexpr std::uint16_t kSmBase = 0x0800;
inline constexpr std::uint16_t kSmSize = 8;
inline constexpr unsigned kMaxSyncManagers = 16;
namespace sm {  // offsets within one SyncManager channel
inline constexpr Reg<std::uint16_t> kPhysicalStart{0x0, "Physical Start Address"};
inline constexpr Reg<std::uint16_t> kLength{0x2, "Length"};
inline constexpr Reg<std::uint8_t> kControl{0x4, "Control Register"};
inline constexpr Reg<std::uint8_t> kStatus{0x5, "Status Register"};
inline constexpr Reg<std::uint8_t> kActivate{0x6, "Activate"};
inline constexpr Reg<std::uint8_t> kPdiControl{0x7, "PDI Control"};
// Control register bits
inline constexpr std::uint8_t kControlModeMask = 0x03;  // 00 buffered (3-buffer), 10 mailbox
inline constexpr std::uint8_t kControlModeBuffered = 0x00;
inline constexpr std::uint8_t kControlModeMailbox = 0x02;
inline constexpr std::uint8_t kControlDirectionMask = 0x0C;  // 00 ECAT read, 01 ECAT write
inline constexpr std::uint8_t kControlDirectionWrite = 0x04;
inline constexpr std::uint8_t kControlEcatEvent = 0x10;
inline constexpr std::uint8_t kControlPdiEvent = 0x20;
inline constexpr std::uint8_t kControlWatchdog = 0x40;
// Status register bits
inline constexpr std::uint8_t kStatusInterruptWrite = 0x01;
inline constexpr std::uint8_t kStatusInterruptRead = 0x02;
inline constexpr std::uint8_t kStatusMailboxFull = 0x08;
inline constexpr std::uint8_t kStatusBufferMask = 0x30;  // last written 3-buffer
inline constexpr std::uint8_t kStatusReadBufferOpen = 0x40;
inline constexpr std::uint8_t kStatusWriteBufferOpen = 0x80;
// Activate register bits
inline constexpr std::uint8_t kActivateEnable = 0x01;
inline constexpr std::uint8_t kActivateRepeatRequest = 0x02;
inline constexpr std::uint8_t kActivateLatchEcat = 0x40;
inline constexpr std::uint8_t kActivateLatchPdi = 0x80;
// PDI control bits
inline constexpr std::uint8_t kPdiDeactivate = 0x01;
inline constexpr std::uint8_t kPdiRepeatAck = 0x02;
}  // namespace sm
constexpr std::uint16_t smChannel(unsigned n) {
  return static_cast<std::uint16_t>(kSmBase + kSmSize * n);
}

// Distributed clocks
constexpr std::uint16_t receiveTime(unsigned port) {
  return static_cast<std::uint16_t>(0x0900 + 4 * port);
}
inline constexpr Reg<std::uint32_t> kReceiveTimePort0{0x0900, "Receive Time Port 0"};
inline constexpr Reg<std::uint32_t> kReceiveTimePort1{0x0904, "Receive Time Port 1"};
inline constexpr Reg<std::uint32_t> kReceiveTimePort2{0x0908, "Receive Time Port 2"};
inline constexpr Reg<std::uint32_t> kReceiveTimePort3{0x090C, "Receive Time Port 3"};
inline constexpr std::array<Reg<std::uint32_t>, 4> kReceiveTimePorts{
    kReceiveTimePort0, kReceiveTimePort1, kReceiveTimePort2, kReceiveTimePort3};
inline constexpr Reg<std::uint64_t> kSystemTime{0x0910, "System Time"};
inline constexpr Reg<std::uint64_t> kReceiveTimeEcatProcessingUnit{
    0x0918, "Receive Time ECAT Processing Unit"};
inline constexpr Reg<std::uint64_t> kSystemTimeOffset{0x0920, "System Time Offset"};
inline constexpr Reg<std::uint32_t> kSystemTimeDelay{0x0928, "System Time Delay"};
inline constexpr Reg<std::uint32_t> kSystemTimeDifference{0x092C, "System Time Difference"};
inline constexpr Reg<std::uint16_t> kSpeedCounterStart{0x0930, "Speed Counter Start"};
inline constexpr Reg<std::uint16_t> kSpeedCounterDiff{0x0932, "Speed Counter Diff"};
inline constexpr Reg<std::uint8_t> kSystemTimeDifferenceFilterDepth{
    0x0934, "System Time Difference Filter Depth"};
inline constexpr Reg<std::uint8_t> kSpeedCounterFilterDepth{0x0935, "Speed Counter Filter Depth"};
inline constexpr Reg<std::uint8_t> kReceiveTimeLatchMode{0x0936, "Receive Time Latch Mode"};
inline constexpr Reg<std::uint8_t> kCyclicUnitControl{0x0980, "Cyclic Unit Control"};
inline constexpr Reg<std::uint8_t> kDcActivation{0x0981, "Activation"};
inline constexpr Reg<std::uint16_t> kSyncPulseLength{0x0982, "Pulse Length of SyncSignals"};
inline constexpr Reg<std::uint8_t> kDcActivationStatus{0x0984, "Activation Status"};
inline constexpr Reg<std::uint8_t> kSync0Status{0x098E, "SYNC0 Status"};
inline constexpr Reg<std::uint8_t> kSync1Status{0x098F, "SYNC1 Status"};
inline constexpr Reg<std::uint64_t> kStartTimeCyclicOperation{0x0990,
                                                              "Start Time Cyclic Operation"};
inline constexpr Reg<std::uint64_t> kNextSync1Pulse{0x0998, "Next SYNC1 Pulse"};
inline constexpr Reg<std::uint32_t> kSync0CycleTime{0x09A0, "SYNC0 Cycle Time"};
inline constexpr Reg<std::uint32_t> kSync1CycleTime{0x09A4, "SYNC1 Cycle Time"};
inline constexpr Reg<std::uint8_t> kLatch0Control{0x09A8, "Latch0 Control"};
inline constexpr Reg<std::uint8_t> kLatch1Control{0x09A9, "Latch1 Control"};
inline constexpr Reg<std::uint8_t> kLatch0Status{0x09AE, "Latch0 Status"};
inline constexpr Reg<std::uint8_t> kLatch1Status{0x09AF, "Latch1 Status"};
inline constexpr Reg<std::uint64_t> kLatch0TimePositiveEdge{0x09B0, "Latch0 Time Positive Edge"};
inline constexpr Reg<std::uint64_t> kLatch0TimeNegativeEdge{0x09B8, "Latch0 Time Negative Edge"};
inline constexpr Reg<std::uint64_t> kLatch1TimePositiveEdge{0x09C0, "Latch1 Time Positive Edge"};
inline constexpr Reg<std::uint64_t> kLatch1TimeNegativeEdge{0x09C8, "Latch1 Time Negative Edge"};
inline constexpr Reg<std::uint32_t> kEcatBufferChangeEventTime{0x09F0,
                                                               "EtherCAT Buffer Change Event Time"};
inline constexpr Reg<std::uint32_t> kPdiBufferStartEventTime{0x09F8, "PDI Buffer Start Event Time"};
inline constexpr Reg<std::uint32_t> kPdiBufferChangeEventTime{0x09FC,
                                                              "PDI Buffer Change Event Time"};

// ESC specific
inline constexpr Reg<std::uint32_t> kDigitalIoOutputData{0x0F00, "Digital I/O Output Data"};
inline constexpr Reg<std::uint64_t> kGeneralPurposeOutputs{0x0F10, "General Purpose Outputs"};
inline constexpr Reg<std::uint64_t> kGeneralPurposeInputs{0x0F18, "General Purpose Inputs"};
inline constexpr Block kUserRam{0x0F80, 128, "User RAM"};

inline constexpr std::uint16_t kRegisterSpaceEnd = 0x1000;  // process RAM starts here
// Where the digital I/O PDI writes the digital inputs: the first bytes of process RAM
// (ESC datasheet section II, Digital I/O Input Data, 0x1000:0x1003).
inline constexpr Block kDigitalIoInputData{0x1000, 4, "Digital I/O Input Data"};
// PDI control 0x0140 values of the digital I/O PDI (section II 0x0140): 4 digital inputs,
// 4 digital outputs, 2 of each, digital I/O.
inline constexpr std::uint8_t kPdiFourDigitalInputs = 0x01;
inline constexpr std::uint8_t kPdiDigitalIo = 0x04;

// ---- bit fields -----------------------------------------------------------------------------
namespace dl_status {  // 0x0110
inline constexpr std::uint16_t kPdiOperational = 0x0001;
inline constexpr std::uint16_t kPdiWatchdogStatus = 0x0002;  // 1 = not expired
inline constexpr std::uint16_t kEnhancedLinkDetection = 0x0004;
constexpr std::uint16_t physicalLink(unsigned port) {
  return static_cast<std::uint16_t>(0x0010u << port);
}
constexpr std::uint16_t loopPort(unsigned port) {
  return static_cast<std::uint16_t>(0x0100u << (2 * port));
}
constexpr std::uint16_t communication(unsigned port) {
  return static_cast<std::uint16_t>(0x0200u << (2 * port));
}
}  // namespace dl_status

namespace dl_control {  // 0x0100-0x0103 (ESC datasheet section II, ESC DL Control)
inline constexpr std::uint32_t kForwardingRule = 0x00000001;  // 1: destroy non-EtherCAT frames
inline constexpr std::uint32_t kTemporaryLoop = 0x00000002;   // loop setting for about 1 s only
inline constexpr std::uint32_t kRxFifoSizeShift = 16;         // bits 16-18
// Reset value: forwarding rule set, RX FIFO size 7 (section II; the XMC4800's ESC SVD agrees).
inline constexpr std::uint32_t kResetValue = 0x00000001 | (7u << kRxFifoSizeShift);
// Loop control, 2 bits per port in byte 0x0101 (section I §3.1).
inline constexpr std::uint8_t kLoopMask = 0x03;
inline constexpr std::uint8_t kLoopAuto = 0x00;
inline constexpr std::uint8_t kLoopAutoClose = 0x01;
inline constexpr std::uint8_t kLoopOpen = 0x02;    // open whatever the link: no link loses frames
inline constexpr std::uint8_t kLoopClosed = 0x03;  // closed whatever the link: nothing received
constexpr std::uint8_t loopSetting(std::uint8_t loopByte, unsigned port) {
  return static_cast<std::uint8_t>((loopByte >> (2 * port)) & kLoopMask);
}
}  // namespace dl_control

namespace ecat_event {  // 0x0200 ECAT event mask / 0x0210 ECAT event request (section II)
inline constexpr std::uint16_t kDcLatch = 0x0001;   // latch status 0x09AE/0x09AF shows an event
inline constexpr std::uint16_t kDlStatus = 0x0004;  // DL status changed; ECAT read of 0x0110 clears
inline constexpr std::uint16_t kAlStatus = 0x0008;  // AL status changed; ECAT read of 0x0130 clears
inline constexpr unsigned kSmShift = 4;             // bit 4 + n: SyncManager n event
inline constexpr unsigned kMaxSmEvents = 8;         // bits 4-11 (SM0-7); 12-15 reserved
inline constexpr std::uint16_t kSmBits = 0x0FF0;
// Reset value: DL status event pending (the ports' link state is new after reset; seen in
// soem-sdinfo-ek1100-el1004.pcapng, where IRQ 0x0004 is set from the first frame after the
// mask write, frame 15, until the master reads 0x0110 of the last slave, frame 201).
inline constexpr std::uint16_t kResetValue = kDlStatus;
}  // namespace ecat_event

namespace al_event {  // 0x0220 AL event request (section II)
inline constexpr std::uint32_t kAlControl = 0x00000001;  // AL control written; PDI read clears
inline constexpr std::uint32_t kDcLatch = 0x00000002;    // a PDI-owned latch unit has an event
}  // namespace al_event

namespace latch {  // DC latch unit (section II 0x0980, 0x09A8-0x09CF)
// 0x0980 cyclic unit control: latch unit 0 (bit 4) / 1 (bit 5) controlled by the PDI (1) or
// ECAT (0); the owner writes the control register and its read of a time clears the event.
inline constexpr std::uint8_t kPdiControlledUnit0 = 0x10;
// 0x09A8/0x09A9 latch control: 1 = single event (only the first edge until read), 0 =
// continuous (every edge, no event).
inline constexpr std::uint8_t kControlSinglePositive = 0x01;
inline constexpr std::uint8_t kControlSingleNegative = 0x02;
inline constexpr std::uint8_t kControlMask = 0x03;
// 0x09AE/0x09AF latch status: edge events (single-event mode only) and the pin's level.
inline constexpr std::uint8_t kStatusPositiveEvent = 0x01;
inline constexpr std::uint8_t kStatusNegativeEvent = 0x02;
inline constexpr std::uint8_t kStatusEvents = 0x03;
inline constexpr std::uint8_t kStatusPin = 0x04;
// Time registers: unit u, edge e (0 positive, 1 negative) at 0x09B0 + 16u + 8e.
constexpr std::uint16_t timeRegister(unsigned unit, bool negativeEdge) {
  return static_cast<std::uint16_t>(kLatch0TimePositiveEdge.address + 16 * unit +
                                    (negativeEdge ? 8 : 0));
}
inline constexpr unsigned kUnits = 2;
}  // namespace latch

namespace al {  // 0x0120 / 0x0130
inline constexpr std::uint16_t kStateMask = 0x000F;
inline constexpr std::uint16_t kErrorFlag = 0x0010;  // status: error indication; control: ack
inline constexpr std::uint16_t kDeviceIdentification = 0x0020;
}  // namespace al

namespace sii {  // 0x0502 EEPROM control/status
inline constexpr std::uint16_t kWriteEnable = 0x0001;
inline constexpr std::uint16_t kReadSize8Bytes = 0x0040;   // 1: 8-byte reads, 0: 4-byte reads
inline constexpr std::uint16_t kTwoAddressBytes = 0x0080;  // 1: EEPROM > 16 kbit
inline constexpr std::uint16_t kCommandMask = 0x0700;
inline constexpr std::uint16_t kCommandNop = 0x0000;
inline constexpr std::uint16_t kCommandRead = 0x0100;
inline constexpr std::uint16_t kCommandWrite = 0x0200;
inline constexpr std::uint16_t kCommandReload = 0x0400;
inline constexpr std::uint16_t kChecksumError = 0x0800;
inline constexpr std::uint16_t kDeviceInfoError = 0x1000;
inline constexpr std::uint16_t kCommandError = 0x2000;  // missing acknowledge / invalid command
inline constexpr std::uint16_t kWriteEnableError = 0x4000;
inline constexpr std::uint16_t kBusy = 0x8000;
inline constexpr std::uint16_t kErrorMask = 0x7800;
}  // namespace sii

namespace features {  // 0x0008 ESC features supported
inline constexpr std::uint16_t kFmmuBitOperationNotSupported = 0x0001;
inline constexpr std::uint16_t kDistributedClocks = 0x0004;
inline constexpr std::uint16_t kDcWidth64 = 0x0008;
inline constexpr std::uint16_t kEnhancedLinkDetectionEbus = 0x0040;
inline constexpr std::uint16_t kEnhancedLinkDetectionMii = 0x0080;
inline constexpr std::uint16_t kSeparateFcsErrorHandling = 0x0100;
inline constexpr std::uint16_t kLrwNotSupported = 0x0400;
inline constexpr std::uint16_t kBrwAprwFprwNotSupported = 0x0800;
}  // namespace features

// ---- lookup ----------------------------------------------------------------------------------
struct RegisterInfo {
  std::uint16_t address;
  std::uint16_t width;
  std::string_view name;
};

// Every named register outside the repeated FMMU/SM blocks, in address order.
std::span<const RegisterInfo> registerTable();
// The register containing address (FMMU and SM channels included), if any.
std::optional<RegisterInfo> findRegister(std::uint16_t address);

}  // namespace ecsim::reg
