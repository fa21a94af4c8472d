// Pieces of the ESI reader shared between its source files. Internal to config/.
#pragma once

#include "config/esi.hpp"
#include "config/xml_util.hpp"

namespace ecsim::esi_detail {

// Appends the DataTypes and Objects of a <Dictionary> element.
Status readDictionary(const xml::Context& ctx, const xml::Element* dictionary, EsiDictionary& out);

// Reads an RxPdo/TxPdo element. `pdoTemplates` is the <Descriptions><Pdos> element of
// 2006-era files whose devices write <RxPdo Ref="name" Chn="n" .../>: the PDO is then the
// <Pdo RefName="name"> there, with every number carrying a ChnFac attribute increased by
// Chn * ChnFac.
Result<EsiPdo> readPdo(const xml::Context& ctx, const xml::Element* e,
                       const xml::Element* pdoTemplates = nullptr);

// Reads a <Module> element (EtherCATModule root or Descriptions/Modules).
Result<EsiModule> readModule(const xml::Context& ctx, const xml::Element* e);

}  // namespace ecsim::esi_detail
