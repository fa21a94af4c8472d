// `ecsim serve` over a real veth pair: frames built here (not by any ecsim library that the
// simulator uses to answer) go out of a raw socket on the master's end; the simulator answers
// on the other end. Checks the slice of issue #4: BRD 0x0000 gives WKC = N, auto-increment
// addressing, same frame length back, malformed frames dropped and counted without harm,
// SIGINT stops cleanly and the capture decodes in tshark.
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "link/netns.hpp"
#include "link/pcap.hpp"
#include "link/raw_socket_link.hpp"
#include "protocol/frame.hpp"
#include "support/privileges.hpp"
#include "support/readiness.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A tool the test needs (tshark, capinfos): missing is a failure under CI=true, else a skip.
#define REQUIRE_TOOL(probe, tool)                                  \
  do {                                                             \
    if (!runCommand(probe).ok()) {                                 \
      if (ciMode()) FAIL() << tool << " missing under CI=true";    \
      GTEST_SKIP() << tool << " not installed (wireshark-common)"; \
    }                                                              \
  } while (false)

// Waits for the end of `ecsim serve` after SIGINT: a bound against a hang, generous because a
// sanitizer build on a busy machine is slow to finish and report.
constexpr std::chrono::seconds kExitWait{30};

class ServedNetwork {
 public:
  ServedNetwork(const VethNamespace& ns, unsigned slaves, const std::string& pcap,
                const std::string& log, const std::vector<std::string>& extra = {})
      : ns_(ns) {
    std::vector<std::string> argv{
        kEcsim, "serve", "--iface", ns.simulatorInterface(), "--slaves", std::to_string(slaves)};
    if (!pcap.empty()) {
      argv.push_back("--pcap");
      argv.push_back(pcap);
    }
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto child = ns.spawn(argv, SpawnOptions{log, log});
    if (child.ok()) child_ = std::move(child).value();
    auto link = RawSocketLink::open(ns.masterInterface(), RawSocketOptions{ns.name(), true});
    if (link.ok()) link_.emplace(std::move(link).value());
  }
  bool ok() const { return link_.has_value() && child_.pid() > 0; }
  ChildProcess& child() { return child_; }
  RawSocketLink& link() { return *link_; }

  // Sends one frame and waits for its answer: the same source MAC (with the locally
  // administered bit an ESC sets) and the same first index; nullopt on timeout. The index
  // alone is one byte: among the answers to random frames (the robustness test) one in 256
  // would pass for ours. `wait` only guards against a hang: `ecsim serve` is an ordinary
  // process, late by tens of milliseconds when the machine is busy (CI, sanitizers).
  std::optional<std::vector<std::uint8_t>> roundTrip(
      ConstBytes frame, std::chrono::milliseconds wait = std::chrono::seconds(10)) {
    if (!link_->send(frame).ok()) return std::nullopt;
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    auto deadline = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < deadline) {
      auto n = link_->receive(buf, std::chrono::milliseconds(20));
      if (n.ok() && *n > 17 && answers(frame, ConstBytes(buf.data(), *n)))
        return std::vector<std::uint8_t>(buf.begin(), buf.begin() + *n);
    }
    return std::nullopt;
  }

  std::optional<std::pair<std::uint16_t, std::vector<std::uint8_t>>> datagram(
      Command c, std::uint32_t address, std::vector<std::uint8_t> data,
      std::chrono::milliseconds wait = std::chrono::seconds(10)) {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    FrameBuilder b(
        buf,
        EthernetHeader{kBroadcastMac, {0x02, 0, 0, 0, 0, 1}, std::nullopt, kEtherTypeEtherCat});
    if (!b.add(c, ++index_, address, data).ok()) return std::nullopt;
    auto len = b.finish();
    auto answer = roundTrip(ConstBytes(buf.data(), *len), wait);
    if (!answer) return std::nullopt;
    EXPECT_EQ(answer->size(), *len) << "frame comes back with the same length";
    auto frame = EtherCatFrame::parse(std::span(answer->data(), answer->size()));
    if (!frame.ok()) return std::nullopt;
    auto d = *frame->begin();
    return std::make_pair(d.wkc(), std::vector<std::uint8_t>(d.data().begin(), d.data().end()));
  }

  // Waits until the simulator answers (it needs a moment to open its socket; frames sent
  // before are lost, so each try waits briefly and the next one is a new frame). 30 s: a
  // start-up under sanitizers on a busy machine, never a normal wait.
  bool waitReady() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline && child_.running()) {
      if (datagram(Command::kBrd, 0, {0, 0}, std::chrono::milliseconds(200))) return true;
    }
    return false;
  }

 private:
  static bool answers(ConstBytes request, ConstBytes answer) {
    for (std::size_t i = 6; i < 12; ++i) {
      const std::uint8_t expected = i == 6 ? (request[i] | 0x02) : request[i];
      if (answer[i] != expected) return false;
    }
    return answer[17] == request[17];
  }

  const VethNamespace& ns_;
  ChildProcess child_;
  std::optional<RawSocketLink> link_;
  std::uint8_t index_{0};
};

class ServeVeth : public ::testing::TestWithParam<unsigned> {};

TEST_P(ServeVeth, BroadcastReadCountsEverySlave) {
  ECSIM_REQUIRE_NETWORK();
  const unsigned n = GetParam();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = uniqueTempPath("serve_" + std::to_string(n) + ".log");
  ServedNetwork net(*ns, n, "", log);
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  auto brd = net.datagram(Command::kBrd, DatagramHeader::physical(0, 0x0000), {0, 0});
  ASSERT_TRUE(brd);
  EXPECT_EQ(brd->first, n);
  EXPECT_EQ(brd->second[0], 0x11) << "ESC type ET1100";
  // Auto-increment: the last slave answers ADP = 1 - n with its station address once set.
  auto last = static_cast<std::uint16_t>(1 - static_cast<int>(n));
  auto w = net.datagram(Command::kApwr, DatagramHeader::physical(last, 0x0010), {0x34, 0x12});
  ASSERT_TRUE(w);
  EXPECT_EQ(w->first, 1);
  auto r = net.datagram(Command::kFprd, DatagramHeader::physical(0x1234, 0x0010), {0, 0});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->first, 1);
  EXPECT_EQ(readLe16(r->second, 0), 0x1234);
  ASSERT_TRUE(net.child().kill(SIGINT).ok());
  auto code = net.child().wait(kExitWait);
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0) << readText(log);
  if (!HasFailure()) std::filesystem::remove(log);  // kept for a look when it failed
}

INSTANTIATE_TEST_SUITE_P(Sizes, ServeVeth, ::testing::Values(1u, 10u, 250u));

// Issue 18: `--busy-poll --send-cpu N` answers through a kernel thread on CPU N
// (link/kernel_thread_sender.hpp), says so, and keeps its own thread off that CPU: a
// busy-polling thread at real-time priority beside it would starve it.
TEST(ServeVethBusyPoll, SendCpuAnswersThroughAKernelThreadOnACpuItLeaves) {
  ECSIM_REQUIRE_NETWORK();
  const long cpus = ::sysconf(_SC_NPROCESSORS_ONLN);
  ASSERT_GE(cpus, 2) << "CI machines have 2 CPUs";
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = uniqueTempPath("serve_busy.log");
  const int sendCpu = static_cast<int>(cpus) - 1;
  ServedNetwork net(*ns, 10, "", log,
                    {"--busy-poll", "--send-cpu", std::to_string(sendCpu), "--rt"});
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  for (int i = 0; i < 200; ++i) {
    auto brd = net.datagram(Command::kBrd, DatagramHeader::physical(0, 0x0000), {0, 0});
    ASSERT_TRUE(brd);
    ASSERT_EQ(brd->first, 10);
  }
  const std::string out = readText(log);
  const std::string said = "answers sent by a kernel thread on CPU ";
  const auto at = out.find(said);
  ASSERT_NE(at, std::string::npos) << out;
  const int cpu = std::atoi(out.c_str() + at + said.size());
  EXPECT_EQ(cpu, sendCpu);
  // The server's own affinity leaves the sending CPU out.
  cpu_set_t set;
  ASSERT_EQ(::sched_getaffinity(net.child().pid(), sizeof set, &set), 0);
  EXPECT_FALSE(CPU_ISSET(cpu, &set)) << "the server may still run on CPU " << cpu;
  EXPECT_GE(CPU_COUNT(&set), 1);
  ASSERT_TRUE(net.child().kill(SIGINT).ok());
  auto code = net.child().wait(kExitWait);
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0) << readText(log);
  if (!HasFailure()) std::filesystem::remove(log);
}

// Random frames aimed at the simulator: it must drop what is malformed, count it, keep
// running, and still answer correctly afterwards.
TEST(ServeVethRobustness, SurvivesTenThousandMalformedFrames) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = uniqueTempPath("serve_fuzz.log");
  ServedNetwork net(*ns, 4, "", log);
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  std::mt19937 rng(12345);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  int malformedSent = 0;
  for (int i = 0; i < 10000; ++i) {
    std::size_t len = 14 + rng() % (kMaxFrameSize - 14);
    for (std::size_t k = 0; k < len; ++k) buf[k] = static_cast<std::uint8_t>(rng());
    buf[12] = 0x88;
    buf[13] = 0xA4;
    switch (i % 4) {
      case 0:
        break;  // random EtherCAT header and datagrams
      case 1:   // type 1, but a datagram length past the end
        buf[14] = 0x10;
        buf[15] = 0x10;
        writeLe16(Bytes(buf), 14 + 2 + 6, static_cast<std::uint16_t>(0x7FF));
        len = std::max<std::size_t>(len % 200, 30);
        break;
      case 2:
        len = 14 + rng() % 12;
        break;  // truncated headers
      case 3:   // VLAN tag then garbage
        buf[12] = 0x81;
        buf[13] = 0x00;
        buf[16] = 0x88;
        buf[17] = 0xA4;
        break;
    }
    if (net.link().send(ConstBytes(buf.data(), len)).ok()) ++malformedSent;
    if (i % 256 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GT(malformedSent, 9000);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(net.child().running()) << readText(log);
  // Drain whatever answers the random-but-valid frames produced, then check correctness.
  std::array<std::uint8_t, kMaxFrameSize> drain{};
  while (true) {
    auto got = net.link().receive(drain, std::chrono::milliseconds(50));
    if (!got.ok() || *got == 0) break;
  }
  auto brd = net.datagram(Command::kBrd, 0, {0, 0});
  ASSERT_TRUE(brd);
  EXPECT_EQ(brd->first, 4);
  ASSERT_TRUE(net.child().kill(SIGINT).ok());
  ASSERT_TRUE(net.child().wait(kExitWait).ok());
  std::string out = readText(log);
  auto pos = out.find("malformed dropped ");
  ASSERT_NE(pos, std::string::npos) << out;
  EXPECT_GT(std::stoul(out.substr(pos + 18)), 2000u) << out;
  if (!HasFailure()) std::filesystem::remove(log);
}

TEST(ServeVethCapture, TsharkDecodesEveryFrameAsEtherCat) {
  ECSIM_REQUIRE_NETWORK();
  REQUIRE_TOOL((std::vector<std::string>{"tshark", "--version"}), "tshark");
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string pcap = uniqueTempPath("serve_capture.pcap");
  const std::string log = uniqueTempPath("serve_capture.log");
  std::filesystem::remove(pcap);
  {
    ServedNetwork net(*ns, 3, pcap, log);
    ASSERT_TRUE(net.ok());
    ASSERT_TRUE(net.waitReady()) << readText(log);
    for (std::uint16_t pos = 0; pos < 3; ++pos) {
      auto r = net.datagram(Command::kAprd,
                            DatagramHeader::physical(static_cast<std::uint16_t>(-pos), 0x0000),
                            {0, 0, 0, 0});
      ASSERT_TRUE(r);
      EXPECT_EQ(r->first, 1);
    }
    net.datagram(Command::kBwr, DatagramHeader::physical(0, 0x0120), {0x11, 0x00});
    net.datagram(Command::kFprd, DatagramHeader::physical(0x1001, 0x0130), {0, 0});
    ASSERT_TRUE(net.child().kill(SIGINT).ok());
    auto code = net.child().wait(kExitWait);
    ASSERT_TRUE(code.ok());
    EXPECT_EQ(*code, 0);
  }
  auto decoded =
      runCommand({"tshark", "-r", pcap, "-T", "fields", "-e", "frame.protocols", "-e", "ecat.cmd"});
  ASSERT_TRUE(decoded.ok());
  ASSERT_EQ(decoded->exitCode, 0) << decoded->output;
  std::istringstream lines(decoded->output);
  std::string line;
  int frames = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line.rfind("Running as user", 0) == 0) continue;  // tshark's notice
    ++frames;
    EXPECT_NE(line.find("eth:ethertype:ecat"), std::string::npos) << line;
  }
  EXPECT_GE(frames, 2 * 6) << "each request and its answer captured";
  auto bad =
      runCommand({"tshark", "-r", pcap, "-Y", "_ws.malformed || _ws.expert.severity >= \"error\""});
  ASSERT_TRUE(bad.ok());
  EXPECT_EQ(bad->output.find("ECAT"), std::string::npos) << bad->output;
  auto cmds =
      runCommand({"tshark", "-r", pcap, "-Y", "ecat.cmd == 1", "-T", "fields", "-e", "ecat.cmd"});
  ASSERT_TRUE(cmds.ok());
  EXPECT_NE(cmds->output.find("1"), std::string::npos) << "APRD decoded as command 1";
  if (!HasFailure()) {
    std::filesystem::remove(pcap);
    std::filesystem::remove(log);
  }
}

// A VLAN-tagged request is answered with the same tag (the kernel strips it before the
// simulator's socket; it used to answer untagged).
TEST(ServeVethVlan, AnswersATaggedFrameWithTheSameTci) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = uniqueTempPath("serve_vlan.log");
  ServedNetwork net(*ns, 3, "", log);
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  const std::uint16_t tci = 0xA00C;  // priority 5, VLAN 12
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf,
                 EthernetHeader{kBroadcastMac, {0x02, 0, 0, 0, 0, 7}, tci, kEtherTypeEtherCat});
  ASSERT_TRUE(b.add(Command::kBrd, 0x5A, 0, std::vector<std::uint8_t>{0, 0}).ok());
  const auto len = b.finish();
  ASSERT_TRUE(len.ok());
  ASSERT_TRUE(net.link().send(ConstBytes(buf.data(), *len)).ok());
  std::optional<EthernetHeader> header;
  std::uint16_t wkc = 0;
  std::array<std::uint8_t, kMaxFrameSize> answer{};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!header && std::chrono::steady_clock::now() < deadline) {
    auto n = net.link().receive(answer, std::chrono::milliseconds(20));
    if (!n.ok() || *n == 0 || answer[6] != 0x02 || answer[11] != 7) continue;
    auto frame = EtherCatFrame::parse(std::span(answer.data(), *n));
    if (!frame.ok() || (*frame->begin()).index() != 0x5A) continue;
    header = frame->ethernet();
    wkc = (*frame->begin()).wkc();
  }
  ASSERT_TRUE(header) << "no answer to the tagged frame";
  ASSERT_TRUE(header->vlanTci.has_value()) << "answered without the VLAN tag";
  EXPECT_EQ(*header->vlanTci, tci);
  EXPECT_EQ(wkc, 3);
  ASSERT_TRUE(net.child().kill(SIGINT).ok());
  ASSERT_TRUE(net.child().wait(kExitWait).ok());
  if (!HasFailure()) std::filesystem::remove(log);
}

// `--pcap-malformed FILE`: the frames the simulator dropped as malformed, as they came, in a
// capture of their own (classic pcap has no per-record flag: the file is the flag), so a
// master's bad frames can be looked at in Wireshark.
TEST(ServeVethCapture, MalformedFramesGoToTheirOwnCapture) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string bad = uniqueTempPath("serve_malformed.pcap");
  const std::string log = uniqueTempPath("serve_malformed.log");
  ServedNetwork net(*ns, 2, "", log, {"--pcap-malformed", bad});
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  std::vector<std::vector<std::uint8_t>> sent;
  for (std::uint8_t i = 0; i < 3; ++i) {
    // EtherCAT type 1 with a datagram that claims 0x7FF bytes in a 60-byte frame.
    std::vector<std::uint8_t> frame(60, 0);
    for (std::size_t k = 0; k < 6; ++k) frame[k] = 0xFF;
    frame[6] = 0x02;
    frame[11] = static_cast<std::uint8_t>(0x40 + i);
    writeBe16(frame, 12, kEtherTypeEtherCat);
    writeLe16(frame, 14, 0x1000 | 50);
    writeLe16(frame, 22, 0x7FF);
    ASSERT_TRUE(net.link().send(frame).ok());
    sent.push_back(frame);
  }
  ASSERT_TRUE(net.datagram(Command::kBrd, 0, {0, 0})) << "still answering";
  ASSERT_TRUE(net.child().kill(SIGINT).ok());
  auto code = net.child().wait(kExitWait);
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0) << readText(log);
  auto records = PcapReader::readAll(bad);
  ASSERT_TRUE(records.ok()) << records.error().message();
  ASSERT_EQ(records->size(), sent.size()) << "only the malformed frames, each once";
  for (std::size_t i = 0; i < sent.size(); ++i) EXPECT_EQ((*records)[i].data, sent[i]);
  if (!HasFailure()) {
    std::filesystem::remove(bad);
    std::filesystem::remove(log);
  }
}

// Captures you can trust after a crash. A server that answered and then idled has its records
// on disk (it wrote 0 bytes before), and SIGKILL in the middle of traffic leaves a file that
// capinfos reads without error (it ended in a torn record before): whole records only.
TEST(ServeVethCapture, SigkillDuringTrafficLeavesACaptureCapinfosReads) {
  ECSIM_REQUIRE_NETWORK();
  REQUIRE_TOOL((std::vector<std::string>{"capinfos", "-h"}), "capinfos");
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string pcap = uniqueTempPath("serve_kill.pcap");
  const std::string log = uniqueTempPath("serve_kill.log");
  std::filesystem::remove(pcap);
  // SIGKILL leaves the control socket behind: in the temporary folder, removed below.
  const std::string control = uniqueTempPath("serve_kill.sock");
  ServedNetwork net(*ns, 2, pcap, log, {"--control", control});
  ASSERT_TRUE(net.ok());
  ASSERT_TRUE(net.waitReady()) << readText(log);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(net.datagram(Command::kBrd, 0, {0, 0}));
  // Idle now: every answered frame and its request reach the file without any further frame.
  auto recordsOnDisk = [&] {
    auto records = PcapReader::readAll(pcap);
    return records.ok() ? records->size() : std::size_t{0};
  };
  EXPECT_TRUE(waitUntil([&] { return recordsOnDisk() >= 20; }))
      << "an idle server keeps its records buffered: " << recordsOnDisk() << " on disk";
  const std::size_t beforeTraffic = recordsOnDisk();
  // Traffic, and SIGKILL in its middle.
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {0x02, 0, 0, 0, 0, 1}, std::nullopt, kEtherTypeEtherCat});
  ASSERT_TRUE(b.add(Command::kBrd, 1, 0, std::vector<std::uint8_t>{0, 0}).ok());
  const auto len = b.finish();
  ASSERT_TRUE(len.ok());
  std::array<std::uint8_t, kMaxFrameSize> answer{};
  SimTime killedAt = 0;
  for (int i = 0; i < 4000; ++i) {
    (void)net.link().send(ConstBytes(buf.data(), *len));
    (void)net.link().receive(answer, std::chrono::microseconds(i % 2 == 0 ? 0 : 200));
    if (i == 2000) {
      killedAt = WallClock().now();
      ASSERT_TRUE(net.child().kill(SIGKILL).ok());
    }
  }
  auto code = net.child().wait(kExitWait);
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 128 + SIGKILL);
  auto info = runCommand({"capinfos", "-c", pcap});
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->exitCode, 0) << info->output;
  EXPECT_EQ(info->output.find("error"), std::string::npos) << info->output;
  auto records = PcapReader::readAll(pcap);
  ASSERT_TRUE(records.ok()) << records.error().message();
  EXPECT_GT(records->size(), beforeTraffic) << "records of the traffic before the kill";
  if (!records->empty() && killedAt > 0) {
    // A figure, not a pass/fail: how much before the kill the last record on disk was stamped.
    std::printf("capture after SIGKILL: %zu records, the last one %.1f ms before the kill\n",
                records->size(), static_cast<double>(killedAt - records->back().timestampNs) / 1e6);
  }
  std::filesystem::remove(control);
  if (!HasFailure()) {
    std::filesystem::remove(pcap);
    std::filesystem::remove(log);
  }
}

// `--pcap` on a full device: reported at once (the header is written at open), exit status 1;
// it used to serve on, losing every record, and exit 0.
TEST(ServeVethCapture, FullDeviceIsReportedAtOnceWithAFailingExitStatus) {
  ECSIM_REQUIRE_NETWORK();
  if (!std::filesystem::exists("/dev/full")) {
    if (ciMode()) FAIL() << "/dev/full missing under CI=true";
    GTEST_SKIP() << "no /dev/full";
  }
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = uniqueTempPath("serve_full.log");
  ServedNetwork net(*ns, 1, "/dev/full", log);
  ASSERT_TRUE(net.ok());
  auto code = net.child().wait(kExitWait);
  if (!code.ok()) (void)net.child().stop();
  ASSERT_TRUE(code.ok()) << "still serving with a capture that loses everything";
  EXPECT_NE(*code, 0);
  const std::string out = readText(log);
  EXPECT_NE(out.find("/dev/full"), std::string::npos) << out;
  EXPECT_NE(out.find("No space left"), std::string::npos) << out;
  if (!HasFailure()) std::filesystem::remove(log);
}

}  // namespace
}  // namespace ecsim::testing
