// A small master for the CoE tests: it reaches a slave only through frames on a Segment, the
// way SOEM does (notes/soem-interop.md §3.3-3.5): SII through the EEPROM registers, mailbox
// SMs from the SII, FPWR of the whole SM0 buffer, poll of 0x080D bit 3, FPRD of the whole SM1
// buffer; SDO upload/download (expedited, normal, segmented, complete access) and SDO
// information built with the protocol codecs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/registers.hpp"
#include "protocol/sdo.hpp"
#include "protocol/sdo_info.hpp"
#include "protocol/sii.hpp"
#include "slavesim/coe/coe_server.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/process_data.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {

inline std::vector<std::uint8_t> smRegisterBytes(std::uint16_t start, std::uint16_t length,
                                                 std::uint8_t control, std::uint8_t enable = 1) {
  std::vector<std::uint8_t> s(8, 0);
  writeLe16(s, 0, start);
  writeLe16(s, 2, length);
  s[4] = control;
  s[6] = enable;
  return s;
}

inline std::vector<std::uint8_t> fmmuRegisterBytes(std::uint32_t logical, std::uint16_t length,
                                                   std::uint16_t physical, std::uint8_t type) {
  std::vector<std::uint8_t> f(16, 0);
  writeLe32(f, 0, logical);
  writeLe16(f, 4, length);
  f[7] = 7;
  writeLe16(f, 8, physical);
  f[11] = type;
  f[12] = 1;
  return f;
}

// Reads the SII of the slave at `station` through 0x0502/0x0504/0x0508, category by category,
// as a master does: each read command keeps the EEPROM busy for a while (0x0502 bit 15; 0.53-
// 0.80 ms on a real EK1100, ../shared/pcap/replay-dc.pcapng frames 104-110), so the status is
// polled every 100 us of simulated time from `start` on until busy clears, then the data read.
// The firmware does not run meanwhile (the ESC alone serves the EEPROM), so callers may go on
// at their own time afterwards.
inline std::vector<std::uint8_t> readSiiThroughFrames(topology::Segment& seg,
                                                      std::uint16_t station, SimTime start = 0) {
  std::vector<std::uint8_t> bytes;
  SimTime t = start;
  auto escOnly = [&](Command c, std::uint16_t ado, std::vector<std::uint8_t> data) {
    auto r = exchange(seg, {{c, phys(station, ado), std::move(data)}}, t, false).at(0);
    t += 100 * kNsPerUs;
    return r;
  };
  auto readWords = [&](std::uint32_t word, std::size_t count) {
    while (count > 0) {
      std::vector<std::uint8_t> cmd(6, 0);
      writeLe16(cmd, 0, reg::sii::kCommandRead);
      writeLe32(cmd, 2, word);
      escOnly(Command::kFpwr, reg::kSiiControlStatus.address, cmd);
      for (int poll = 0; poll < 100; ++poll) {
        auto status = escOnly(Command::kFprd, reg::kSiiControlStatus.address, {0, 0});
        if ((readLe16(status.data, 0) & reg::sii::kBusy) == 0) break;
      }
      auto data = escOnly(Command::kFprd, reg::kSiiData.address, {0, 0, 0, 0});
      for (std::size_t i = 0; i < 2 && count > 0; ++i, --count, ++word) {
        if (bytes.size() < 2 * (word + 1)) bytes.resize(2 * (word + 1), 0xFF);
        bytes[2 * word] = data.data[2 * i];
        bytes[2 * word + 1] = data.data[2 * i + 1];
      }
    }
  };
  readWords(0, sii::kHeaderWords);
  std::uint32_t word = sii::kWordFirstCategory;
  for (int guard = 0; guard < 256 && word < 0x4000; ++guard) {
    readWords(word, 2);
    const std::uint16_t type = readLe16(bytes, 2 * word);
    const std::uint16_t length = readLe16(bytes, 2 * word + 2);
    if (type == 0xFFFF) break;
    readWords(word + 2, length);
    word += 2 + length;
  }
  return bytes;
}

struct Upload {
  std::uint32_t abort{0};  // 0: success
  std::vector<std::uint8_t> data;
  std::uint8_t command{0};  // command byte of the initiate response
  int segments{0};
};

class MailboxMaster {
 public:
  MailboxMaster(topology::Segment& seg, std::uint16_t station, std::uint16_t outStart,
                std::uint16_t outSize, std::uint16_t inStart, std::uint16_t inSize)
      : seg_(seg),
        station_(station),
        outStart_(outStart),
        outSize_(outSize),
        inStart_(inStart),
        inSize_(inSize) {}

  // SM0/SM1 as SOEM programs them.
  void configureSyncManagers() {
    one(seg_, Command::kFpwr, phys(station_, reg::smChannel(0)),
        smRegisterBytes(outStart_, outSize_, 0x26));
    one(seg_, Command::kFpwr, phys(station_, reg::smChannel(1)),
        smRegisterBytes(inStart_, inSize_, 0x22));
  }

  std::uint8_t nextCounter() {
    counter_ = nextMailboxCounter(counter_);
    return counter_;
  }
  std::uint16_t mailboxOutSize() const { return outSize_; }
  std::uint16_t mailboxInSize() const { return inSize_; }

  // Writes a whole SM0 buffer holding `message`; returns the WKC.
  std::uint16_t send(const std::vector<std::uint8_t>& message) {
    std::vector<std::uint8_t> buffer(outSize_, 0);
    std::copy_n(message.begin(), std::min(message.size(), buffer.size()), buffer.begin());
    return one(seg_, Command::kFpwr, phys(station_, outStart_), buffer).wkc;
  }
  // Polls 0x080D bit 3 a few times, then reads the whole SM1 buffer.
  std::optional<std::vector<std::uint8_t>> receive(int polls = 4) {
    for (int i = 0; i < polls; ++i) {
      auto status = one(seg_, Command::kFprd,
                        phys(station_, reg::smChannel(1) + reg::sm::kStatus.address), {0});
      if ((status.data[0] & reg::sm::kStatusMailboxFull) != 0) {
        auto r = one(seg_, Command::kFprd, phys(station_, inStart_),
                     std::vector<std::uint8_t>(inSize_, 0));
        if (r.wkc == 1) return r.data;
      }
    }
    return std::nullopt;
  }
  // send() then receive(), skipping emergencies (as SOEM does).
  std::optional<std::vector<std::uint8_t>> transact(const std::vector<std::uint8_t>& message) {
    send(message);
    for (int i = 0; i < 8; ++i) {
      auto r = receive();
      if (!r) return r;
      if (!isEmergency(*r)) return r;
      emergencies.push_back(*r);
    }
    return std::nullopt;
  }
  static bool isEmergency(const std::vector<std::uint8_t>& m) {
    return m.size() >= 8 && (m[5] & 0x0F) == 3 && (m[7] >> 4) == 1;
  }
  std::vector<std::vector<std::uint8_t>> emergencies;

  std::vector<std::uint8_t> sdoRequest(const SdoRequest& request) {
    std::vector<std::uint8_t> m(outSize_, 0);
    MailboxHeader h;
    h.counter = nextCounter();
    auto n = encodeSdoRequestMailbox(m, request, h);
    EXPECT_TRUE(n.ok());
    m.resize(n.ok() ? *n : 0);
    return m;
  }

  std::optional<SdoResponse> sdoTransact(const SdoRequest& request) {
    auto reply = transact(sdoRequest(request));
    if (!reply) return std::nullopt;
    lastReply_ = *reply;
    auto decoded = decodeSdoResponseMailbox(lastReply_);
    if (!decoded.ok()) return std::nullopt;
    return decoded->sdo;
  }

  Upload upload(std::uint16_t index, std::uint8_t sub, bool completeAccess = false) {
    Upload out;
    auto r = sdoTransact(SdoInitiateUploadRequest{index, sub, completeAccess});
    if (!r) {
      out.abort = 0xFFFFFFFF;
      return out;
    }
    out.command = lastReply_.size() > 8 ? lastReply_[8] : 0;
    if (auto* abort = std::get_if<SdoAbort>(&*r)) {
      out.abort = abort->abortCode;
      return out;
    }
    auto* init = std::get_if<SdoInitiateUploadResponse>(&*r);
    if (init == nullptr) {
      out.abort = 0xFFFFFFFE;
      return out;
    }
    out.data.assign(init->data.begin(), init->data.end());
    bool toggle = false;
    while (!init->expedited && out.data.size() < init->completeSize) {
      auto seg = sdoTransact(SdoUploadSegmentRequest{toggle});
      if (!seg) {
        out.abort = 0xFFFFFFFF;
        return out;
      }
      if (auto* abort = std::get_if<SdoAbort>(&*seg)) {
        out.abort = abort->abortCode;
        return out;
      }
      auto* s = std::get_if<SdoUploadSegmentResponse>(&*seg);
      if (s == nullptr || s->toggle != toggle) {
        out.abort = 0xFFFFFFFD;
        return out;
      }
      out.data.insert(out.data.end(), s->data.begin(), s->data.end());
      ++out.segments;
      toggle = !toggle;
      if (s->last) break;
    }
    return out;
  }

  template <typename T>
  T uploadValue(std::uint16_t index, std::uint8_t sub) {
    Upload u = upload(index, sub);
    EXPECT_EQ(u.abort, 0u) << std::hex << "upload " << index << ":" << int(sub);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < u.data.size() && i < 8; ++i)
      v |= std::uint64_t{u.data[i]} << (8 * i);
    return static_cast<T>(v);
  }

  // Expedited when <= 4 bytes (unless forceNormal), normal when it fits, else segmented.
  // Returns 0 or the abort code.
  std::uint32_t download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> data,
                         bool completeAccess = false, bool forceNormal = false) {
    SdoInitiateDownloadRequest req;
    req.index = index;
    req.subindex = sub;
    req.completeAccess = completeAccess;
    req.completeSize = static_cast<std::uint32_t>(data.size());
    const std::size_t capacity = sdoNormalDataCapacity(outSize_);
    std::size_t sent = 0;
    if (data.size() <= 4 && !forceNormal && !data.empty()) {
      req.expedited = true;
      req.data = data;
      sent = data.size();
    } else {
      sent = std::min(capacity, data.size());
      req.data = ConstBytes(data).first(sent);
    }
    auto r = sdoTransact(req);
    if (!r) return 0xFFFFFFFF;
    if (auto* abort = std::get_if<SdoAbort>(&*r)) return abort->abortCode;
    bool toggle = false;
    while (sent < data.size()) {
      const std::size_t n = std::min(sdoSegmentDataCapacity(outSize_), data.size() - sent);
      auto seg = sdoTransact(SdoDownloadSegmentRequest{toggle, sent + n == data.size(),
                                                       ConstBytes(data).subspan(sent, n)});
      if (!seg) return 0xFFFFFFFF;
      if (auto* abort = std::get_if<SdoAbort>(&*seg)) return abort->abortCode;
      sent += n;
      toggle = !toggle;
    }
    return 0;
  }

  // SDO information: one request, all fragments of the response reassembled.
  struct InfoReply {
    std::optional<SdoInfoResponse> response;
    int fragments{0};
    std::vector<std::vector<std::uint8_t>> raw;
  };
  InfoReply info(const SdoInfoRequest& request) {
    InfoReply out;
    std::vector<std::uint8_t> m(outSize_, 0);
    MailboxHeader h;
    h.counter = nextCounter();
    auto n = encodeSdoInfoRequestMailbox(m, request, h);
    EXPECT_TRUE(n.ok());
    m.resize(*n);
    send(m);
    SdoInfoReassembler joiner;
    for (int i = 0; i < 1000 && !joiner.complete(); ++i) {
      auto r = receive();
      if (!r) break;
      out.raw.push_back(*r);
      auto msg = decodeSdoInfoMailbox(out.raw.back());
      if (!msg.ok() || !joiner.add(*msg).ok()) break;
      ++out.fragments;
    }
    if (joiner.complete()) {
      auto d = decodeSdoInfoResponse(joiner.opcode(), joiner.data());
      if (d.ok()) out.response = *d;
    }
    return out;
  }

  const std::vector<std::uint8_t>& lastReply() const { return lastReply_; }

 private:
  topology::Segment& seg_;
  std::uint16_t station_;
  std::uint16_t outStart_, outSize_, inStart_, inSize_;
  std::uint8_t counter_{0};
  std::vector<std::uint8_t> lastReply_;
};

// The low n bytes of v, little-endian (an SDO value).
inline std::vector<std::uint8_t> bytesOf(std::uint32_t v, std::size_t n) {
  std::vector<std::uint8_t> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  return out;
}

inline void requestState(topology::Segment& seg, std::uint16_t station, std::uint16_t control) {
  one(seg, Command::kFpwr, phys(station, reg::kAlControl.address), le16(control));
}
inline std::uint16_t alStatus(topology::Segment& seg, std::uint16_t station) {
  return readLe16(one(seg, Command::kFprd, phys(station, reg::kAlStatus.address), {0, 0}).data, 0);
}
inline std::uint16_t alStatusCode(topology::Segment& seg, std::uint16_t station) {
  return readLe16(one(seg, Command::kFprd, phys(station, reg::kAlStatusCode.address), {0, 0}).data,
                  0);
}

// ---- a device of our own for the CoE tests -----------------------------------------------------
//
//   0x2000 UNSIGNED8 rw, limits 10..200      0x2001 UNSIGNED16 rw      0x2002 INTEGER32 rw, +-1000
//   0x2003 UNSIGNED32 ro                      0x2004 UNSIGNED32 wo      0x2005 UNSIGNED32 rw PREOP
//   0x2006 OCTET_STRING 300 bytes rw          0x2007 INTEGER24 ro       0x2008 RECORD u8, u16, BOOL
//   0x7000 outputs: :01 BOOL, :02 BIT3, :03 UNSIGNED16, :04 BOOL (RX mappable, rw)
//   0x6000 inputs:  :01 BOOL, :02 BIT4, :03 INTEGER16, :04 UNSIGNED8 (TX mappable, ro)
//   0x1600 = 7000:01, 7000:02, 4-bit gap, 7000:03 (24 bits)    0x1601 = 7000:04, 7-bit gap
//   0x1A00 = 6000:01, 6000:02, 3-bit gap, 6000:03, 6000:04 (32 bits)
//   0x1A01 (fixed) = 6000:04; excluded by 0x1A00
//   0x1C12 = {0x1600} of 2, 0x1C13 = {0x1A00} of 2    -> SM2 3 bytes, SM3 4 bytes
inline constexpr std::uint16_t kStation = 0x1001;
inline constexpr std::uint16_t kMbxOut = 0x1000;
inline constexpr std::uint16_t kMbxIn = 0x1080;
inline constexpr std::uint16_t kSm2Start = 0x1100;
inline constexpr std::uint16_t kSm3Start = 0x1180;
inline constexpr char kTestDeviceName[] = "ecsim CoE test device";

inline std::shared_ptr<slavesim::coe::ObjectDictionary> makeTestDictionary() {
  namespace coe = slavesim::coe;
  namespace dt = coe::data_type;
  namespace ac = coe::access;
  auto od = std::make_shared<coe::ObjectDictionary>();
  od->addVar(0x1000, "Device type", dt::kUnsigned32, 32, ac::kReadOnly);
  (void)od->set<std::uint32_t>(0x1000, 0, 0x00001389);
  od->addString(0x1008, "Device name", kTestDeviceName);
  od->addString(0x1009, "Hardware version", "1.0");
  od->addString(0x100A, "Software version", "2.3.4");
  coe::addIdentityObject(*od, {0x0000ABCD, 0x00000042, 0x00010000, 0x1234});
  const std::uint8_t types[] = {1, 2, 3, 4};
  coe::addSyncManagerTypes(*od, types);
  auto& u8 = od->addVar(0x2000, "Limited byte", dt::kUnsigned8, 8, ac::kReadWrite);
  u8.entries[0].minimum = {10};
  u8.entries[0].maximum = {200};
  u8.entries[0].value = {50};
  od->addVar(0x2001, "Word", dt::kUnsigned16, 16, ac::kReadWrite);
  auto& i32 = od->addVar(0x2002, "Signed", dt::kInteger32, 32, ac::kReadWrite);
  i32.entries[0].minimum = {0x18, 0xFC, 0xFF, 0xFF};  // -1000
  i32.entries[0].maximum = {0xE8, 0x03, 0x00, 0x00};  // 1000
  od->addVar(0x2003, "Read only", dt::kUnsigned32, 32, ac::kReadOnly);
  (void)od->set<std::uint32_t>(0x2003, 0, 0xCAFEF00D);
  od->addVar(0x2004, "Write only", dt::kUnsigned32, 32, ac::kWriteOnly);
  od->addVar(0x2005, "PREOP parameter", dt::kUnsigned32, 32, ac::kReadWritePreOp);
  od->addVar(0x2006, "Blob", dt::kOctetString, 300 * 8, ac::kReadWrite);
  for (std::size_t i = 0; i < 300; ++i)
    od->findEntry(0x2006, 0)->value[i] = static_cast<std::uint8_t>(i);
  od->addVar(0x2007, "Three bytes", dt::kInteger24, 24, ac::kReadOnly);
  (void)od->set<std::int32_t>(0x2007, 0, -2);
  od->addRecord(0x2008, "Mixed record", dt::kRecord);
  auto entry = [](std::uint8_t sub, std::uint16_t type, std::uint16_t bits, std::uint16_t rights,
                  std::string name) {
    coe::Entry e;
    e.subindex = sub;
    e.dataType = type;
    e.bitLength = bits;
    e.access = rights;
    e.name = std::move(name);
    return e;
  };
  od->addEntry(0x2008, entry(1, dt::kUnsigned8, 8, ac::kReadWrite, "Byte"));
  od->addEntry(0x2008, entry(2, dt::kUnsigned16, 16, ac::kReadWrite, "Word"));
  od->addEntry(0x2008, entry(3, dt::kBoolean, 1, ac::kReadWrite, "Flag"));
  const std::uint16_t out = ac::kReadWrite | ac::kRxMappable;
  const std::uint16_t in = ac::kReadOnly | ac::kTxMappable;
  od->addRecord(0x7000, "Outputs", dt::kRecord);
  od->addEntry(0x7000, entry(1, dt::kBoolean, 1, out, "Enable"));
  od->addEntry(0x7000, entry(2, dt::bitType(3), 3, out, "Mode"));
  od->addEntry(0x7000, entry(3, dt::kUnsigned16, 16, out, "Setpoint"));
  od->addEntry(0x7000, entry(4, dt::kBoolean, 1, out, "Extra"));
  od->addRecord(0x6000, "Inputs", dt::kRecord);
  od->addEntry(0x6000, entry(1, dt::kBoolean, 1, in, "Ready"));
  od->addEntry(0x6000, entry(2, dt::bitType(4), 4, in, "State"));
  od->addEntry(0x6000, entry(3, dt::kInteger16, 16, in, "Actual"));
  od->addEntry(0x6000, entry(4, dt::kUnsigned8, 8, in, "Counter"));
  using M = coe::MappedObject;
  coe::addPdoMapping(*od, {0x1600,
                           "Outputs A",
                           {M{0x7000, 1, 1}, M{0x7000, 2, 3}, M{0, 0, 4}, M{0x7000, 3, 16}},
                           {},
                           4,
                           false});
  coe::addPdoMapping(*od, {0x1601, "Outputs B", {M{0x7000, 4, 1}, M{0, 0, 7}}, {}, 2, false});
  coe::addPdoMapping(
      *od, {0x1A00,
            "Inputs A",
            {M{0x6000, 1, 1}, M{0x6000, 2, 4}, M{0, 0, 3}, M{0x6000, 3, 16}, M{0x6000, 4, 8}},
            {},
            5,
            false});
  coe::addPdoMapping(*od, {0x1A01, "Inputs B", {M{0x6000, 4, 8}}, {}, 1, true});
  od->pdoRules(0x1A00).excludes = {0x1A01};
  od->pdoRules(0x1A01).excludes = {0x1A00};
  const std::uint16_t rx[] = {0x1600};
  const std::uint16_t tx[] = {0x1A00};
  coe::addPdoAssignment(*od, 2, rx, 2, true);
  coe::addPdoAssignment(*od, 3, tx, 2, true);
  coe::addSyncManagerParameters(*od, coe::kSmOutputParameterIndex, {});
  coe::addSyncManagerParameters(*od, coe::kSmInputParameterIndex, {});
  return od;
}

// A slave with the test dictionary, a CoE server and the process-data device, station 0x1001
// assigned and (when `preop`) its mailbox configured and in PREOP.
struct CoeTestSlave {
  topology::Segment seg;
  std::shared_ptr<slavesim::coe::ObjectDictionary> od;
  slavesim::coe::CoeServer* server{nullptr};
  slavesim::ProcessDataDevice* device{nullptr};
  std::unique_ptr<MailboxMaster> master;

  explicit CoeTestSlave(std::uint16_t mailboxSize = 128,
                        slavesim::coe::CoeServerOptions options = {}, bool preop = true) {
    od = makeTestDictionary();
    slavesim::SlaveProfile profile;
    profile.mailbox = slavesim::SlaveProfile::Mailbox{kMbxOut, mailboxSize, kMbxIn, mailboxSize};
    auto slave = makeSlave("coe", 0x42, profile,
                           makeSii(0x0000ABCD, 0x42, kMbxOut, mailboxSize, kMbxIn, mailboxSize));
    auto s = std::make_unique<slavesim::coe::CoeServer>(od, options);
    server = s.get();
    slave->setMailboxServer(std::move(s));
    auto d = std::make_unique<slavesim::ProcessDataDevice>(od);
    device = d.get();
    slave->setDevice(std::move(d));
    seg.addSlave(std::move(slave));
    one(seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
    master =
        std::make_unique<MailboxMaster>(seg, kStation, kMbxOut, mailboxSize, kMbxIn, mailboxSize);
    if (preop) {
      master->configureSyncManagers();
      requestState(seg, kStation, 0x0002);
      EXPECT_EQ(alStatus(seg, kStation), 0x0002);
    }
  }

  // Process-data SMs and FMMUs (outputs at logical 0, inputs after them), then SAFEOP.
  std::uint16_t toSafeOp(std::uint16_t sm2Length = 3, std::uint16_t sm3Length = 4,
                         std::uint16_t control = 0x0004) {
    one(seg, Command::kFpwr, phys(kStation, reg::smChannel(2)),
        smRegisterBytes(kSm2Start, sm2Length, 0x64));
    one(seg, Command::kFpwr, phys(kStation, reg::smChannel(3)),
        smRegisterBytes(kSm3Start, sm3Length, 0x20));
    one(seg, Command::kFpwr, phys(kStation, reg::fmmuChannel(0)),
        fmmuRegisterBytes(0, sm2Length, kSm2Start, 2));
    one(seg, Command::kFpwr, phys(kStation, reg::fmmuChannel(1)),
        fmmuRegisterBytes(sm2Length, sm3Length, kSm3Start, 1));
    requestState(seg, kStation, control);
    return alStatus(seg, kStation);
  }
};

}  // namespace ecsim::testing
