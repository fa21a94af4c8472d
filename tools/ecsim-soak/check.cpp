// Checking an answer against what the ESC datasheet says each datagram must come back with.
// Deliberately independent of the simulator: the expectations are written from the request
// alone (see the list in frames.hpp).
#include <fmt/core.h>

#include <algorithm>
#include <array>

#include "protocol/registers.hpp"
#include "tools/ecsim-soak/frames.hpp"

namespace ecsim::soak {
namespace {

constexpr std::size_t kMaxDatagrams = 128;
constexpr std::size_t kEcatHeaderEnd = kEthernetHeaderSize + kEtherCatHeaderSize;
// An ESC sets the locally administered bit of the source address (datasheet section I).
constexpr std::uint8_t kLocallyAdministered = 0x02;

using Views = std::array<ConstDatagramView, kMaxDatagrams>;

std::size_t collect(ConstBytes frame, Views& out) {
  auto parsed = ConstEtherCatFrame::parse(frame);
  if (!parsed.ok()) return 0;
  std::size_t n = 0;
  for (auto it = parsed->begin(); it != parsed->end() && n < out.size(); ++it) out[n++] = *it;
  return n;
}

class Checker {
 public:
  Checker(const SoakFrame& request, const Network& network) : request_(request), net_(network) {}

  CheckResult run(ConstBytes answer) {
    const ConstBytes sent(request_.bytes.data(), request_.length);
    if (answer.size() != sent.size()) {
      return data(fmt::format("frame of {} bytes came back with {}", sent.size(), answer.size()));
    }
    for (std::size_t i = 0; i < kEcatHeaderEnd; ++i) {
      const std::uint8_t want = i == 6 ? (sent[i] | kLocallyAdministered) : sent[i];
      if (answer[i] != want) {
        return data(fmt::format("header byte {}: 0x{:02X}, expected 0x{:02X}", i, answer[i], want));
      }
    }
    const std::size_t n = collect(sent, req_);
    if (collect(answer, ans_) != n) return data("answer's datagram chain differs from the request's");
    count_ = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (!sameHeader(i)) return result_;
    }
    for (std::size_t k = 0; k < request_.opCount; ++k) {
      if (!checkOp(request_.ops[k])) return result_;
    }
    return result_;
  }

 private:
  CheckResult data(std::string what) {
    result_.dataError = true;
    result_.what = std::move(what);
    return result_;
  }
  std::string where(std::size_t i) const {
    const auto& d = req_[i];
    if (isLogical(d.command())) {
      return fmt::format("datagram {} ({} logical 0x{:08X} length {})", i, toString(d.command()),
                         d.address(), d.length());
    }
    return fmt::format("datagram {} ({} ADP 0x{:04X} ADO 0x{:04X} length {})", i,
                       toString(d.command()), d.adp(), d.ado(), d.length());
  }
  // Command, index and length come back unchanged; auto-increment and broadcast datagrams
  // come back with ADP + number of slaves; every other address unchanged.
  bool sameHeader(std::size_t i) {
    const auto& q = req_[i];
    const auto& a = ans_[i];
    if (a.rawCommand() != q.rawCommand() || a.index() != q.index() ||
        readLe16(a.bytes(), 6) != readLe16(q.bytes(), 6)) {
      data(where(i) + ": command, index or length changed");
      return false;
    }
    const AddressMode mode = addressMode(q.command());
    const bool increments = mode == AddressMode::kAutoIncrement || mode == AddressMode::kBroadcast;
    const std::uint32_t want =
        increments ? DatagramHeader::physical(static_cast<std::uint16_t>(q.adp() + net_.slaves),
                                              q.ado())
                   : q.address();
    if (a.address() != want) {
      data(fmt::format("{}: address 0x{:08X}, expected 0x{:08X}", where(i), a.address(), want));
      return false;
    }
    return true;
  }
  bool wkc(std::size_t i, unsigned want) {
    if (i >= count_) {
      data(fmt::format("datagram {} expected, the frame has {}", i, count_));
      return false;
    }
    if (ans_[i].wkc() == want) return true;
    result_.wkcError = true;
    result_.what = fmt::format("{}: WKC {}, expected {}", where(i), ans_[i].wkc(), want);
    return false;
  }
  bool bytes(std::size_t i, ConstBytes want) {
    const auto got = ans_[i].data();
    if (got.size() != want.size()) {
      data(fmt::format("{}: {} data bytes, expected {}", where(i), got.size(), want.size()));
      return false;
    }
    if (std::equal(got.begin(), got.end(), want.begin())) return true;
    const auto at = std::mismatch(got.begin(), got.end(), want.begin()).first - got.begin();
    data(fmt::format("{}: data byte {} is 0x{:02X}, expected 0x{:02X}", where(i), at, got[at],
                     want[at]));
    return false;
  }
  bool checkOp(const Op& op) {
    const std::size_t i = op.first;
    const unsigned slaves = net_.slaves;
    std::array<std::uint8_t, 2> station{};
    writeLe16(station, 0, static_cast<std::uint16_t>(kStationBase + op.slave));
    switch (op.kind) {
      case OpKind::kTypeRead: {
        if (!wkc(i, slaves)) return false;
        const std::uint8_t got = ans_[i].data()[0];
        if (got == net_.escType) return true;
        data(fmt::format("{}: ESC type 0x{:02X}, expected 0x{:02X}", where(i), got, net_.escType));
        return false;
      }
      case OpKind::kAprdStation:
      case OpKind::kFprdStation:
        return wkc(i, 1) && bytes(i, station);
      case OpKind::kNobody:
      case OpKind::kNop:
        return wkc(i, 0) && bytes(i, req_[i].data());
      case OpKind::kWriteRead:
        return wkc(i, 1) && wkc(i + 1, 1) && bytes(i + 1, req_[i].data());
      case OpKind::kBroadcastWrite:
        return wkc(i, slaves) && wkc(i + 1, slaves) && bytes(i + 1, req_[i].data());
      case OpKind::kLogical: {
        // Each slave: FMMU0 writes its slice to the output area (+2), FMMU1 reads the input
        // area just written by the BWR into its slice (+1). The BRD ORs every output area.
        std::array<std::uint8_t, kMaxDatagramLength> image{};
        std::array<std::uint8_t, kBytesPerSlave> ored{};
        const auto input = req_[i].data();
        const auto lrw = req_[i + 1].data();
        for (unsigned s = 0; s < slaves; ++s) {
          for (unsigned b = 0; b < kBytesPerSlave; ++b) {
            image[s * kBytesPerSlave + b] = input[b];
            ored[b] = static_cast<std::uint8_t>(ored[b] | lrw[s * kBytesPerSlave + b]);
          }
        }
        return wkc(i, slaves) && wkc(i + 1, 3 * slaves) &&
               bytes(i + 1, ConstBytes(image.data(), lrw.size())) && wkc(i + 2, slaves) &&
               bytes(i + 2, ored);
      }
      case OpKind::kSetup:
        return wkc(i, 1);
    }
    return true;
  }

  const SoakFrame& request_;
  const Network& net_;
  Views req_{};
  Views ans_{};
  std::size_t count_{0};
  CheckResult result_;
};

}  // namespace

CheckResult checkAnswer(const SoakFrame& request, ConstBytes answer, const Network& network) {
  return Checker(request, network).run(answer);
}

}  // namespace ecsim::soak
