// `ecsim demo`: the one-command tour. Builds a simulated line of slaves in-process, talks to
// it through an in-memory link exactly as a master would on a wire (frames only), captures
// every frame to a pcap, and prints what it found.
#include <fmt/core.h>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "link/memory_link.hpp"
#include "link/pcap.hpp"
#include "link/pcap_tap.hpp"
#include "protocol/al_status.hpp"
#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"
#include "tools/ecsim/commands.hpp"
#include "topology/network_server.hpp"

namespace ecsim::tools {
namespace {

struct DemoOptions {
  std::string out{"ecsim-demo"};
  unsigned slaves{5};
};

// One request/answer exchange through the simulated network, stepping it in this thread.
class Exchanger {
 public:
  Exchanger(Link& master, topology::NetworkServer& server, VirtualClock& clock)
      : master_(master), server_(server), clock_(clock) {}

  std::optional<std::pair<std::vector<std::uint8_t>, std::uint16_t>> run(
      Command cmd, std::uint32_t address, std::vector<std::uint8_t> data) {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    FrameBuilder b(
        buf,
        EthernetHeader{kBroadcastMac, {0x02, 0, 0, 0, 0, 0x01}, std::nullopt, kEtherTypeEtherCat});
    if (!b.add(cmd, index_++, address, data).ok()) return std::nullopt;
    auto len = b.finish();
    if (!len.ok() || !master_.send(ConstBytes(buf.data(), *len)).ok()) return std::nullopt;
    if (!server_.step().ok()) return std::nullopt;
    clock_.advance(100 * kNsPerUs);
    auto got = master_.receive(buf, std::chrono::milliseconds(100));
    if (!got.ok() || *got == 0) return std::nullopt;
    auto frame = EtherCatFrame::parse(std::span(buf.data(), *got));
    if (!frame.ok()) return std::nullopt;
    auto d = *frame->begin();
    return std::make_pair(std::vector<std::uint8_t>(d.data().begin(), d.data().end()), d.wkc());
  }

  // Reads `words` SII words of the slave at station address `station` through 0x0502/0x0508.
  std::vector<std::uint8_t> readSii(std::uint16_t station, std::uint32_t word, unsigned words) {
    std::vector<std::uint8_t> out;
    for (unsigned w = 0; w < words; w += 2) {
      std::vector<std::uint8_t> cmd(6, 0);
      writeLe16(cmd, 0, reg::sii::kCommandRead);
      writeLe32(cmd, 2, word + w);
      run(Command::kFpwr, DatagramHeader::physical(station, reg::kSiiControlStatus.address), cmd);
      auto r = run(Command::kFprd, DatagramHeader::physical(station, reg::kSiiData.address),
                   std::vector<std::uint8_t>(4, 0));
      if (!r) break;
      out.insert(out.end(), r->first.begin(), r->first.end());
    }
    return out;
  }

 private:
  Link& master_;
  topology::NetworkServer& server_;
  VirtualClock& clock_;
  std::uint8_t index_{0};
};

int runDemo(const DemoOptions& o) {
  std::filesystem::create_directories(o.out);
  const std::string pcapPath = (std::filesystem::path(o.out) / "demo.pcap").string();
  topology::Segment segment;
  for (unsigned i = 0; i < o.slaves; ++i) {
    segment.addSlave(slavesim::makeGenericSlave(fmt::format("Slave{}", i + 1), 1000 + i));
  }
  segment.wireLine();
  auto [masterEnd, networkEnd] = MemoryLink::makePair();
  VirtualClock clock(kNsPerSecond);
  auto writer = PcapWriter::open(pcapPath);
  if (!writer.ok()) {
    fmt::print(stderr, "ecsim demo: {}\n", writer.error().message());
    return 1;
  }
  // Capture at the master's port, stamped with model time from 2000-01-01 (the DC epoch).
  class EpochClock final : public Clock {
   public:
    explicit EpochClock(const Clock& c) : c_(c) {}
    SimTime now() const override { return c_.now() + kDcEpochUnixNs; }

   private:
    const Clock& c_;
  } stamp(clock);
  PcapTap tap(masterEnd, *writer, stamp);
  topology::NetworkServer server(networkEnd, segment, clock);
  Exchanger x(tap, server, clock);

  fmt::print("ecsim demo: a simulated EtherCAT line of {} slaves, driven through frames only\n\n",
             o.slaves);
  auto count = x.run(Command::kBrd, DatagramHeader::physical(0, reg::kType.address), {0, 0});
  if (!count) {
    fmt::print(stderr, "ecsim demo: no answer from the network\n");
    return 1;
  }
  fmt::print("BRD 0x0000 -> working counter {} (slaves answering)\n", count->second);
  fmt::print("{:>4}  {:>7}  {:>10}  {:>10}  {:>8}  {:>6}  {}\n", "pos", "station", "vendor",
             "product", "serial", "state", "name");
  for (std::uint16_t pos = 0; pos < count->second; ++pos) {
    const auto station = static_cast<std::uint16_t>(0x1001 + pos);
    std::vector<std::uint8_t> addr(2);
    writeLe16(addr, 0, station);
    x.run(Command::kApwr,
          DatagramHeader::physical(static_cast<std::uint16_t>(-pos),
                                   reg::kConfiguredStationAddress.address),
          addr);
    auto ident = x.readSii(station, 0x08, 8);
    auto al =
        x.run(Command::kFprd, DatagramHeader::physical(station, reg::kAlStatus.address), {0, 0});
    // String 1 (the device name) sits in the STRINGS category right after the header.
    auto strings = x.readSii(station, 0x40, 16);
    std::string name;
    if (strings.size() >= 6 && readLe16(strings, 0) == 10 && strings[4] >= 1) {
      std::size_t len = strings[5];
      for (std::size_t i = 0; i < len && 6 + i < strings.size(); ++i) {
        name.push_back(static_cast<char>(strings[6 + i]));
      }
    }
    std::string state = al ? std::string(toString(static_cast<AlState>(al->first[0] & 0x0F))) : "?";
    fmt::print("{:>4}  {:#07x}  {:#010x}  {:#010x}  {:>8}  {:>6}  {}\n", pos, station,
               ident.size() >= 16 ? readLe32(ident, 0) : 0u,
               ident.size() >= 16 ? readLe32(ident, 4) : 0u,
               ident.size() >= 16 ? readLe32(ident, 12) : 0u, state, name);
  }
  (void)writer->close();
  const auto& c = server.counters();
  fmt::print(
      "\nframes answered {}, malformed {}, capture: {} (open it with Wireshark or "
      "`tshark -r {}`)\n",
      c.framesAnswered, c.framesDropped, pcapPath, pcapPath);
  return 0;
}

}  // namespace

CommandRunner addDemoCommand(CLI::App& app) {
  auto opts = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand("demo", "Run the one-command tour and print a summary");
  cmd->add_option("--out", opts->out, "Directory for the demo's files (pcap, CSV, plots)");
  cmd->add_option("--slaves", opts->slaves, "Slaves in the demo line")
      ->check(CLI::Range(1u, 1000u));
  return [opts] { return runDemo(*opts); };
}

}  // namespace ecsim::tools
