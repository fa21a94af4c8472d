// Reads the master configuration with tinyxml2; ENI files through config/eni.hpp.
#include "config/master_config.hpp"

#include <tinyxml2.h>

#include <cstdio>

#include "config/eni.hpp"
#include "config/esi.hpp"
#include "protocol/read_file.hpp"

namespace ecsim {
namespace {

Error parseError(std::string_view file, int line, const std::string& what) {
  return makeError(ErrorCode::kParse,
                   std::string(file) + ", line " + std::to_string(line) + ": " + what);
}

Result<std::optional<std::uint32_t>> attribute(const tinyxml2::XMLElement* e, const char* name,
                                               std::string_view file) {
  const char* raw = e->Attribute(name);
  if (raw == nullptr) return std::optional<std::uint32_t>{};
  auto value = parseEsiInteger(raw);
  if (!value.ok() || *value < 0 || *value > 0xFFFFFFFFLL) {
    return parseError(file, e->GetLineNum(),
                      std::string("attribute ") + name + ": '" + raw + "' is not a 32-bit number");
  }
  return std::optional<std::uint32_t>{static_cast<std::uint32_t>(*value)};
}

}  // namespace

Result<MasterConfig> parseMasterConfig(std::string_view xml, std::string_view fileName) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    return parseError(fileName, doc.ErrorLineNum(), doc.ErrorStr() ? doc.ErrorStr() : "bad XML");
  }
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "EcsimMaster") {
    return parseError(fileName, root ? root->GetLineNum() : 1,
                      "root element must be <EcsimMaster>");
  }
  MasterConfig config;
  config.file = std::string(fileName);
  for (const auto* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    if (std::string_view(e->Name()) != "Slave") {
      return parseError(fileName, e->GetLineNum(),
                        "unknown element <" + std::string(e->Name()) + ">");
    }
    ExpectedSlave slave;
    slave.line = e->GetLineNum();
    if (const char* name = e->Attribute("name")) slave.name = name;
    ECSIM_ASSIGN_OR_RETURN(auto vendor, attribute(e, "vendor", fileName));
    ECSIM_ASSIGN_OR_RETURN(auto product, attribute(e, "product", fileName));
    if (!vendor || !product) {
      return parseError(fileName, e->GetLineNum(), "<Slave> needs vendor and product");
    }
    slave.vendorId = *vendor;
    slave.productCode = *product;
    ECSIM_ASSIGN_OR_RETURN(slave.revision, attribute(e, "revision", fileName));
    ECSIM_ASSIGN_OR_RETURN(slave.serial, attribute(e, "serial", fileName));
    config.slaves.push_back(std::move(slave));
  }
  return config;
}

MasterConfig masterConfigFromEni(EniConfig eni) {
  MasterConfig config;
  config.file = eni.file.string();
  for (const EniSlave& s : eni.slaves) {
    ExpectedSlave slave;
    slave.name = s.name;
    slave.vendorId = s.vendorId;
    slave.productCode = s.productCode;
    slave.revision = s.revisionNo;
    // ENI tools write SerialNo 0 when they do not check it.
    if (s.serialNo && *s.serialNo != 0) slave.serial = s.serialNo;
    slave.station = s.physAddr;
    slave.line = s.line;
    config.slaves.push_back(std::move(slave));
  }
  config.eni = std::move(eni);
  return config;
}

Result<MasterConfig> loadMasterConfig(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string xml, readRegularFile(path, kMaxXmlFileBytes));
  return readMasterConfig(xml, path);
}

Result<MasterConfig> readMasterConfig(std::string_view xml, const std::filesystem::path& path) {
  tinyxml2::XMLDocument doc;
  const bool parsed = doc.Parse(xml.data(), xml.size()) == tinyxml2::XML_SUCCESS;
  if (parsed && doc.RootElement() != nullptr &&
      std::string_view(doc.RootElement()->Name()) == "EtherCATConfig") {
    ECSIM_ASSIGN_OR_RETURN(EniConfig eni, parseEni(xml, path));
    return masterConfigFromEni(std::move(eni));
  }
  return parseMasterConfig(xml, path.string());
}

}  // namespace ecsim
