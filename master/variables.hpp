// Process data by name: every PDO entry of the process image as a variable named
// "<slave>.<entry>" ("Drive1.Statusword", "DI1.Input 3"), like the pins of a LinuxCNC HAL
// component, with typed access to the bits it occupies in the process image.
//
//   slave  the name the configuration gives the slave (SlaveInfo::configuredName: a topology's
//          or ENI's slave name, Master::setSlaveNames), else its SII order string ("ECS1008")
//          or, without one, its SII device name; when several
//          slaves share a name, each is "<name>_<position>"; "<position>" always works too
//   entry  the entry's name (PDO entry name from the SII or dictionary); when a slave has two
//          entries of that name, "<pdo name>.<entry name>"; "0xIIII:SS" always works too
//
// Bits are little-endian in the image, as on the wire (ETG.1000.4: bit 0 of a byte first).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "master/process_image.hpp"
#include "master/slave_info.hpp"
#include "protocol/result.hpp"

namespace ecsim::master {

// How the bits of an entry are read: from the CoE data type where known, else from its size.
enum class VariableType : std::uint8_t {
  kBool,
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kReal32,
  kReal64,
  kBits,  // any other width: an unsigned bit field
};
std::string_view toString(VariableType type);
// From a CoE data type (ETG.1000.6 Table 64: 0x0001 BOOL ... 0x001B UINT64) and bit length.
VariableType variableType(std::uint16_t dataType, std::uint8_t bitLength);

struct VariableInfo {
  std::string name;   // "Drive1.Statusword"
  std::string slave;  // "Drive1"
  std::string entry;  // "Statusword"
  std::size_t position{0};
  bool output{true};
  std::uint32_t bitOffset{0};  // in the process image
  std::uint8_t bitLength{0};
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  std::uint16_t dataType{0};
  VariableType type{VariableType::kBits};
};

// Reads/writes `bitLength` (1..64) bits at `bitOffset` of `image`, little-endian.
std::uint64_t readBits(ConstBytes image, std::uint32_t bitOffset, std::uint8_t bitLength);
void writeBits(Bytes image, std::uint32_t bitOffset, std::uint8_t bitLength, std::uint64_t value);

// A variable bound to a process image (the master's, which stays where it is while the
// master lives). get/set never allocate.
class PdoVariable {
 public:
  PdoVariable(VariableInfo info, std::vector<std::uint8_t>& image)
      : info_(std::move(info)), image_(&image) {}

  const VariableInfo& info() const { return info_; }
  const std::string& name() const { return info_.name; }

  std::uint64_t raw() const;
  void setRaw(std::uint64_t value);

  // Integral types: the bits, sign-extended when the variable's type is signed; bool: not 0;
  // float/double: the IEEE bits of a REAL32/REAL64, else the integer value converted.
  template <typename T>
  T get() const {
    if constexpr (std::is_same_v<T, bool>) {
      return raw() != 0;
    } else if constexpr (std::is_floating_point_v<T>) {
      return static_cast<T>(asDouble());
    } else {
      return static_cast<T>(signedValue());
    }
  }
  template <typename T>
  void set(T value) {
    if constexpr (std::is_floating_point_v<T>) {
      setDouble(static_cast<double>(value));
    } else {
      setRaw(static_cast<std::uint64_t>(value));
    }
  }

  double asDouble() const;
  void setDouble(double value);
  // "1", "-12", "0x1F" for a bit field wider than 1 bit, "3.25" for a REAL.
  std::string format() const;

 private:
  std::int64_t signedValue() const;

  VariableInfo info_;
  std::vector<std::uint8_t>* image_;
};

// Every entry of the layout, named as above.
// The naming rule's last step for the variables of one slave, `slave` and `entry` set and `name`
// holding the name of the PDO the entry came from: an entry name two PDOs share becomes
// "<pdo>.<entry>", and every name "<slave>.<entry>". The master's and the simulated slaves'
// (embed/slave_variables.hpp) names are made by it, so they are the same names.
void finishVariableNames(std::span<VariableInfo> slaveVariables);
std::vector<VariableInfo> nameVariables(const ProcessImageLayout& layout,
                                        const std::vector<SlaveInfo>& slaves);
// Finds `name` (or an alias as above) among `variables`; kNotFound names the closest variables
// ("no process variable 'Drive1.StatusWord'; closest: Drive1.Statusword, Drive2.Statusword").
Result<VariableInfo> findVariable(const std::vector<VariableInfo>& variables,
                                  std::string_view name);

}  // namespace ecsim::master
