#include "slavesim/soe/soe_server.hpp"

#include <algorithm>

#include "slavesim/al_state_machine.hpp"

namespace ecsim::slavesim::soe {
namespace {

// The communication phase whose write protection applies (ETG.1000.6 §5.9: PREOP = CP2,
// SAFEOP = CP3, OP = CP4).
unsigned phaseOf(const Esc& esc) {
  switch (AlStateMachine::state(esc)) {
    case AlState::kSafeOp:
      return 3;
    case AlState::kOp:
      return 4;
    default:
      return 2;
  }
}

// -1, 0, 1 as a < b, a == b, a > b for two values of `entry`'s type.
int compare(const IdnEntry& entry, ConstBytes a, ConstBytes b) {
  if (entry.attribute.dataType() == SoeDataType::kSigned) {
    const auto x = soeNumber(a, true);
    const auto y = soeNumber(b, true);
    return x < y ? -1 : x > y ? 1 : 0;
  }
  const auto x = static_cast<std::uint64_t>(soeNumber(a, false));
  const auto y = static_cast<std::uint64_t>(soeNumber(b, false));
  return x < y ? -1 : x > y ? 1 : 0;
}

void append(std::vector<std::uint8_t>& out, const std::vector<std::uint8_t>& bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}

std::vector<std::uint8_t> textList(const std::string& text) {
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  return encodeSoeList(bytes, static_cast<std::uint16_t>(bytes.size()));
}

}  // namespace

SoeServer::SoeServer(std::vector<IdnDictionary> drives) : drives_(std::move(drives)) {}

void SoeServer::reset() {
  incoming_ = {};
}

void SoeServer::onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                          SimTime now) {
  auto decoded = decodeSoePayload(message);
  if (!decoded.ok()) {
    // Too short for the SoE header: nothing to answer to (no IDN, no opcode).
    ++counters_.errors;
    return;
  }
  const SoeHeader& h = decoded->soe;
  switch (h.opcode) {
    case SoeOpcode::kReadRequest:
      ++counters_.reads;
      read(h, replies);
      return;
    case SoeOpcode::kWriteRequest:
      write(esc, h, decoded->data, replies, now);
      return;
    default:
      // Responses, notifications and slave info go from slave to master only.
      sendError(h, soe_error::kGeneralError, replies);
      return;
  }
}

void SoeServer::poll(Esc& /*esc*/, MailboxReplies& /*replies*/, SimTime now) {
  for (IdnDictionary& drive : drives_) {
    for (std::uint16_t i : drive.idnList(idn::kProcedureCommands)) {
      IdnEntry* e = drive.find(i);
      if (e == nullptr || e->commandState != soe_command::kStateInProgress ||
          now < e->commandDoneAt) {
        continue;
      }
      e->commandState = soe_command::kStateExecuted;
      if (i == idn::kResetClass1Diagnostic) {
        if (IdnEntry* c1d = drive.find(idn::kClass1Diagnostic); c1d != nullptr) {
          std::fill(c1d->value.begin(), c1d->value.end(), 0);
        }
      }
    }
  }
}

void SoeServer::read(const SoeHeader& request, MailboxReplies& replies) {
  if (request.driveNo >= drives_.size()) {
    sendError(request, soe_error::kInvalidDriveNumber, replies);
    return;
  }
  const IdnEntry* e = drives_[request.driveNo].find(request.idn);
  if (e == nullptr) {
    sendError(request, soe_error::kNoIdn, replies);
    return;
  }
  if (request.elements == 0) {
    sendError(request, soe_error::kNoElementAddressed, replies);
    return;
  }
  std::vector<std::uint8_t> data;
  const std::uint8_t asked = request.elements;
  if (asked & soe_element::kDataState) {
    std::uint8_t state[kSoeDataStateSize];
    writeLe16(state, 0, e->attribute.isProcedureCommand() ? e->commandState : 0);
    data.insert(data.end(), state, state + kSoeDataStateSize);
  }
  if (asked & soe_element::kName) {
    if (e->name.empty()) return sendError(request, soe_error::kNoName, replies);
    append(data, textList(e->name));
  }
  if (asked & soe_element::kAttribute) {
    std::uint8_t attribute[kSoeAttributeSize];
    writeLe32(attribute, 0, e->attribute.raw);
    data.insert(data.end(), attribute, attribute + kSoeAttributeSize);
  }
  if (asked & soe_element::kUnit) {
    if (e->unit.empty()) return sendError(request, soe_error::kNoUnit, replies);
    append(data, textList(e->unit));
  }
  if (asked & soe_element::kMinimum) {
    if (!e->minimum) return sendError(request, soe_error::kNoMinimum, replies);
    append(data, *e->minimum);
  }
  if (asked & soe_element::kMaximum) {
    if (!e->maximum) return sendError(request, soe_error::kNoMaximum, replies);
    append(data, *e->maximum);
  }
  if (asked & soe_element::kValue) append(data, e->valueElement());
  if (asked & soe_element::kDefault) {
    if (!e->defaultValue) return sendError(request, soe_error::kNoDefault, replies);
    append(data, *e->defaultValue);
  }
  SoeHeader response = request;
  response.opcode = SoeOpcode::kReadResponse;
  const std::size_t room =
      replies.mailboxSize() > kSoeDataOffset ? replies.mailboxSize() - kSoeDataOffset : 0;
  if (room == 0) return;
  const std::size_t fragments = std::max<std::size_t>(1, (data.size() + room - 1) / room);
  for (std::size_t f = 0; f < fragments; ++f) {
    const std::size_t at = f * room;
    const std::size_t n = std::min(room, data.size() - at);
    SoeHeader part = response;
    if (f + 1 < fragments) {
      part.incomplete = true;
      part.idn = static_cast<std::uint16_t>(fragments - 1 - f);
      ++counters_.fragmentsSent;
    }
    send(part, ConstBytes(data).subspan(at, n), replies);
  }
}

void SoeServer::write(Esc& esc, const SoeHeader& request, ConstBytes data, MailboxReplies& replies,
                      SimTime now) {
  if (request.incomplete) {
    // A fragment: the IDN field counts the fragments left; collected without a reply.
    if (!incoming_.active || incoming_.driveNo != request.driveNo ||
        incoming_.elements != request.elements) {
      incoming_ = {true, request.driveNo, request.elements, {}};
    }
    incoming_.data.insert(incoming_.data.end(), data.begin(), data.end());
    ++counters_.fragmentsReceived;
    return;
  }
  std::vector<std::uint8_t> whole;
  if (incoming_.active && incoming_.driveNo == request.driveNo &&
      incoming_.elements == request.elements) {
    whole = std::move(incoming_.data);
  }
  incoming_ = {};
  whole.insert(whole.end(), data.begin(), data.end());
  ++counters_.writes;

  if (request.driveNo >= drives_.size()) {
    return sendError(request, soe_error::kInvalidDriveNumber, replies);
  }
  IdnDictionary& drive = drives_[request.driveNo];
  IdnEntry* e = drive.find(request.idn);
  if (e == nullptr) return sendError(request, soe_error::kNoIdn, replies);
  const std::uint8_t asked = request.elements;
  std::uint16_t code = 0;
  if (asked == 0) {
    code = soe_error::kNoElementAddressed;
  } else if (asked & soe_element::kDataState) {
    code = soe_error::kInvalidAccessElement1;
  } else if (asked & soe_element::kName) {
    code = soe_error::kNameReadOnly;
  } else if (asked & soe_element::kAttribute) {
    code = soe_error::kAttributeReadOnly;
  } else if (asked & soe_element::kUnit) {
    code = soe_error::kUnitReadOnly;
  } else if (asked & soe_element::kMinimum) {
    code = soe_error::kMinimumReadOnly;
  } else if (asked & soe_element::kMaximum) {
    code = soe_error::kMaximumReadOnly;
  } else if (asked & soe_element::kDefault) {
    code = soe_error::kDefaultReadOnly;
  } else {
    code = writeValue(esc, drive, *e, whole, now);
  }
  if (code != 0) return sendError(request, code, replies);
  SoeHeader response = request;
  response.opcode = SoeOpcode::kWriteResponse;
  send(response, {}, replies);
}

std::uint16_t SoeServer::writeValue(Esc& esc, IdnDictionary& drive, IdnEntry& entry,
                                    ConstBytes data, SimTime now) {
  const SoeAttribute a = entry.attribute;
  if (a.readOnly()) return soe_error::kDataReadOnly;
  if (a.writeProtectedInPhase(phaseOf(esc))) return soe_error::kDataWriteProtectedNow;
  if (!a.isList()) {
    if (data.size() < a.elementSize()) return soe_error::kDataTooShort;
    if (data.size() > a.elementSize()) return soe_error::kDataTooLong;
    if (a.isProcedureCommand()) return runCommand(drive, entry, readLe16(data, 0), now);
    if (entry.minimum && compare(entry, data, *entry.minimum) < 0) {
      return soe_error::kDataBelowMinimum;
    }
    if (entry.maximum && compare(entry, data, *entry.maximum) > 0) {
      return soe_error::kDataAboveMaximum;
    }
    entry.value.assign(data.begin(), data.end());
    return 0;
  }
  auto list = decodeSoeList(data);
  if (!list.ok()) return soe_error::kDataTooShort;
  if (kSoeListHeaderSize + list->currentLength != data.size()) {
    return data.size() < kSoeListHeaderSize + list->currentLength ? soe_error::kDataTooShort
                                                                  : soe_error::kDataTooLong;
  }
  if (list->currentLength > entry.maxListLength) return soe_error::kDataTooLong;
  if (list->currentLength % a.elementSize() != 0) return soe_error::kDataTooShort;
  if (entry.idn == idn::kAtConfiguration || entry.idn == idn::kMdtConfiguration) {
    const auto allowed = drive.idnList(entry.idn == idn::kAtConfiguration ? idn::kConfigurableAt
                                                                          : idn::kConfigurableMdt);
    for (std::size_t i = 0; i + 1 < list->data.size(); i += 2) {
      if (std::find(allowed.begin(), allowed.end(), readLe16(list->data, i)) == allowed.end()) {
        return soe_error::kConfiguredIdnNotSupported;
      }
    }
  }
  entry.value.assign(list->data.begin(), list->data.end());
  return 0;
}

std::uint16_t SoeServer::runCommand(IdnDictionary& /*drive*/, IdnEntry& entry, std::uint16_t value,
                                    SimTime now) {
  switch (value) {
    case soe_command::kCancel:
      entry.commandState = soe_command::kStateCancelled;
      break;
    case soe_command::kSet:
      if (entry.commandState == soe_command::kStateInProgress) {
        entry.commandState = soe_command::kStateInterrupted;
      } else {
        entry.commandState = soe_command::kSet;
      }
      break;
    case soe_command::kSetAndEnable:
      if (entry.commandState == soe_command::kStateInProgress) {
        return soe_error::kCommandAlreadyActive;
      }
      entry.commandState = soe_command::kStateInProgress;
      entry.commandDoneAt = now + kCommandDuration;
      break;
    default:
      return soe_error::kCommandInvalidParameters;
  }
  entry.value.assign(2, 0);
  writeLe16(entry.value, 0, value);
  return 0;
}

void SoeServer::sendError(const SoeHeader& request, std::uint16_t code, MailboxReplies& replies) {
  ++counters_.errors;
  auto message = encodeSoeError(request, code);
  if (message.ok()) replies.send(std::move(message).value());
}

void SoeServer::send(SoeHeader header, ConstBytes data, MailboxReplies& replies) {
  auto message = encodeSoeMailbox(header, data);
  if (message.ok()) replies.send(std::move(message).value());
}

}  // namespace ecsim::slavesim::soe
