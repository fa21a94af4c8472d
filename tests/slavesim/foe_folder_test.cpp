// FoE files kept beside a slave's state file (issue #20 item 1: files written over FoE are
// stored per slave, in memory and optionally with the slave's state file;
// slavesim/foe/foe_folder.hpp). The SOES demo slave (foe_test_support.hpp) gets a firmware
// image in BOOT through frames; a second slave built from the same state file is the simulator
// started again, i.e. the device powered up: it boots the image (0x100A, CiA 301 §7.5.2.5) and
// reads the file back. A transfer cut short leaves the previous file, a host that cannot write
// the file makes the device answer "disk full" (ETG.1000.6 §5.7, FoE error 0x8003), and the
// folder is our own format, read strictly.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <string>

#include "slavesim/foe/foe_folder.hpp"
#include "tests/slavesim/foe_test_support.hpp"
#include "tests/slavesim/temp_dir.hpp"

namespace ecsim::testing {
namespace {

using slavesim::foe::FoeFiles;

class FoeFolderTest : public TempDir {
 protected:
  std::filesystem::path stateFile() const { return dir_ / "soes.state"; }
  std::filesystem::path folder() const { return dir_ / "soes.state.foe"; }
  slavesim::EsiSlaveOptions options() const {
    slavesim::EsiSlaveOptions o;
    o.stateFile = stateFile();
    return o;
  }
  static std::string text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void put(const std::filesystem::path& p, const std::string& s) {
    std::ofstream(p, std::ios::binary) << s;
  }
  // The software version (0x100A) the device reports in PREOP.
  static std::string softwareVersion(FoeSlave& s) {
    MailboxMaster preop(s.seg, kStation, 0x1000, 128, 0x1080, 128);
    preop.configureSyncManagers();
    requestState(s.seg, kStation, 0x0002);
    EXPECT_EQ(alStatus(s.seg, kStation), 0x0002);
    const Upload up = preop.upload(0x100A, 0);
    EXPECT_EQ(up.abort, 0u);
    requestState(s.seg, kStation, kInit);
    return {up.data.begin(), up.data.end()};
  }
};

TEST(FoeFolderNames, PercentEncodingKeepsEveryNameOneFolderEntry) {
  using slavesim::foe::percentDecode;
  using slavesim::foe::percentEncode;
  EXPECT_EQ(percentEncode("app_v2.bin"), "app_v2.bin");
  EXPECT_EQ(percentEncode("fw/../x y"), "fw%2F..%2Fx%20y");
  EXPECT_EQ(percentEncode(std::string("a\0%", 3)), "a%00%25");
  for (const std::string& name :
       std::vector<std::string>{"fw/../x y", "%", "..", std::string("\xff\x01", 2)}) {
    EXPECT_EQ(percentDecode(percentEncode(name)), name);
    EXPECT_EQ(percentEncode(name).find('/'), std::string::npos);
  }
  EXPECT_FALSE(percentDecode("a b"));
  EXPECT_FALSE(percentDecode("%2"));
  EXPECT_FALSE(percentDecode("%G0"));
}

TEST_F(FoeFolderTest, FirmwareWrittenInBootOutlivesTheSimulator) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  const auto image = firmwareImage(300, "3.0.1");
  std::string versionBefore;
  {
    FoeSlave s(options());
    ASSERT_TRUE(s.ready());
    versionBefore = softwareVersion(s);
    s.toBoot();
    ASSERT_EQ(alStatus(s.seg, kStation), kBoot);
    const FoeReply w = s.write("fw/app.bin", image);
    EXPECT_EQ(w.opcode, FoeOpcode::kAck);
    EXPECT_EQ(w.value, 3u);
    // On disk as soon as the last packet is acknowledged, under its encoded name.
    EXPECT_EQ(text(folder() / "file-fw%2Fapp.bin"), std::string(image.begin(), image.end()));
    EXPECT_NE(text(folder() / "firmware").find("\npending fw%2Fapp.bin\n"), std::string::npos)
        << text(folder() / "firmware");
    EXPECT_FALSE(std::filesystem::exists(folder() / "file-fw%2Fapp.bin.tmp"));
  }
  ASSERT_NE(versionBefore, "3.0.1");

  // The simulator started again: the device powers up with the image written in BOOT.
  FoeSlave again(options());
  ASSERT_TRUE(again.ready());
  EXPECT_EQ(softwareVersion(again), "3.0.1");
  const std::string record = text(folder() / "firmware");
  EXPECT_EQ(record.find("pending"), std::string::npos) << record;
  EXPECT_NE(record.find("\ninstalled-version 3.0.1\n"), std::string::npos) << record;
  again.toBoot();
  EXPECT_EQ(again.read("fw/app.bin"), image);

  // And once more: installed, not pending, it still reports the new version.
  FoeSlave third(options());
  ASSERT_TRUE(third.ready());
  EXPECT_EQ(softwareVersion(third), "3.0.1");
}

TEST_F(FoeFolderTest, ATransferCutShortLeavesThePreviousFile) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  const auto first = firmwareImage(300, "1.0");
  {
    FoeSlave s(options());
    ASSERT_TRUE(s.ready());
    s.toBoot();
    EXPECT_EQ(s.write("app.bin", first).value, 3u);
    // A second write of app.bin: WRQ and one full DATA packet, then the master gives up (ERR).
    EXPECT_EQ(s.transact(FoeOpcode::kWrite, 0, std::string_view("app.bin")).opcode,
              FoeOpcode::kAck);
    const std::vector<std::uint8_t> part(foeDataPerPacket(s.bootOutSize), 0xEE);
    EXPECT_EQ(s.transact(FoeOpcode::kData, 1, ConstBytes(part)).opcode, FoeOpcode::kAck);
    EXPECT_TRUE(std::filesystem::exists(folder() / "file-app.bin.tmp"));
    auto err = encodeFoeMailbox(FoeOpcode::kError, 0x8000, "stop");
    err[5] = static_cast<std::uint8_t>(err[5] | (s.master->nextCounter() << 4));
    s.master->send(err);
    s.seg.pollSlaves(0);
    EXPECT_FALSE(std::filesystem::exists(folder() / "file-app.bin.tmp"));
  }
  // A simulator killed mid-transfer leaves a .tmp behind: skipped when the folder is read.
  put(folder() / "file-app.bin.tmp", "half");
  FoeSlave again(options());
  ASSERT_TRUE(again.ready());
  again.toBoot();
  EXPECT_EQ(again.read("app.bin"), first);
}

TEST_F(FoeFolderTest, NothingIsMadeUntilAFileIsWritten) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  FoeSlave s(options());
  ASSERT_TRUE(s.ready());
  // A network built by a command that never runs it (ecsim check, a study) leaves no folder.
  EXPECT_FALSE(std::filesystem::exists(folder()));
  s.toBoot();
  EXPECT_FALSE(std::filesystem::exists(folder())) << "a state change writes nothing";
  EXPECT_EQ(s.write("app.bin", firmwareImage(200, "x")).value, 2u);
  EXPECT_TRUE(std::filesystem::is_regular_file(folder() / "file-app.bin"));
}

TEST_F(FoeFolderTest, AFileTheHostCannotWriteIsDiskFull) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  FoeSlave s(options());
  ASSERT_TRUE(s.ready());
  s.toBoot();
  // A folder where the transfer's temporary file would go: open(2) fails (EISDIR).
  std::filesystem::create_directories(folder() / "file-app.bin.tmp");
  const FoeReply w = s.transact(FoeOpcode::kWrite, 0, std::string_view("app.bin"));
  EXPECT_EQ(w.opcode, FoeOpcode::kError);
  EXPECT_EQ(w.value, 0x8003u) << "disk full";
  std::filesystem::remove(folder() / "file-app.bin.tmp");
  EXPECT_EQ(s.write("app.bin", firmwareImage(200, "x")).value, 2u) << "and writable again";
}

TEST_F(FoeFolderTest, TheFolderIsReadStrictly) {
  const auto refusal = [&] {
    auto files = FoeFiles::keptIn(folder());
    EXPECT_FALSE(files.ok());
    return files.ok() ? std::string() : files.error().message();
  };
  std::filesystem::create_directory(folder());
  put(folder() / "notes.txt", "mine");
  EXPECT_NE(refusal().find("notes.txt"), std::string::npos) << refusal();
  std::filesystem::remove(folder() / "notes.txt");

  put(folder() / "firmware", "ecsim-foe-firmware 1\npendnig app.bin\n");
  const std::string unknownKey = refusal();
  EXPECT_NE(unknownKey.find("firmware:2"), std::string::npos) << unknownKey;
  EXPECT_NE(unknownKey.find("pendnig"), std::string::npos) << unknownKey;

  put(folder() / "firmware", "ecsim-foe-firmware 1\npending app.bin\n");
  EXPECT_NE(refusal().find("'app.bin' is not in the folder"), std::string::npos) << refusal();
  put(folder() / "file-app.bin", "image");
  auto files = FoeFiles::keptIn(folder());
  ASSERT_TRUE(files.ok()) << files.error().message();
  EXPECT_EQ((*files)->find("app.bin")->size(), 5u);
  EXPECT_FALSE((*files)->pendingFirmware()) << "installed at the start, a power-up";

  std::filesystem::remove_all(folder());
  put(folder(), "a regular file");
  EXPECT_NE(refusal().find("refused as an FoE file folder"), std::string::npos);
  std::filesystem::remove(folder());
  std::filesystem::create_directory(dir_ / "elsewhere");
  std::filesystem::create_directory_symlink(dir_ / "elsewhere", folder());
  EXPECT_NE(refusal().find("symbolic link"), std::string::npos) << refusal();
}

}  // namespace
}  // namespace ecsim::testing
