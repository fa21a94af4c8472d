// ecsim's own drive ESI (examples/esi/ecsim_devices.xml) changed for one test: objects a vendor
// drive may have and the ECS7201 has not (CiA 402 factor group, digital inputs, touch probe)
// added to the ECS7201's dictionary, and text replaced, written into the test's folder. The
// project's ESI stays as it is.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {

struct EsiVariant {
  std::string dataTypes;  // <DataType> elements for the ECS7201's <DataTypes>
  std::string objects;    // <Object> elements for its <Objects>
  std::vector<std::pair<std::string, std::string>> replacements;  // everywhere in the file
};

// A RECORD of two UDINTs (:01 numerator, :02 denominator), as the factor group objects
// 0x608F, 0x6091 and 0x6092 are (IEC 61800-7-201 / CiA 402-2), named DT_RATIO.
inline constexpr const char* kRatioDataType =
    "<DataType><Name>DT_RATIO</Name><BitSize>80</BitSize>"
    "<SubItem><SubIdx>0</SubIdx><Name>Highest sub-index</Name><Type>USINT</Type><BitSize>8</BitSize>"
    "<BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>"
    "<SubItem><SubIdx>1</SubIdx><Name>Numerator</Name><Type>UDINT</Type><BitSize>32</BitSize>"
    "<BitOffs>16</BitOffs><Flags><Access>rw</Access></Flags></SubItem>"
    "<SubItem><SubIdx>2</SubIdx><Name>Denominator</Name><Type>UDINT</Type><BitSize>32</BitSize>"
    "<BitOffs>48</BitOffs><Flags><Access>rw</Access></Flags></SubItem></DataType>\n";

// An <Object> of DT_RATIO with its two default values.
inline std::string ratioObject(const char* index, const char* name, std::uint32_t numerator,
                               std::uint32_t denominator) {
  return std::string("<Object><Index>") + index + "</Index><Name>" + name +
         "</Name><Type>DT_RATIO</Type><BitSize>80</BitSize><Info>"
         "<SubItem><Name>Highest sub-index</Name><Info><DefaultValue>2</DefaultValue></Info></SubItem>"
         "<SubItem><Name>Numerator</Name><Info><DefaultValue>" +
         std::to_string(numerator) +
         "</DefaultValue></Info></SubItem>"
         "<SubItem><Name>Denominator</Name><Info><DefaultValue>" +
         std::to_string(denominator) +
         "</DefaultValue></Info></SubItem></Info><Flags><Access>rw</Access></Flags></Object>\n";
}

// A VAR <Object> (e.g. "UDINT", 32, "ro", "T").
inline std::string varObject(const char* index, const char* name, const char* type, int bits,
                             const char* access, const char* pdoMapping = nullptr) {
  return std::string("<Object><Index>") + index + "</Index><Name>" + name + "</Name><Type>" +
         type + "</Type><BitSize>" + std::to_string(bits) +
         "</BitSize><Info><DefaultValue>0</DefaultValue></Info><Flags><Access>" + access +
         "</Access>" +
         (pdoMapping != nullptr ? std::string("<PdoMapping>") + pdoMapping + "</PdoMapping>" : "") +
         "</Flags></Object>\n";
}

inline std::filesystem::path writeEcs7201Variant(const std::filesystem::path& path,
                                                 const EsiVariant& variant) {
  std::ifstream in(examplesEsiPath());
  std::stringstream text;
  text << in.rdbuf();
  std::string esi = text.str();
  for (const auto& [from, to] : variant.replacements) {
    for (auto at = esi.find(from); at != std::string::npos; at = esi.find(from, at + to.size())) {
      esi.replace(at, from.size(), to);
    }
  }
  const auto device = esi.find("<Type ProductCode=\"#x00007201\"");
  EXPECT_NE(device, std::string::npos);
  if (device != std::string::npos) {
    const auto objects = esi.find("</Objects>", device);
    esi.insert(objects, variant.objects);
    const auto types = esi.find("</DataTypes>", device);
    esi.insert(types, variant.dataTypes);
  }
  std::ofstream(path) << esi;
  return path;
}

}  // namespace ecsim::testing
