#include "master/eni_config.hpp"

#include <cstdio>

#include "protocol/frame.hpp"

namespace ecsim::master {
namespace {

std::string hex8(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

bool hasTransition(const std::vector<EniTransition>& list, char from, char to) {
  for (const auto& t : list) {
    if (t.from == from && t.to == to) return true;
  }
  return false;
}

}  // namespace

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

char eniStateLetter(AlState state) {
  switch (state) {
    case AlState::kInit:
      return 'I';
    case AlState::kPreOp:
      return 'P';
    case AlState::kBootstrap:
      return 'B';
    case AlState::kSafeOp:
      return 'S';
    case AlState::kOp:
      return 'O';
  }
  return 'I';
}

std::size_t addEniRegisterCmds(DatagramBatch& batch, const EniSlave& slave, char from, char to,
                               std::vector<int>* lines) {
  constexpr std::uint16_t kAlControl = 0x0120;
  std::size_t added = 0;
  for (const EniRegisterCmd& c : slave.initCmds) {
    if (!hasTransition(c.transitions, from, to)) continue;
    if (c.ado == kAlControl) continue;
    const auto command = static_cast<Command>(c.cmd);
    const std::uint32_t address = DatagramHeader::physical(c.adp, c.ado);
    const std::uint16_t wkc = c.cnt.value_or(1);
    Datagram& d = batch.add();
    if (c.data.empty()) {
      d.prepare(command, address, static_cast<std::uint16_t>(c.length()), wkc);
    } else {
      d.prepare(command, address, ConstBytes(c.data.data(), c.data.size()), wkc);
    }
    if (lines != nullptr) lines->push_back(c.line);
    ++added;
  }
  return added;
}

std::vector<const EniCoeCmd*> eniCoeCmds(const EniSlave& slave, char from, char to) {
  std::vector<const EniCoeCmd*> list;
  if (!slave.mailbox) return list;
  for (const EniCoeCmd& c : slave.mailbox->coeInitCmds) {
    if (hasTransition(c.transitions, from, to)) list.push_back(&c);
  }
  return list;
}

}  // namespace ecsim::master
