// Reads the master configuration with tinyxml2 (the library config/ uses for its readers).
#include "master/master_config.hpp"

#include <tinyxml2.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "config/esi.hpp"

namespace ecsim::master {
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

std::string hex8(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
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

Result<MasterConfig> loadMasterConfig(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return makeError(ErrorCode::kIo, path.string() + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parseMasterConfig(text.str(), path.string());
}

Status checkIdentities(const MasterConfig& config, const std::vector<SlaveInfo>& slaves) {
  if (config.slaves.size() != slaves.size()) {
    return makeError(ErrorCode::kNotFound,
                     config.file + " expects " + std::to_string(config.slaves.size()) +
                         " slaves, the bus has " + std::to_string(slaves.size()));
  }
  std::string context;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    const ExpectedSlave& want = config.slaves[i];
    const SiiIdentity& have = slaves[i].identity();
    std::string diff;
    auto compare = [&](std::string_view what, std::uint32_t expected, std::uint32_t found) {
      if (expected == found) return;
      diff += (diff.empty() ? "" : ", ") + std::string(what) + " " + hex8(found) + " (expected " +
              hex8(expected) + ")";
    };
    compare("vendor", want.vendorId, have.vendorId);
    compare("product code", want.productCode, have.productCode);
    if (want.revision) compare("revision", *want.revision, have.revision);
    if (want.serial) compare("serial", *want.serial, have.serial);
    if (diff.empty()) continue;
    std::string expected = want.name.empty() ? "" : " configured as '" + want.name + "'";
    context += (context.empty() ? "" : "; ") + slaves[i].label() + expected + ", " + config.file +
               " line " + std::to_string(want.line) + ": " + diff;
  }
  if (context.empty()) return okStatus();
  return makeError(ErrorCode::kInvalidArgument, "identity mismatch: " + context);
}

}  // namespace ecsim::master
