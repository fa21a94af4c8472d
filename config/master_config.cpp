// Reads the master configuration with tinyxml2; ENI files through config/eni.hpp. The simple
// <EcsimMaster> format is ours and read strictly: any element or attribute besides those in
// master_config.hpp is an error with the closest valid name (a misspelt `revison` left the
// revision unchecked).
#include "config/master_config.hpp"

#include <tinyxml2.h>

#include <cstdio>

#include "config/eni.hpp"
#include "config/esi.hpp"
#include "config/xml_util.hpp"
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

// What each element takes (the file's comment in master_config.hpp); anything else is an error.
const xml::Names kRootNames{{}, {"Slave"}};
const xml::Names kSlaveNames{{"name", "vendor", "product", "revision", "serial"}};

}  // namespace

Result<MasterConfig> parseMasterConfig(std::string_view xml, std::string_view fileName) {
  const xml::Context ctx{std::string(fileName)};
  tinyxml2::XMLDocument doc;
  ECSIM_TRY(xml::parseDocument(xml, ctx, doc));
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "EcsimMaster") {
    return parseError(fileName, root ? root->GetLineNum() : 1,
                      "root element must be <EcsimMaster>");
  }
  ECSIM_TRY(xml::checkNames(ctx, root, kRootNames));
  MasterConfig config;
  config.file = std::string(fileName);
  for (const auto* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    ECSIM_TRY(xml::checkNames(ctx, e, kSlaveNames));
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
