#include "slavesim/esi_slave.hpp"

#include <algorithm>

#include "config/sii_builder.hpp"
#include "slavesim/coe/od_from_esi.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/devices/device_models.hpp"
#include "slavesim/eoe/eoe_server.hpp"
#include "slavesim/foe/foe_folder.hpp"
#include "slavesim/foe/foe_server.hpp"
#include "slavesim/generic_slave.hpp"
#include "slavesim/soe/soe_server.hpp"

namespace ecsim::slavesim {
namespace {

constexpr std::uint32_t kRamStart = reg::kRegisterSpaceEnd;

std::size_t portCount(const EsiDevice& device) {
  std::size_t n = 0;
  for (char c : device.physics) n += c == ' ' ? 0 : 1;
  return n == 0 ? 2 : n;
}

}  // namespace

EscType chooseEscType(const EsiDevice& device) {
  const EscType& small = kLan9252;
  if (device.syncManagers.size() > small.syncManagers || device.fmmus.size() > small.fmmus ||
      portCount(device) > small.maxPorts) {
    return kEt1100;
  }
  const std::uint32_t ramEnd = kRamStart + static_cast<std::uint32_t>(small.ramKb) * 1024;
  for (const auto& sm : device.syncManagers) {
    const std::uint32_t size = std::max<std::uint32_t>(sm.defaultSize, sm.maxSize.value_or(0));
    if (sm.startAddress < kRamStart || sm.startAddress + size > ramEnd) return kEt1100;
  }
  return small;
}

Result<std::unique_ptr<Slave>> makeSlaveFromEsi(const EsiDevice& device, std::string name,
                                                const EsiSlaveOptions& options) {
  SiiBuildOptions siiOptions;
  siiOptions.serial = options.serial;
  siiOptions.deviceNameFirst = options.deviceNameFirst;
  ECSIM_ASSIGN_OR_RETURN(SiiContents sii, makeSiiContents(device, options.vendorId, siiOptions));

  coe::OdBuildOptions odOptions;
  odOptions.vendorId = options.vendorId;
  odOptions.serial = options.serial;
  coe::OdBuildReport report;
  auto od = std::make_shared<coe::ObjectDictionary>(
      coe::buildObjectDictionary(device, odOptions, &report));
  if (options.warnings != nullptr) {
    for (auto& note : report.notes) options.warnings->push_back(std::move(note));
  }
  // A PDO that kept the dictionary's mapping is described so in the SII too: a master reading
  // the SII PDO categories and one reading CoE build the same process image.
  for (std::uint16_t index : report.keptMappings) {
    for (auto* list : {&sii.txPdos, &sii.rxPdos}) {
      for (SiiPdo& p : *list) {
        if (p.index != index) continue;
        p.entries.clear();
        for (const coe::MappedObject& m : coe::mappedObjects(*od, index)) {
          SiiPdoEntry e;
          e.index = m.index;
          e.subIndex = m.subindex;
          e.bitLength = m.bitLength;
          if (const coe::Entry* o = od->findEntry(m.index, m.subindex);
              o != nullptr && o->dataType <= 0xFF) {
            e.dataType = static_cast<std::uint8_t>(o->dataType);
          }
          p.entries.push_back(e);
        }
      }
    }
  }
  std::vector<std::uint8_t> image;
  if (device.eeprom && device.eeprom->data.size() >= sii::kHeaderBytes) {
    image = device.eeprom->data;  // the vendor's own image, as the device carries it
  } else {
    ECSIM_ASSIGN_OR_RETURN(image, encodeSii(sii));
  }

  SlaveProfile profile;
  const SiiMailbox& mbx = sii.standardMailbox;
  if (mbx.receiveSize > 0) {
    profile.mailbox = SlaveProfile::Mailbox{mbx.receiveOffset, mbx.receiveSize, mbx.sendOffset,
                                            mbx.sendSize != 0 ? mbx.sendSize : mbx.receiveSize};
  }
  // BOOT: the bootstrap mailbox layout of the SII (ESI <Eeprom><BootStrap>).
  const SiiMailbox& boot = sii.bootstrapMailbox;
  if (profile.mailbox && boot.receiveSize > 0 && boot.sendSize > 0) {
    profile.bootstrapMailbox =
        SlaveProfile::Mailbox{boot.receiveOffset, boot.receiveSize, boot.sendOffset, boot.sendSize};
  }
  // FoE: in the mailbox states when the ESI mailbox names it, in BOOT whenever there is one.
  // With a state file the files outlive the simulator, beside it (foe_folder.hpp); what was
  // kept there is booted now, as at any power-up.
  std::shared_ptr<foe::FoeFiles> foeFiles;
  if (profile.mailbox && (device.mailbox.foe || profile.bootstrapMailbox)) {
    if (options.stateFile.empty()) {
      foeFiles = std::make_shared<foe::FoeFiles>();
    } else {
      ECSIM_ASSIGN_OR_RETURN(foeFiles, foe::FoeFiles::keptIn(foe::foeFolderFor(options.stateFile)));
      ECSIM_TRY(foe::installFirmware(*foeFiles, *od));
    }
  }

  // 0x1018 says what the SII says (they differ when a vendor image carries another identity).
  coe::addIdentityObject(*od, {sii.identity.vendorId, sii.identity.productCode,
                               sii.identity.revision, sii.identity.serial});

  auto pd = std::make_unique<ProcessDataDevice>(od);
  std::uint32_t virtualSms = 0;
  for (std::size_t n = 0; n < device.syncManagers.size() && n < 32; ++n) {
    if (device.syncManagers[n].isVirtual) virtualSms |= 1u << n;
  }
  pd->setVirtualSyncManagers(virtualSms);
  pd->updateProfile(profile);
  if (!pd->bindStatus().ok() && options.warnings != nullptr) {
    // A real device with this description would refuse PREOP->SAFEOP with 0x001D/0x001E until
    // a master assigns PDOs it can bind; say so now rather than only in the AL status code.
    options.warnings->push_back("the default PDO configuration cannot be bound (" +
                                pd->bindStatus().error().context +
                                "): PREOP->SAFEOP is refused until a master assigns PDOs that "
                                "can be");
  }
  profile.sync.initialMode = profile.sync.mode;
  profile.sync.dcSupported = !device.dcOpModes.empty();
  if (options.deviceModels) {
    devices::DeviceModelOptions modelOptions = options.models;
    if (!options.stateFile.empty()) modelOptions.stateFile = options.stateFile;
    const bool driveObjects = od->findEntry(devices::cia402::obj::kControlword, 0) != nullptr &&
                              od->findEntry(devices::cia402::obj::kStatusword, 0) != nullptr;
    devices::DeviceModelKind kind = options.model.value_or(devices::deviceModelFor(
        sii.identity.vendorId, sii.identity.productCode, device.profileNo, driveObjects));
    if (!options.model && kind == devices::DeviceModelKind::kNone &&
        sii.identity.vendorId != kEcsimVendorId) {
      // A vendor's device: an encoder when its TxPDOs carry counter values, else IO.
      kind = !devices::counterValueChannels(*od).empty()
                 ? devices::DeviceModelKind::kEncoder
                 : devices::chooseIoProfile(*od, device.profileNo);
    }
    ECSIM_TRY(devices::attachDeviceModel(*pd, kind, modelOptions));
    // A power cycle re-creates the model as built here (plus what outlives the power) and
    // boots the firmware written over FoE in BOOT, if any.
    pd->setRestart([kind, modelOptions, foeFiles](ProcessDataDevice& d) -> Status {
      if (foeFiles) ECSIM_TRY(foe::installFirmware(*foeFiles, d.dictionary()));
      return devices::restartDeviceModel(d, kind, modelOptions);
    });
  } else if (foeFiles) {
    pd->setRestart([foeFiles](ProcessDataDevice& d) {
      return foe::installFirmware(*foeFiles, d.dictionary());
    });
  }

  auto slave =
      std::make_unique<Slave>(std::move(name), options.escType.value_or(chooseEscType(device)),
                              std::move(image), std::move(profile));
  if (slave->profile().mailbox) {
    coe::CoeServerOptions coeOptions;
    coeOptions.coe = device.mailbox.coe;
    coeOptions.sdoInfo = device.mailbox.coeDetails.sdoInfo;
    coeOptions.completeAccess = device.mailbox.coeDetails.completeAccess;
    auto server = std::make_unique<coe::CoeServer>(od, coeOptions);
    if (device.mailbox.eoe) server->addProtocol(std::make_unique<eoe::EoeServer>());
    if (foeFiles) {
      foe::FoeServerOptions foeOptions;
      foeOptions.outsideBoot = device.mailbox.foe;
      server->addProtocol(std::make_unique<foe::FoeServer>(foeFiles, foeOptions));
    }
    if (device.mailbox.soe) {
      const EsiDictionary none;
      if (options.soeDictionary == nullptr && options.warnings != nullptr) {
        options.warnings->push_back(
            "the ESI mailbox has SoE but no SoE dictionary is given: the drive serves only the "
            "IDN lists every drive has");
      }
      std::vector<soe::IdnDictionary> drives;
      for (unsigned n = 0; n < std::max<unsigned>(1, device.mailbox.soeChannels); ++n) {
        drives.push_back(soe::buildIdnDictionary(
            options.soeDictionary != nullptr ? *options.soeDictionary : none,
            options.soeDictionaryFile, n == 0 ? options.warnings : nullptr));
      }
      server->addProtocol(std::make_unique<soe::SoeServer>(std::move(drives)));
    }
    slave->setMailboxServer(std::move(server));
  }
  slave->setDevice(std::move(pd));
  for (unsigned axis = 0; !options.models.emergencies; ++axis) {
    devices::Cia402Drive* drive = devices::driveOf(*slave, axis);
    if (drive == nullptr) break;
    drive->setEmergencySink(emergencySinkOf(*slave));
  }
  return slave;
}

Result<std::unique_ptr<Slave>> makeSlaveFromEsi(const EsiFile& file, const EsiDevice& device,
                                                std::string name, EsiSlaveOptions options) {
  options.vendorId = file.vendor.id;
  return makeSlaveFromEsi(device, std::move(name), options);
}

ProcessDataDevice* processDataDeviceOf(Slave& slave) {
  return dynamic_cast<ProcessDataDevice*>(slave.device());
}

coe::ObjectDictionary* objectDictionaryOf(Slave& slave) {
  ProcessDataDevice* pd = processDataDeviceOf(slave);
  return pd == nullptr ? nullptr : &pd->dictionary();
}

coe::CoeServer* coeServerOf(Slave& slave) {
  return dynamic_cast<coe::CoeServer*>(slave.mailboxServer());
}

eoe::EoeServer* eoeServerOf(Slave& slave) {
  coe::CoeServer* server = coeServerOf(slave);
  if (server == nullptr) return nullptr;
  return dynamic_cast<eoe::EoeServer*>(server->protocol(MailboxType::kEoe));
}

devices::EmergencySink emergencySinkOf(Slave& slave) {
  coe::CoeServer* server = coeServerOf(slave);
  if (server == nullptr) return {};
  return [server](const Emergency& e) { server->pushEmergency(e); };
}

}  // namespace ecsim::slavesim
