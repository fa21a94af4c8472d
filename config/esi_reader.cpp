// ESI reader: roots, vendor, groups, devices, modules and slots.

#include <fmt/core.h>

#include "config/esi_parts.hpp"
#include "protocol/read_file.hpp"

namespace ecsim {
namespace {

using esi_detail::readDictionary;
using esi_detail::readModule;
using esi_detail::readPdo;
using xml::Children;
using xml::Context;
using xml::Element;

// A number in the text of `e`, plus channel * ChnFac when `e` has a ChnFac attribute (PDO
// templates of 2006-era files).
template <typename T>
Result<T> channelNumber(const Context& ctx, const Element* e, std::string_view what,
                        std::int64_t channel) {
  const std::string_view raw = xml::text(e);
  auto value = parseEsiInteger(raw);
  if (!value.ok()) return ctx.error(e, std::string(what) + ": " + value.error().context);
  const std::int64_t factor = e->Int64Attribute("ChnFac", 0);
  return xml::narrow<T>(ctx, e, what, raw, *value + channel * factor);
}

// "Channel #1" with channel offset 2 -> "Channel #3" (template names count from 1).
std::string renumberChannel(const std::string& name, std::int64_t offset) {
  const std::size_t hash = name.rfind('#');
  if (hash == std::string::npos || hash + 1 >= name.size()) return name;
  std::size_t end = hash + 1;
  while (end < name.size() && name[end] >= '0' && name[end] <= '9') ++end;
  if (end == hash + 1 || end - hash > 10) return name;
  std::int64_t number = offset;
  std::int64_t digits = 0;
  for (std::size_t i = hash + 1; i < end; ++i) digits = digits * 10 + (name[i] - '0');
  number += digits;
  return name.substr(0, hash + 1) + std::to_string(number) + name.substr(end);
}

Status readVendor(const Context& ctx, const Element* e, EsiVendor& out) {
  if (e == nullptr) return okStatus();
  ECSIM_ASSIGN_OR_RETURN(auto id, xml::childNumber<std::uint32_t>(ctx, e, "Id"));
  out.id = id.value_or(0);
  out.names = xml::localTexts(e, "Name");
  return okStatus();
}

Result<EsiFmmu> readFmmu(const Context& ctx, const Element* e) {
  EsiFmmu out;
  out.text = std::string(xml::text(e));
  ECSIM_ASSIGN_OR_RETURN(out.sm, xml::attrNumber<std::uint8_t>(ctx, e, "Sm"));
  ECSIM_ASSIGN_OR_RETURN(out.opOnly, xml::attrBool(ctx, e, "OpOnly", false));
  return out;
}

Result<EsiSyncManager> readSyncManager(const Context& ctx, const Element* e) {
  EsiSyncManager out;
  out.text = std::string(xml::text(e));
  ECSIM_ASSIGN_OR_RETURN(auto start, xml::attrNumber<std::uint16_t>(ctx, e, "StartAddress"));
  ECSIM_ASSIGN_OR_RETURN(auto size, xml::attrNumber<std::uint16_t>(ctx, e, "DefaultSize"));
  ECSIM_ASSIGN_OR_RETURN(out.minSize, xml::attrNumber<std::uint16_t>(ctx, e, "MinSize"));
  ECSIM_ASSIGN_OR_RETURN(out.maxSize, xml::attrNumber<std::uint16_t>(ctx, e, "MaxSize"));
  ECSIM_ASSIGN_OR_RETURN(auto control, xml::attrNumber<std::uint8_t>(ctx, e, "ControlByte"));
  if (const char* enable = e->Attribute("Enable"); enable != nullptr) {
    if (auto flag = parseEsiBool(enable); flag.ok()) {
      out.enable = *flag ? 1 : 0;
    } else {
      ECSIM_ASSIGN_OR_RETURN(out.enable,
                             xml::parseNumber<std::uint8_t>(ctx, e, "attribute Enable", enable));
    }
  }
  ECSIM_ASSIGN_OR_RETURN(out.isVirtual, xml::attrBool(ctx, e, "Virtual", false));
  ECSIM_ASSIGN_OR_RETURN(out.opOnly, xml::attrBool(ctx, e, "OpOnly", false));
  ECSIM_ASSIGN_OR_RETURN(out.fixed, xml::attrBool(ctx, e, "Fixed", false));
  out.startAddress = start.value_or(0);
  out.defaultSize = size.value_or(0);
  out.controlByte = control.value_or(0);
  return out;
}

Status readMailbox(const Context& ctx, const Element* e, EsiMailbox& out) {
  if (e == nullptr) return okStatus();
  out.present = true;
  ECSIM_ASSIGN_OR_RETURN(out.dataLinkLayer, xml::attrBool(ctx, e, "DataLinkLayer", false));
  out.aoe = e->FirstChildElement("AoE") != nullptr;
  out.eoe = e->FirstChildElement("EoE") != nullptr;
  out.foe = e->FirstChildElement("FoE") != nullptr;
  out.voe = e->FirstChildElement("VoE") != nullptr;
  if (const Element* soe = e->FirstChildElement("SoE"); soe != nullptr) {
    out.soe = true;
    ECSIM_ASSIGN_OR_RETURN(auto channels, xml::attrNumber<std::uint8_t>(ctx, soe, "ChannelCount"));
    out.soeChannels = channels.value_or(1);
  }
  if (const Element* coe = e->FirstChildElement("CoE"); coe != nullptr) {
    out.coe = true;
    EsiCoe& c = out.coeDetails;
    ECSIM_ASSIGN_OR_RETURN(c.sdoInfo, xml::attrBool(ctx, coe, "SdoInfo", false));
    ECSIM_ASSIGN_OR_RETURN(c.pdoAssign, xml::attrBool(ctx, coe, "PdoAssign", false));
    ECSIM_ASSIGN_OR_RETURN(c.pdoConfig, xml::attrBool(ctx, coe, "PdoConfig", false));
    ECSIM_ASSIGN_OR_RETURN(c.pdoUpload, xml::attrBool(ctx, coe, "PdoUpload", false));
    ECSIM_ASSIGN_OR_RETURN(c.completeAccess, xml::attrBool(ctx, coe, "CompleteAccess", false));
    ECSIM_ASSIGN_OR_RETURN(c.segmentedSdo, xml::attrBool(ctx, coe, "SegmentedSdo", false));
    ECSIM_ASSIGN_OR_RETURN(auto ds402, xml::attrNumber<std::uint8_t>(ctx, coe, "DS402Channels"));
    c.ds402Channels = ds402.value_or(0);
  }
  return okStatus();
}

Result<EsiDcOpMode> readOpMode(const Context& ctx, const Element* e) {
  EsiDcOpMode out;
  out.name = std::string(xml::childText(e, "Name"));
  out.description = std::string(xml::childText(e, "Desc"));
  ECSIM_ASSIGN_OR_RETURN(auto assign, xml::childNumber<std::uint16_t>(ctx, e, "AssignActivate"));
  out.assignActivate = assign.value_or(0);
  struct Cycle {
    const char* name;
    std::uint32_t* time;
    std::int32_t* factor;
  };
  for (const Cycle& c : {Cycle{"CycleTimeSync0", &out.cycleTimeSync0, &out.cycleTimeSync0Factor},
                         Cycle{"CycleTimeSync1", &out.cycleTimeSync1, &out.cycleTimeSync1Factor}}) {
    const Element* t = e->FirstChildElement(c.name);
    if (t == nullptr) continue;
    ECSIM_ASSIGN_OR_RETURN(auto time, xml::childNumber<std::uint32_t>(ctx, e, c.name));
    ECSIM_ASSIGN_OR_RETURN(auto factor, xml::attrNumber<std::int32_t>(ctx, t, "Factor"));
    *c.time = time.value_or(0);
    *c.factor = factor.value_or(0);
  }
  ECSIM_ASSIGN_OR_RETURN(auto shift0, xml::childNumber<std::int64_t>(ctx, e, "ShiftTimeSync0"));
  ECSIM_ASSIGN_OR_RETURN(auto shift1, xml::childNumber<std::int64_t>(ctx, e, "ShiftTimeSync1"));
  out.shiftTimeSync0 = shift0.value_or(0);
  out.shiftTimeSync1 = shift1.value_or(0);
  return out;
}

Result<EsiEeprom> readEeprom(const Context& ctx, const Element* e) {
  EsiEeprom out;
  ECSIM_ASSIGN_OR_RETURN(out.byteSize, xml::childNumber<std::uint32_t>(ctx, e, "ByteSize"));
  ECSIM_ASSIGN_OR_RETURN(out.configData, xml::childHex(ctx, e, "ConfigData"));
  ECSIM_ASSIGN_OR_RETURN(out.bootStrap, xml::childHex(ctx, e, "BootStrap"));
  ECSIM_ASSIGN_OR_RETURN(out.data, xml::childHex(ctx, e, "Data"));
  for (const Element* c : Children(e, "Category")) {
    EsiEepromCategory category;
    ECSIM_ASSIGN_OR_RETURN(auto type, xml::childNumber<std::uint16_t>(ctx, c, "CatNo"));
    if (!type) return ctx.error(c, "Eeprom Category without CatNo");
    category.type = *type;
    ECSIM_ASSIGN_OR_RETURN(category.data, xml::childHex(ctx, c, "Data"));
    out.categories.push_back(std::move(category));
  }
  return out;
}

// The ESC memory an SM of the ESI occupies: 3 x its length in 3-buffer mode (control byte
// bits 0-1 = 00), 1 x in mailbox mode; an SM of length 1 is no buffer, only its byte (ESC
// datasheet section I, SyncManager chapter; issue #15 item 3). Beckhoff_EM2xxx.xml has two
// such 1-byte SMs side by side at 0x0F00/0x0F01 (line 31-32): they do not overlap.
std::pair<std::uint32_t, std::uint32_t> smArea(const EsiSyncManager& sm) {
  const bool buffered = (sm.controlByte & 0x03) == 0x00 && sm.defaultSize > 1;
  return {sm.startAddress, sm.startAddress + sm.defaultSize * (buffered ? 3u : 1u)};
}

// SMs whose areas overlap are a warning (the device is still built as written: what the ESC
// does with overlapping SMs is the ESC model's business).
void warnOverlappingSyncManagers(const Context& ctx, const std::vector<EsiSyncManager>& sms,
                                 const std::vector<const Element*>& elements) {
  for (std::size_t i = 0; i < sms.size(); ++i) {
    const auto [a0, a1] = smArea(sms[i]);
    for (std::size_t j = i + 1; j < sms.size(); ++j) {
      const auto [b0, b1] = smArea(sms[j]);
      if (a0 == a1 || b0 == b1 || a1 <= b0 || b1 <= a0) continue;
      ctx.warn(elements[j], fmt::format("Sm {} (0x{:04X}-0x{:04X}) overlaps Sm {} (line {}, "
                                        "0x{:04X}-0x{:04X})",
                                        j, b0, b1 - 1, i, elements[i]->GetLineNum(), a0, a1 - 1));
    }
  }
}

Status readSlots(const Context& ctx, const Element* e, std::vector<EsiSlot>& out) {
  if (e == nullptr) return okStatus();
  ECSIM_ASSIGN_OR_RETURN(auto indexIncrement,
                         xml::attrNumber<std::uint32_t>(ctx, e, "SlotIndexIncrement"));
  ECSIM_ASSIGN_OR_RETURN(auto pdoIncrement,
                         xml::attrNumber<std::uint32_t>(ctx, e, "SlotPdoIncrement"));
  for (const Element* s : Children(e, "Slot")) {
    EsiSlot slot;
    slot.line = s->GetLineNum();
    slot.name = std::string(xml::childText(s, "Name"));
    ECSIM_ASSIGN_OR_RETURN(auto ownIndex,
                           xml::attrNumber<std::uint32_t>(ctx, s, "SlotIndexIncrement"));
    ECSIM_ASSIGN_OR_RETURN(auto ownPdo, xml::attrNumber<std::uint32_t>(ctx, s, "SlotPdoIncrement"));
    slot.indexIncrement = ownIndex.value_or(indexIncrement.value_or(0));
    slot.pdoIncrement = ownPdo.value_or(pdoIncrement.value_or(0));
    ECSIM_ASSIGN_OR_RETURN(auto min, xml::attrNumber<std::uint32_t>(ctx, s, "MinInstances"));
    ECSIM_ASSIGN_OR_RETURN(auto max, xml::attrNumber<std::uint32_t>(ctx, s, "MaxInstances"));
    slot.minInstances = min.value_or(0);
    slot.maxInstances = max.value_or(0);
    for (const Element* c : Children(s, "ModuleClass")) {
      slot.moduleClasses.emplace_back(xml::childText(c, "Class"));
    }
    for (const Element* m : Children(s, "ModuleIdent")) {
      ECSIM_ASSIGN_OR_RETURN(auto ident,
                             xml::parseNumber<std::uint32_t>(ctx, m, "ModuleIdent", xml::text(m)));
      slot.moduleIdents.push_back(ident);
      ECSIM_ASSIGN_OR_RETURN(const bool isDefault, xml::attrBool(ctx, m, "Default", false));
      if (isDefault && !slot.defaultModuleIdent) slot.defaultModuleIdent = ident;
    }
    out.push_back(std::move(slot));
  }
  return okStatus();
}

Status readPdos(const Context& ctx, const Element* parent, const char* name,
                std::vector<EsiPdo>& out, const Element* pdoTemplates = nullptr) {
  for (const Element* p : Children(parent, name)) {
    ECSIM_ASSIGN_OR_RETURN(auto pdo, readPdo(ctx, p, pdoTemplates));
    out.push_back(std::move(pdo));
  }
  return okStatus();
}

Status readModules(const Context& ctx, const Element* modules, std::vector<EsiModule>& out) {
  for (const Element* m : Children(modules, "Module")) {
    ECSIM_ASSIGN_OR_RETURN(auto module, readModule(ctx, m));
    out.push_back(std::move(module));
  }
  return okStatus();
}

Result<EsiDevice> readDevice(const Context& ctx, const Element* e, const Element* pdoTemplates) {
  EsiDevice out;
  out.line = e->GetLineNum();
  if (const char* physics = e->Attribute("Physics")) out.physics = physics;
  ECSIM_ASSIGN_OR_RETURN(out.invisible, xml::attrBool(ctx, e, "Invisible", false));
  const Element* type = e->FirstChildElement("Type");
  if (type == nullptr) return ctx.error(e, "Device without Type");
  out.type = std::string(xml::text(type));
  ECSIM_ASSIGN_OR_RETURN(auto product, xml::attrNumber<std::uint32_t>(ctx, type, "ProductCode"));
  ECSIM_ASSIGN_OR_RETURN(auto revision, xml::attrNumber<std::uint32_t>(ctx, type, "RevisionNo"));
  ECSIM_ASSIGN_OR_RETURN(out.useLrdLwr, xml::attrBool(ctx, type, "UseLrdLwr", false));
  out.hasProductCode = product.has_value();
  out.productCode = product.value_or(0);
  out.revision = revision.value_or(0);
  out.names = xml::localTexts(e, "Name");
  out.groupType = std::string(xml::childText(e, "GroupType"));
  out.imageName = std::string(xml::childText(e, "Image16x14"));
  if (const Element* info = e->FirstChildElement("Info"); info != nullptr) {
    const Element* electrical = info->FirstChildElement("Electrical");
    ECSIM_ASSIGN_OR_RETURN(out.ebusCurrent,
                           xml::childNumber<std::int32_t>(
                               ctx, electrical != nullptr ? electrical : info, "EBusCurrent"));
    ECSIM_ASSIGN_OR_RETURN(out.identificationAdo,
                           xml::childNumber<std::uint16_t>(ctx, info, "IdentificationAdo"));
    const std::string_view reg134 = xml::childText(info, "IdentificationReg134");
    out.identificationReg134 = reg134 == "1" || reg134 == "true";
  }
  for (const Element* profile : Children(e, "Profile")) {
    ECSIM_ASSIGN_OR_RETURN(auto number, xml::childNumber<std::uint32_t>(ctx, profile, "ProfileNo"));
    if (number && !out.profileNo) out.profileNo = number;
    ECSIM_TRY(readDictionary(ctx, profile->FirstChildElement("Dictionary"), out.dictionary));
  }
  for (const Element* f : Children(e, "Fmmu")) {
    ECSIM_ASSIGN_OR_RETURN(auto fmmu, readFmmu(ctx, f));
    out.fmmus.push_back(std::move(fmmu));
  }
  std::vector<const Element*> smElements;
  for (const Element* s : Children(e, "Sm")) {
    ECSIM_ASSIGN_OR_RETURN(auto sm, readSyncManager(ctx, s));
    out.syncManagers.push_back(std::move(sm));
    smElements.push_back(s);
  }
  warnOverlappingSyncManagers(ctx, out.syncManagers, smElements);
  ECSIM_TRY(readPdos(ctx, e, "RxPdo", out.rxPdos, pdoTemplates));
  ECSIM_TRY(readPdos(ctx, e, "TxPdo", out.txPdos, pdoTemplates));
  ECSIM_TRY(readMailbox(ctx, e->FirstChildElement("Mailbox"), out.mailbox));
  for (const Element* m : Children(e->FirstChildElement("Dc"), "OpMode")) {
    ECSIM_ASSIGN_OR_RETURN(auto mode, readOpMode(ctx, m));
    out.dcOpModes.push_back(std::move(mode));
  }
  if (const Element* eeprom = e->FirstChildElement("Eeprom"); eeprom != nullptr) {
    ECSIM_ASSIGN_OR_RETURN(auto contents, readEeprom(ctx, eeprom));
    out.eeprom = std::move(contents);
  }
  ECSIM_TRY(readSlots(ctx, e->FirstChildElement("Slots"), out.slots));
  ECSIM_TRY(readModules(ctx, e->FirstChildElement("Modules"), out.modules));
  return out;
}

Result<EsiFile> readDocument(const Context& ctx, const tinyxml2::XMLDocument& doc) {
  EsiFile file;
  file.path = ctx.file();
  const Element* root = doc.RootElement();
  if (root == nullptr) return ctx.error(1, "no root element");
  const std::string_view rootName = root->Name();
  if (rootName == "EtherCATInfo") {
    file.root = EsiRoot::kEtherCatInfo;
  } else if (rootName == "EtherCATDict") {
    file.root = EsiRoot::kEtherCatDict;
  } else if (rootName == "EtherCATModule") {
    file.root = EsiRoot::kEtherCatModule;
  } else {
    return ctx.error(root, "root element <" + std::string(rootName) +
                               "> is none of EtherCATInfo, EtherCATDict, EtherCATModule");
  }
  if (const char* version = root->Attribute("Version")) file.version = version;
  ECSIM_TRY(readVendor(ctx, root->FirstChildElement("Vendor"), file.vendor));
  ECSIM_TRY(readDictionary(ctx, root->FirstChildElement("Dictionary"), file.dictionary));
  ECSIM_TRY(readModules(ctx, root->FirstChildElement("Modules"), file.modules));
  const Element* descriptions = root->FirstChildElement("Descriptions");
  for (const Element* g :
       Children(descriptions ? descriptions->FirstChildElement("Groups") : nullptr, "Group")) {
    file.groups.push_back({std::string(xml::childText(g, "Type")), xml::localTexts(g, "Name")});
  }
  const Element* pdoTemplates = descriptions ? descriptions->FirstChildElement("Pdos") : nullptr;
  for (const Element* d :
       Children(descriptions ? descriptions->FirstChildElement("Devices") : nullptr, "Device")) {
    ECSIM_ASSIGN_OR_RETURN(auto device, readDevice(ctx, d, pdoTemplates));
    file.devices.push_back(std::move(device));
  }
  if (descriptions != nullptr) {
    ECSIM_TRY(readModules(ctx, descriptions->FirstChildElement("Modules"), file.modules));
  }
  return file;
}

}  // namespace

namespace esi_detail {

Result<EsiPdo> readPdo(const Context& ctx, const Element* e, const Element* pdoTemplates) {
  EsiPdo out;
  out.line = e->GetLineNum();
  // The body (Index, Name, Exclude, Entry) comes from the element itself or its template.
  const Element* body = e;
  std::int64_t channel = 0;
  if (const char* ref = e->Attribute("Ref");
      ref != nullptr && e->FirstChildElement("Index") == nullptr) {
    out.ref = ref;
    body = nullptr;
    for (const Element* t : Children(pdoTemplates, "Pdo")) {
      if (const char* name = t->Attribute("RefName"); name != nullptr && out.ref == name) {
        body = t;
        break;
      }
    }
    if (body == nullptr)
      return ctx.error(
          e, std::string(e->Name()) + " Ref '" + out.ref + "' names no <Pdos><Pdo RefName>");
    ECSIM_ASSIGN_OR_RETURN(auto chn, xml::attrNumber<std::int64_t>(ctx, e, "Chn"));
    channel = chn.value_or(0);
  }
  ECSIM_ASSIGN_OR_RETURN(out.sm, xml::attrNumber<std::uint8_t>(ctx, e, "Sm"));
  ECSIM_ASSIGN_OR_RETURN(out.fixed, xml::attrBool(ctx, e, "Fixed", false));
  ECSIM_ASSIGN_OR_RETURN(out.mandatory, xml::attrBool(ctx, e, "Mandatory", false));
  ECSIM_ASSIGN_OR_RETURN(out.isVirtual, xml::attrBool(ctx, e, "Virtual", false));

  const Element* index = body->FirstChildElement("Index");
  if (index == nullptr) return ctx.error(body, std::string(e->Name()) + " without Index");
  ECSIM_ASSIGN_OR_RETURN(out.index, channelNumber<std::uint16_t>(ctx, index, "PDO Index", channel));
  ECSIM_ASSIGN_OR_RETURN(out.dependOnSlot, xml::attrBool(ctx, index, "DependOnSlot", false));
  for (const Element* n : Children(body, "Name")) {
    EsiLocalText name{n->UnsignedAttribute("LcId", 0), std::string(xml::text(n))};
    if (channel != 0 && n->Attribute("ChnFac") != nullptr) {
      name.text = renumberChannel(name.text, channel * n->Int64Attribute("ChnFac", 0));
    }
    out.names.push_back(std::move(name));
  }
  for (const Element* x : Children(body, "Exclude")) {
    ECSIM_ASSIGN_OR_RETURN(auto excluded, channelNumber<std::uint16_t>(ctx, x, "Exclude", channel));
    out.excludes.push_back(excluded);
  }
  for (const Element* n : Children(body, "Entry")) {
    EsiPdoEntry entry;
    const Element* entryIndex = n->FirstChildElement("Index");
    if (entryIndex == nullptr) return ctx.error(n, "PDO Entry without Index");
    ECSIM_ASSIGN_OR_RETURN(entry.index,
                           channelNumber<std::uint16_t>(ctx, entryIndex, "Entry Index", channel));
    ECSIM_ASSIGN_OR_RETURN(entry.dependOnSlot,
                           xml::attrBool(ctx, entryIndex, "DependOnSlot", false));
    if (const Element* sub = n->FirstChildElement("SubIndex"); sub != nullptr) {
      ECSIM_ASSIGN_OR_RETURN(entry.subIndex,
                             channelNumber<std::uint8_t>(ctx, sub, "SubIndex", channel));
    }
    ECSIM_ASSIGN_OR_RETURN(auto bits, xml::childNumber<std::uint16_t>(ctx, n, "BitLen"));
    if (!bits) return ctx.error(n, "PDO Entry without BitLen");
    entry.bitLength = *bits;
    entry.name = std::string(xml::childText(n, "Name"));
    entry.dataType = std::string(xml::childText(n, "DataType"));
    out.entries.push_back(std::move(entry));
  }
  return out;
}

Result<EsiModule> readModule(const Context& ctx, const Element* e) {
  EsiModule out;
  out.line = e->GetLineNum();
  if (const Element* type = e->FirstChildElement("Type"); type != nullptr) {
    out.type = std::string(xml::text(type));
    ECSIM_ASSIGN_OR_RETURN(auto ident, xml::attrNumber<std::uint32_t>(ctx, type, "ModuleIdent"));
    out.moduleIdent = ident.value_or(0);
    if (const char* cls = type->Attribute("ModuleClass")) out.moduleClass = cls;
  }
  out.names = xml::localTexts(e, "Name");
  ECSIM_TRY(readPdos(ctx, e, "RxPdo", out.rxPdos));
  ECSIM_TRY(readPdos(ctx, e, "TxPdo", out.txPdos));
  for (const Element* profile : Children(e, "Profile")) {
    ECSIM_TRY(readDictionary(ctx, profile->FirstChildElement("Dictionary"), out.dictionary));
  }
  return out;
}

}  // namespace esi_detail

Result<EsiFile> parseEsi(std::string_view xmlText, std::string_view fileName) {
  std::vector<std::string> warnings;
  const Context ctx{std::string(fileName), &warnings};
  tinyxml2::XMLDocument doc(true, tinyxml2::PRESERVE_WHITESPACE);
  ECSIM_TRY(xml::parseDocument(xmlText, ctx, doc));
  ECSIM_ASSIGN_OR_RETURN(EsiFile file, readDocument(ctx, doc));
  file.warnings = std::move(warnings);
  file.encoding = xml::declaredEncoding(xmlText);
  return file;
}

Result<EsiFile> loadEsiFile(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string content, readRegularFile(path, kMaxXmlFileBytes));
  return parseEsi(content, path.string());
}

}  // namespace ecsim
