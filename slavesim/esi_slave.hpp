// A simulated slave built from an ESI device description:
//   SII image  config/sii_builder.hpp (or the vendor's <Eeprom><Data> image as it is);
//   ESC type   chooseEscType() below, unless the options name one;
//   profile    standard mailbox from the SII (which the builder takes from the ESI MBoxOut /
//              MBoxIn SMs), process-data SM lengths from the PDO configuration;
//   dictionary coe/od_from_esi.hpp, identity taken from the SII so SII and 0x1018 agree;
//   mailbox    a CoeServer for any device with a standard mailbox (SdoInfo / CompleteAccess
//              from the ESI <CoE> element); other protocols (and CoE, when the ESI mailbox
//              has none) get "unsupported protocol" mailbox error replies; a device whose
//              ESI mailbox has <SoE> gets an SoE server (soe/soe_server.hpp) with one drive
//              per <SoE ChannelCount>, its IDNs from options.soeDictionary;
//   device     ProcessDataDevice over the same dictionary (also for SII-only slaves, whose
//              dictionary no mailbox reaches); ESI Virtual SMs are neither checked nor copied;
//              ecsim's own devices get their model (IO terminal, CiA 402 drive), and any
//              device whose ESI describes a CiA 402 axis a drive per axis, and another
//              vendor's IO device the io or analog profile of its PDO entries, as its
//              application, see devices/device_models.hpp and devices/io_profile.hpp.
// Modular devices come with their modules already in `device` (config/esi_modules.hpp, done by
// the topology builder). BOOT: the SII bootstrap mailbox (ESI <Eeprom><BootStrap>) is checked
// at INIT->BOOT (0x0015), and an foe::FoeServer answers FoE there (and in the mailbox states
// when the ESI mailbox has <FoE/>); a power cycle boots the image written in BOOT.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "protocol/result.hpp"
#include "protocol/sii.hpp"
#include "slavesim/coe/coe_server.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/devices/device_models.hpp"
#include "slavesim/eoe/eoe_server.hpp"
#include "slavesim/esc_type.hpp"
#include "slavesim/process_data.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::slavesim {

struct EsiSlaveOptions {
  std::uint32_t vendorId{0};  // <Vendor><Id>; the EsiFile overload fills it in
  std::uint32_t serial{0};
  std::optional<EscType> escType;
  // SII string 1 (SOEM's slave name): the ESI <Name> when true, the <Type> text otherwise.
  bool deviceNameFirst{true};
  // Attach the device model devices::deviceModelFor() names, for another vendor's device
  // without one devices::chooseIoProfile's (false: plain process data).
  bool deviceModels{true};
  // The model a topology names (model="cia402|io|analog|loopback|none"); unset: the choice above.
  std::optional<devices::DeviceModelKind> model;
  // Persistent device state (a drive's shaft position), TopologySlave::stateFile; when set it
  // wins over models.stateFile. A device with FoE keeps its files in the folder beside it
  // (foe::foeFolderFor, foe_folder.hpp).
  std::filesystem::path stateFile;
  // Parameters of the device model (devices/device_params.hpp). A drive's emergencies go to
  // the slave's CoE server unless models.emergencies is set.
  devices::DeviceModelOptions models;
  // SoE devices (ESI <Mailbox><SoE>): each drive's IDNs from this EtherCATDict dictionary
  // (soe/idn_dictionary.hpp; a topology's <Slave soeDictionary=>); nullptr: the IDN lists
  // every drive has, nothing else (said in `warnings`). `soeDictionaryFile` names it.
  const EsiDictionary* soeDictionary{nullptr};
  std::string soeDictionaryFile;
  // Where the build says what it could not take as written (dictionary notes of
  // coe::buildObjectDictionary, a default PDO configuration that cannot be bound); nullptr: not
  // reported.
  std::vector<std::string>* warnings{nullptr};
};

// ET1100 by default. A LAN9252-class ESC (4 SMs, 3 FMMUs, 2 ports, 4 KB process RAM) when
// the device fits it: at most 4 SMs and 3 FMMUs in the ESI, at most 2 ports in its Physics,
// and every SM inside 0x1000-0x1FFF.
EscType chooseEscType(const EsiDevice& device);

Result<std::unique_ptr<Slave>> makeSlaveFromEsi(const EsiDevice& device, std::string name,
                                                const EsiSlaveOptions& options = {});
// Same, with the vendor id from the file.
Result<std::unique_ptr<Slave>> makeSlaveFromEsi(const EsiFile& file, const EsiDevice& device,
                                                std::string name, EsiSlaveOptions options = {});

// The parts of a slave made by makeSlaveFromEsi (nullptr for other slaves).
ProcessDataDevice* processDataDeviceOf(Slave& slave);
coe::ObjectDictionary* objectDictionaryOf(Slave& slave);
coe::CoeServer* coeServerOf(Slave& slave);
// The EoE server behind the slave's mailbox (ESI <Mailbox><EoE>), or nullptr.
eoe::EoeServer* eoeServerOf(Slave& slave);
// A sink that queues emergencies on the slave's CoE server (empty without one), for
// devices::attachDeviceModel when a model is re-created (a simulated power cycle).
devices::EmergencySink emergencySinkOf(Slave& slave);

}  // namespace ecsim::slavesim
