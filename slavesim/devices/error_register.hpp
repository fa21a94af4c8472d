// The CiA 301 error register, object 0x1001 (UNSIGNED8, read-only): which kinds of error a
// device has at present. Bit 0 (generic) is set whenever any error is present; the others say
// of which kind it is. Device models write it through an ObjectRef when their dictionary has
// the object (examples/esi: every CoE device; real ESI files may lack it, e.g. Beckhoff's
// terminals) and clear it when the error goes.
//
//   ECS7201/ECS7211 (Cia402Drive)  cia402::errorRegisterFor(error code) while in Fault, 0
//                                  after the fault reset (the emergency carries the same byte)
//   ECS3102 (AnalogInputTerminal)  generic + voltage while a channel is under- or overrange
//                                  (its status bit 6 "error"), as CANopen voltage-input
//                                  modules do (Turck BL20 AI U: emergency 0x3003, bit 2)
//   SSI encoder (SsiEncoderTerminal, when the dictionary has 0x1001)
//                                  generic while a channel has a data or frame error; voltage
//                                  too while the encoder's supply has failed
#pragma once

#include <cstdint>

namespace ecsim::slavesim::devices::error_register {

inline constexpr std::uint16_t kIndex = 0x1001;

inline constexpr std::uint8_t kGeneric = 1u << 0;
inline constexpr std::uint8_t kCurrent = 1u << 1;
inline constexpr std::uint8_t kVoltage = 1u << 2;
inline constexpr std::uint8_t kTemperature = 1u << 3;
inline constexpr std::uint8_t kCommunication = 1u << 4;
inline constexpr std::uint8_t kDeviceProfile = 1u << 5;
inline constexpr std::uint8_t kManufacturer = 1u << 7;

}  // namespace ecsim::slavesim::devices::error_register
