#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "link/pcap.hpp"
#include "link/pcap_tap.hpp"
#include "protocol/time.hpp"
#include "test_support.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;
using testing::etherCatFrame;

// A file path in the temporary directory, removed at the end of the test.
class TempPath {
 public:
  explicit TempPath(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("ecsim-link-" + std::to_string(::getpid()) + "-" + name)) {}
  ~TempPath() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

std::vector<std::uint8_t> fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

TEST(PcapWriter, RoundTripKeepsBytesAndNanosecondTimestamps) {
  TempPath file("roundtrip.pcap");
  const std::vector<std::vector<std::uint8_t>> frames = {etherCatFrame(1), etherCatFrame(2),
                                                         std::vector<std::uint8_t>(1514, 0xA5)};
  // 2023-11-14T22:13:20.123456789Z, then 1 ns later, then model time 5 ns after epoch 0.
  const std::vector<SimTime> stamps = {1'700'000'000'123'456'789, 1'700'000'000'123'456'790, 5};
  {
    auto writer = PcapWriter::open(file.str());
    ASSERT_TRUE(writer.ok()) << writer.error().message();
    for (std::size_t i = 0; i < frames.size(); ++i) {
      ASSERT_TRUE(writer->write(frames[i], stamps[i]).ok());
    }
    EXPECT_EQ(writer->framesWritten(), 3u);
    ASSERT_TRUE(writer->close().ok());
  }
  // Classic pcap, nanosecond variant: magic 0xa1b23c4d in host (little-endian) order, then
  // version 2.4, snap length 65535 and link type 1 (pcap file format, LINKTYPE_ETHERNET).
  const auto bytes = fileBytes(file.str());
  ASSERT_GE(bytes.size(), 24u);
  EXPECT_EQ(readLe32(bytes, 0), 0xa1b23c4du);
  EXPECT_EQ(readLe16(bytes, 4), 2);
  EXPECT_EQ(readLe16(bytes, 6), 4);
  EXPECT_EQ(readLe32(bytes, 16), 65535u);
  EXPECT_EQ(readLe32(bytes, 20), 1u);
  // First record header: seconds, then nanoseconds.
  EXPECT_EQ(readLe32(bytes, 24), 1'700'000'000u);
  EXPECT_EQ(readLe32(bytes, 28), 123'456'789u);

  auto reader = PcapReader::open(file.str());
  ASSERT_TRUE(reader.ok()) << reader.error().message();
  EXPECT_EQ(reader->linkType(), kLinkTypeEthernet);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    auto frame = reader->next();
    ASSERT_TRUE(frame.ok()) << frame.error().message();
    ASSERT_TRUE(frame->has_value());
    EXPECT_EQ((*frame)->timestampNs, stamps[i]);
    EXPECT_EQ((*frame)->originalLength, frames[i].size());
    EXPECT_EQ(std::vector<std::uint8_t>((*frame)->data.begin(), (*frame)->data.end()), frames[i]);
  }
  auto end = reader->next();
  ASSERT_TRUE(end.ok());
  EXPECT_FALSE(end->has_value());
  EXPECT_EQ(reader->frameCount(), 3u);
}

TEST(PcapWriter, FlushMakesFramesVisibleBeforeClose) {
  TempPath file("flush.pcap");
  auto writer = PcapWriter::open(file.str());
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->write(etherCatFrame(9), 42).ok());
  ASSERT_TRUE(writer->flush().ok());
  auto records = PcapReader::readAll(file.str());
  ASSERT_TRUE(records.ok()) << records.error().message();
  ASSERT_EQ(records->size(), 1u);
  EXPECT_EQ((*records)[0].timestampNs, 42);
  EXPECT_EQ((*records)[0].data, etherCatFrame(9));
}

TEST(PcapWriter, RefusesTimestampsOutsideThePcapRangeAndWritesAfterClose) {
  TempPath file("range.pcap");
  auto writer = PcapWriter::open(file.str());
  ASSERT_TRUE(writer.ok());
  auto negative = writer->write(etherCatFrame(1), -1);
  ASSERT_FALSE(negative.ok());
  EXPECT_EQ(negative.error().code, ErrorCode::kInvalidArgument);
  auto tooLate = writer->write(etherCatFrame(1), (SimTime{1} << 32) * kNsPerSecond);
  ASSERT_FALSE(tooLate.ok());
  EXPECT_EQ(tooLate.error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(writer->framesWritten(), 0u);
  ASSERT_TRUE(writer->close().ok());
  EXPECT_FALSE(writer->isOpen());
  EXPECT_TRUE(writer->close().ok());
  auto afterClose = writer->write(etherCatFrame(1), 0);
  ASSERT_FALSE(afterClose.ok());
  EXPECT_EQ(afterClose.error().code, ErrorCode::kState);
}

TEST(PcapWriter, ReportsAnUnwritablePath) {
  auto writer = PcapWriter::open("/nonexistent-dir-ecsim/x.pcap");
  ASSERT_FALSE(writer.ok());
  EXPECT_EQ(writer.error().code, ErrorCode::kIo);
  EXPECT_NE(writer.error().context.find("/nonexistent-dir-ecsim/x.pcap"), std::string::npos);
}

// Captures you can trust after a crash: the header is on disk at open, buffered records reach
// the file within kCaptureFlushInterval of the caller's clock, and only whole records do.
TEST(PcapWriter, HeaderIsOnDiskAtOpen) {
  TempPath file("header.pcap");
  auto writer = PcapWriter::open(file.str());
  ASSERT_TRUE(writer.ok()) << writer.error().message();
  EXPECT_EQ(fileBytes(file.str()).size(), 24u) << "a capture killed before its first frame";
}

TEST(PcapWriter, FlushIfDueWritesWholeRecordsOnceTheIntervalHasPassed) {
  TempPath file("due.pcap");
  auto writer = PcapWriter::open(file.str());
  ASSERT_TRUE(writer.ok()) << writer.error().message();
  const SimTime t0 = 5 * kNsPerSecond;
  ASSERT_TRUE(writer->flushIfDue(t0).ok());
  ASSERT_TRUE(writer->write(etherCatFrame(1), 1).ok());
  ASSERT_TRUE(writer->write(etherCatFrame(2), 2).ok());
  ASSERT_TRUE(writer->flushIfDue(t0 + kCaptureFlushInterval - 1).ok());
  EXPECT_EQ(fileBytes(file.str()).size(), 24u) << "not due yet: buffered";
  ASSERT_TRUE(writer->flushIfDue(t0 + kCaptureFlushInterval).ok());
  EXPECT_EQ(fileBytes(file.str()).size(), 24u + 2 * (16 + 60)) << "due: both records written";
  // Whatever is on disk reads back whole, before close.
  auto records = PcapReader::readAll(file.str());
  ASSERT_TRUE(records.ok()) << records.error().message();
  EXPECT_EQ(records->size(), 2u);
}

TEST(PcapWriter, FullDiskFailsAtOpenNamingTheFile) {
  ECSIM_REQUIRE_OR_SKIP(std::filesystem::exists("/dev/full"), "no /dev/full");
  auto writer = PcapWriter::open("/dev/full");
  ASSERT_FALSE(writer.ok()) << "the header write must fail on a full device";
  EXPECT_EQ(writer.error().code, ErrorCode::kIo);
  EXPECT_NE(writer.error().context.find("/dev/full"), std::string::npos) << writer.error().context;
  EXPECT_NE(writer.error().context.find("No space left"), std::string::npos)
      << writer.error().context;
}

// A PcapTap on the master's end of a memory link pair, writing to a temporary file, stamped
// with a virtual clock at 1000 ns.
struct TapOnMemoryLink {
  explicit TapOnMemoryLink(const std::string& name)
      : file(name),
        writer(std::move(PcapWriter::open(file.str())).value()),
        links(MemoryLink::makePair(4)),
        clock(1'000),
        tap(links.first, writer, clock) {}
  TempPath file;
  PcapWriter writer;
  std::pair<MemoryLink, MemoryLink> links;
  VirtualClock clock;
  PcapTap tap;
};

// A write error after open (here the file-size limit, as a full disk would) is reported by
// the flush that meets it, names the file and the frames lost, and sticks: every later call
// reports it, nothing is written past it.
TEST(PcapWriter, AWriteErrorSticksAndNamesTheFile) {
  TempPath file("efbig.pcap");
  const int code = testing::runInChild([&]() -> int {
    std::signal(SIGXFSZ, SIG_IGN);  // in the child only: the write fails with EFBIG instead
    const rlimit limit{200, 200};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return 100;
    auto writer = PcapWriter::open(file.str());
    if (!writer.ok()) return 1;
    for (std::uint8_t i = 0; i < 5; ++i) {
      if (!writer->write(etherCatFrame(i), i).ok()) return 2;
    }
    auto flushed = writer->flush();
    if (flushed.ok() || flushed.error().code != ErrorCode::kIo) return 3;
    if (flushed.error().context.find(file.str()) == std::string::npos) return 4;
    if (flushed.error().context.find("5 frame(s) lost") == std::string::npos) return 5;
    if (writer->write(etherCatFrame(9), 9).ok()) return 6;
    if (writer->flushIfDue(kNsPerSecond).ok() || writer->close().ok()) return 7;
    return 0;
  });
  EXPECT_EQ(code, 0) << "1: open, 2: buffered write, 3: flush not kIo, 4: no path, 5: no count, "
                        "6: write after error, 7: error not sticky";
}

// PcapTap flushes when a receive finds nothing waiting (the link is idle).
TEST(PcapTap, AnIdleReceiveFlushes) {
  TapOnMemoryLink t("tap_idle.pcap");
  auto& [file, writer, links, clock, tap] = t;
  ASSERT_TRUE(tap.send(etherCatFrame(1)).ok());
  EXPECT_EQ(fileBytes(file.str()).size(), 24u) << "buffered while busy";
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(*tap.receive(buf, 0ns), 0u);
  EXPECT_EQ(fileBytes(file.str()).size(), 24u + 16 + 60) << "flushed when idle";
  EXPECT_TRUE(tap.captureStatus().ok());
}

TEST(PcapReader, ReportsAMissingFile) {
  auto reader = PcapReader::open("/nonexistent-dir-ecsim/y.pcap");
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.error().code, ErrorCode::kIo);
  EXPECT_NE(reader.error().context.find("/nonexistent-dir-ecsim/y.pcap"), std::string::npos);
}

// A pcapng frame whose 64-bit timestamp (microseconds) lies far beyond what SimTime holds
// (year 2262): an error naming the file and frame, not a wrapped time (found by fuzz_pcap,
// which hit the overflow in the seconds-to-nanoseconds conversion).
TEST(PcapReader, RefusesATimestampBeyondSimTime) {
  auto le32 = [](std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  std::vector<std::uint8_t> bytes;
  // Section header block: type, length, byte-order magic, version 1.0, section length -1.
  for (std::uint32_t v : {0x0A0D0D0Au, 28u, 0x1A2B3C4Du, 1u, 0xFFFFFFFFu, 0xFFFFFFFFu, 28u}) {
    le32(bytes, v);
  }
  // Interface description block: Ethernet, snap length 0 (unlimited), microseconds.
  for (std::uint32_t v : {1u, 20u, 1u, 0u, 20u}) le32(bytes, v);
  // Enhanced packet block on interface 0, timestamp 0xFFFFFFFF'00000000 us, 4 bytes of data.
  for (std::uint32_t v : {6u, 36u, 0u, 0xFFFFFFFFu, 0u, 4u, 4u, 0x04030201u, 36u}) le32(bytes, v);
  TempPath file("far-future.pcapng");
  {
    std::ofstream out(file.str(), std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }
  auto reader = PcapReader::open(file.str());
  ASSERT_TRUE(reader.ok()) << reader.error().message();
  auto frame = reader->next();
  ASSERT_FALSE(frame.ok());
  EXPECT_NE(frame.error().context.find(file.str()), std::string::npos) << frame.error().message();
  EXPECT_NE(frame.error().context.find("frame 1"), std::string::npos) << frame.error().message();
  EXPECT_NE(frame.error().context.find("timestamp"), std::string::npos) << frame.error().message();
}

// Real captures from ../shared/pcap (MANIFEST.md gives their frame counts; first timestamps
// and EtherTypes as printed by `tshark -T fields -e frame.time_epoch -e eth.type`).
TEST(PcapReader, ReadsRealPcapngCaptures) {
  const std::string dir = std::string(ECSIM_SHARED_DIR) + "/pcap/";
  const std::string soem = dir + "soem-sdinfo-ek1100-el1004.pcapng";
  const std::string replay = dir + "replay-ek1914-el3004-mailbox.pcapng";
  ECSIM_REQUIRE_OR_SKIP(std::filesystem::exists(soem) && std::filesystem::exists(replay),
                        "captures under " + dir + " are missing");

  auto soemFrames = PcapReader::readAll(soem);
  ASSERT_TRUE(soemFrames.ok()) << soemFrames.error().message();
  ASSERT_EQ(soemFrames->size(), 594u);  // 580 EtherCAT + 14 unrelated IP frames
  std::size_t etherCat = 0;
  for (const auto& record : *soemFrames) {
    if (record.data.size() >= 14 && readBe16(record.data, 12) == kEtherTypeEtherCat) ++etherCat;
  }
  EXPECT_EQ(etherCat, 580u);
  // Frame 1: 1654945306.809188000 (a microsecond capture, scaled to ns), 72 bytes, IPv4.
  EXPECT_EQ((*soemFrames)[0].timestampNs, 1'654'945'306'809'188'000);
  EXPECT_EQ((*soemFrames)[0].data.size(), 72u);

  auto reader = PcapReader::open(replay);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->linkType(), kLinkTypeEthernet);
  auto first = reader->next();
  ASSERT_TRUE(first.ok() && first->has_value());
  // Frame 1: 1773541007.813262247 (nanosecond capture), 29 bytes (unpadded, as sent).
  EXPECT_EQ((*first)->timestampNs, 1'773'541'007'813'262'247);
  EXPECT_EQ((*first)->data.size(), 29u);
  std::size_t count = 1;
  for (;;) {
    auto frame = reader->next();
    ASSERT_TRUE(frame.ok()) << frame.error().message();
    if (!frame->has_value()) break;
    ++count;
  }
  EXPECT_EQ(count, 994u);
}

TEST(PcapTap, RecordsBothDirectionsWithClockTime) {
  TapOnMemoryLink t("tap.pcap");
  auto& [file, writer, links, clock, tap] = t;
  auto& [master, network] = links;
  EXPECT_EQ(tap.pollFd(), master.pollFd());
  EXPECT_NE(tap.describe().find(file.str()), std::string::npos);

  ASSERT_TRUE(tap.send(etherCatFrame(1)).ok());
  // A frame the inner link refuses is not recorded.
  ASSERT_FALSE(tap.send(std::vector<std::uint8_t>(kMaxFrameSize + 1)).ok());
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(*network.receive(buf, 0ns), 60u);
  ASSERT_TRUE(network.send(etherCatFrame(2)).ok());
  clock.advance(2'500);
  // Nothing waiting: nothing recorded.
  ASSERT_EQ(*tap.receive(buf, 0ns), 60u);
  ASSERT_EQ(*tap.receive(buf, 0ns), 0u);
  EXPECT_EQ(tap.framesCaptured(), 2u);
  EXPECT_TRUE(tap.captureStatus().ok());
  ASSERT_TRUE(writer.close().ok());

  auto records = PcapReader::readAll(file.str());
  ASSERT_TRUE(records.ok()) << records.error().message();
  ASSERT_EQ(records->size(), 2u);
  EXPECT_EQ((*records)[0].timestampNs, 1'000);
  EXPECT_EQ((*records)[0].data, etherCatFrame(1));
  EXPECT_EQ((*records)[1].timestampNs, 3'500);
  EXPECT_EQ((*records)[1].data, etherCatFrame(2));
}

TEST(PcapTap, KeepsTheFirstCaptureErrorWithoutFailingTheLink) {
  TempPath file("closed.pcap");
  auto writer = PcapWriter::open(file.str());
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->close().ok());
  auto [master, network] = MemoryLink::makePair(4);
  VirtualClock clock;
  PcapTap tap(master, *writer, clock);
  EXPECT_TRUE(tap.send(etherCatFrame(1)).ok());
  EXPECT_EQ(network.pending(), 1u);
  ASSERT_FALSE(tap.captureStatus().ok());
  EXPECT_EQ(tap.captureStatus().error().code, ErrorCode::kState);
  EXPECT_EQ(tap.framesCaptured(), 0u);
}

// tshark must decode what we write as EtherCAT with nothing malformed.
TEST(PcapWriter, TsharkDecodesFramesAsEtherCat) {
  ECSIM_REQUIRE_OR_SKIP(std::filesystem::exists("/usr/bin/tshark"),
                        "tshark is not installed (apt-get install tshark)");
  TempPath file("tshark.pcap");
  TempPath fields("tshark.out");
  TempPath diagnostics("tshark.err");
  {
    auto writer = PcapWriter::open(file.str());
    ASSERT_TRUE(writer.ok());
    auto [master, network] = MemoryLink::makePair(4);
    WallClock clock;
    PcapTap tap(master, *writer, clock);
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    for (std::uint8_t i = 0; i < 3; ++i) {
      ASSERT_TRUE(tap.send(etherCatFrame(i)).ok());
      ASSERT_EQ(*network.receive(buf, 0ns), 60u);
      ASSERT_TRUE(network.send(etherCatFrame(static_cast<std::uint8_t>(i + 10))).ok());
      ASSERT_EQ(*tap.receive(buf, 0ns), 60u);
    }
    ASSERT_TRUE(writer->close().ok());
  }
  auto tshark = spawnProcess({"tshark", "-r", file.str(), "-T", "fields", "-e", "frame.protocols"},
                             SpawnOptions{fields.str(), diagnostics.str()});
  ASSERT_TRUE(tshark.ok()) << tshark.error().message();
  auto exitCode = tshark->wait(60s);
  ASSERT_TRUE(exitCode.ok()) << exitCode.error().message();
  ASSERT_EQ(*exitCode, 0) << "tshark failed; stderr in " << diagnostics.str();

  std::ifstream in(fields.str());
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 6u);
  // tshark 4.0 prints "eth:ethertype:ecatf:ecat" (EtherCAT frame header, then datagrams) for
  // every frame of the real captures in ../shared/pcap, e.g. all 3604 of replay-dc.pcapng.
  // A malformed frame would add "_ws.malformed".
  for (const auto& line : lines) {
    EXPECT_TRUE(line.starts_with("eth:ethertype:ecat")) << line;
    EXPECT_TRUE(line.ends_with(":ecat")) << line;
    EXPECT_EQ(line.find("malformed"), std::string::npos) << line;
  }
}

}  // namespace
}  // namespace ecsim
