// The master sends what an ENI's <Cyclic> says (master/eni_config.hpp: planEniLayout). The ENI
// is the one eni_export writes for the demo network (what `ecmaster xml` writes), edited here
// the way another configuration tool could have written it: another logical start address;
// outputs and inputs in two frames as an LWR and an LRD, plus a BRD of AL status (0x0130) sent
// in OP only. Each is checked on the wire through a capturing Link, reaches OP, runs 10,000
// cycles without a WKC error, and its variables read the right data under their ENI names; a
// WKC mismatch names the slaves of that Cmd. Errors in the ENI name the file and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "config/eni.hpp"
#include "master/eni_export.hpp"
#include "master/master.hpp"
#include "protocol/frame.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/sim_network.hpp"

namespace ecsim::testing {
namespace {

using master::Master;

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive, kDrive2, kCount };

// Records every frame the master sends while `capturing` is set.
class CaptureLink final : public Link {
 public:
  explicit CaptureLink(Link& inner) : inner_(inner) {}
  Status send(ConstBytes frame) override {
    if (capturing) sent.emplace_back(frame.begin(), frame.end());
    return inner_.send(frame);
  }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    return inner_.receive(buffer, timeout);
  }
  int pollFd() const override { return inner_.pollFd(); }
  std::string describe() const override { return "capture(" + inner_.describe() + ")"; }

  bool capturing{false};
  std::vector<std::vector<std::uint8_t>> sent;

 private:
  Link& inner_;
};

struct WireDatagram {
  Command command{Command::kNop};
  std::uint32_t address{0};
  std::uint16_t length{0};
  bool operator==(const WireDatagram&) const = default;
};

std::string describe(const std::vector<WireDatagram>& list) {
  std::string s;
  for (const auto& d : list) {
    s += std::string(toString(d.command)) + " " + std::to_string(d.address) + "+" +
         std::to_string(d.length) + "; ";
  }
  return s;
}

std::vector<WireDatagram> datagramsOf(const std::vector<std::uint8_t>& frame) {
  std::vector<WireDatagram> out;
  auto parsed = ConstEtherCatFrame::parse(ConstBytes(frame.data(), frame.size()));
  EXPECT_TRUE(parsed.ok());
  if (!parsed.ok()) return out;
  for (const auto& d : *parsed) out.push_back({d.command(), d.address(), d.length()});
  return out;
}

std::vector<EniCyclicCmd>& cmdsOf(EniConfig& eni, std::size_t frame) {
  return eni.cyclic.at(0).frames.at(frame).cmds;
}

class EniCyclicTest : public ::testing::Test {
 protected:
  EniCyclicTest() : capture_(net_.masterLink()) {}
  void SetUp() override {
    addDemoSlaves(net_);
    net_.start();
  }

  // What `ecmaster xml` writes for the demo network: a master configures itself, exports.
  EniConfig exportedEni() {
    Master self(net_.masterLink(), net_.bus());
    auto status = self.start();
    EXPECT_TRUE(status.ok()) << status.error().message();
    EniConfig eni = master::eniFromMaster(self);
    EXPECT_TRUE(self.stop().ok());
    // The names a user gives the slaves in the tool (the export has the SII's device names).
    const char* names[] = {"Coupler", "DI1", "DO1", "AI1", "Drive1", "Drive2"};
    EXPECT_EQ(eni.slaves.size(), std::size(names));
    for (std::size_t i = 0; i < eni.slaves.size() && i < std::size(names); ++i) {
      // The slave's variables: its name and within its <Send>/<Recv> bits (the drives share
      // their SII name).
      const std::string before = eni.slaves[i].name + ".";
      const EniProcessData& pd = eni.slaves[i].processData;
      for (bool output : {true, false}) {
        for (const EniBitRange& r : output ? pd.send : pd.recv) {
          for (auto& v : output ? eni.processImage.outputs : eni.processImage.inputs) {
            if (v.name.rfind(before, 0) != 0 || v.bitOffs < r.bitStart ||
                v.bitOffs >= r.bitStart + r.bitLength) {
              continue;
            }
            v.name = names[i] + v.name.substr(before.size() - 1);
          }
        }
      }
    }
    for (std::size_t i = 0; i < eni.slaves.size() && i < std::size(names); ++i) {
      eni.slaves[i].name = names[i];
    }
    return eni;
  }

  // Writes the ENI as XML and reads it back (so every Cmd has its line), then starts a master.
  Status startWith(const EniConfig& eni, const std::string& file = "edited-eni.xml") {
    auto parsed = parseEni(formatEni(eni), file);
    EXPECT_TRUE(parsed.ok()) << parsed.error().message();
    if (!parsed.ok()) return parsed.takeError();
    master_ = std::make_unique<Master>(capture_, net_.bus());
    master_->setConfig(masterConfigFromEni(std::move(parsed).value()));
    return master_->start();
  }
  const EniConfig& loaded() const { return *master_->config()->eni; }

  // `cycles` exchanges, captured; returns the datagrams of every frame sent.
  std::vector<std::vector<WireDatagram>> runCaptured(int cycles) {
    capture_.sent.clear();
    capture_.capturing = true;
    int failures = 0;
    std::string first;
    for (int c = 0; c < cycles; ++c) {
      auto s = master_->exchange();
      if (!s.ok() && failures++ == 0) first = s.error().message();
    }
    capture_.capturing = false;
    EXPECT_EQ(failures, 0) << first;
    std::vector<std::vector<WireDatagram>> frames;
    for (const auto& f : capture_.sent) frames.push_back(datagramsOf(f));
    return frames;
  }

  // The input variable whose ENI name is "<slave>.<...>.<entry>".
  static std::string eniVariable(const EniConfig& eni, bool output, const std::string& slave,
                                 const std::string& entry) {
    for (const auto& v : output ? eni.processImage.outputs : eni.processImage.inputs) {
      if (v.name.rfind(slave + ".", 0) == 0 && v.name.size() > entry.size() &&
          v.name.compare(v.name.size() - entry.size(), entry.size(), entry) == 0) {
        return v.name;
      }
    }
    ADD_FAILURE() << "no ENI variable " << slave << ".*" << entry;
    return {};
  }

  // Drive1's statusword and DO1's output 3 through their ENI names: the one equals what the
  // drive's dictionary says (0x6041 by SDO), the other reaches DO1's output SM.
  void checkVariablesByEniName() {
    const std::string statusName = eniVariable(loaded(), false, "Drive1", ".Statusword");
    auto statusword = master_->variable(statusName);
    ASSERT_TRUE(statusword.ok()) << statusword.error().message();
    ASSERT_TRUE(master_->exchange().ok());
    auto sdo = master_->sdoUpload(kDrive, 0x6041, 0);
    ASSERT_TRUE(sdo.ok()) << sdo.error().message();
    EXPECT_NE(readLe16(*sdo, 0), 0u);
    EXPECT_EQ(statusword->get<std::uint16_t>(), readLe16(*sdo, 0)) << statusName;
    // The same bits as the master's own name for the entry; Drive2's are its own.
    auto own = master_->variable("Drive1.Statusword");
    ASSERT_TRUE(own.ok());
    EXPECT_EQ(own->info().bitOffset, statusword->info().bitOffset);
    auto other = master_->variable(eniVariable(loaded(), false, "Drive2", ".Statusword"));
    ASSERT_TRUE(other.ok()) << other.error().message();
    auto ownOther = master_->variable("Drive2.Statusword");
    ASSERT_TRUE(ownOther.ok());
    EXPECT_EQ(other->info().bitOffset, ownOther->info().bitOffset);
    EXPECT_NE(other->info().bitOffset, statusword->info().bitOffset);

    const std::string outName = eniVariable(loaded(), true, "DO1", ".Output 3");
    auto out3 = master_->variable(outName);
    ASSERT_TRUE(out3.ok()) << out3.error().message();
    out3->set(true);
    ASSERT_TRUE(master_->exchange().ok());
    ASSERT_TRUE(master_->exchange().ok());
    ConstBytes outputs = sim(kDo).esc().pdiOutputs(0);
    ASSERT_FALSE(outputs.empty());
    EXPECT_EQ(outputs[0], 0x04) << outName;
  }
  slavesim::Slave& sim(std::size_t i) { return net_.segment().slave(i); }

  SimNetwork net_;
  CaptureLink capture_;
  std::unique_ptr<Master> master_;
};

TEST_F(EniCyclicTest, ExportedEniIsOneLrwOverTheWholeImage) {
  EniConfig eni = exportedEni();
  ASSERT_EQ(eni.cyclic.size(), 1u);
  ASSERT_EQ(eni.cyclic[0].frames.size(), 1u);
  ASSERT_EQ(cmdsOf(eni, 0).size(), 1u);
  EXPECT_EQ(cmdsOf(eni, 0)[0].dataLength, 66u);  // 27 output + 39 input bytes
  auto status = startWith(eni);
  ASSERT_TRUE(status.ok()) << status.error().message();
  const auto frames = runCaptured(100);
  ASSERT_EQ(frames.size(), 100u);
  const std::vector<WireDatagram> want{{Command::kLrw, 0, 66}};
  for (const auto& f : frames) ASSERT_EQ(f, want) << describe(f);
}

TEST_F(EniCyclicTest, AnotherLogicalStartAddressIsWhereTheFmmusAndTheLrwGo) {
  EniConfig eni = exportedEni();
  constexpr std::uint32_t kStart = 0x00012300;
  for (auto& c : cmdsOf(eni, 0)) *c.addr += kStart;
  for (auto& s : eni.slaves) {
    for (auto& r : s.processData.send) r.bitStart += kStart * 8;
    for (auto& r : s.processData.recv) r.bitStart += kStart * 8;
  }
  for (auto& v : eni.processImage.outputs) v.bitOffs += kStart * 8;
  for (auto& v : eni.processImage.inputs) v.bitOffs += kStart * 8;
  auto status = startWith(eni);
  ASSERT_TRUE(status.ok()) << status.error().message();
  for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kOp) << i;
  EXPECT_EQ(master_->layout().logicalBase, kStart);
  // DO1's FMMU 0 maps its outputs at the ENI's <Send> BitStart.
  auto fmmu = master_->readRegisters(kDo, 0x0600, 16);
  ASSERT_TRUE(fmmu.ok()) << fmmu.error().message();
  EXPECT_EQ(readLe32(*fmmu, 0), eni.slaves[kDo].processData.send.at(0).bitStart / 8);
  EXPECT_GE(readLe32(*fmmu, 0), kStart);

  const auto frames = runCaptured(10000);
  ASSERT_EQ(frames.size(), 10000u);
  const std::vector<WireDatagram> want{{Command::kLrw, kStart, 66}};
  for (const auto& f : frames) ASSERT_EQ(f, want) << describe(f);
  EXPECT_EQ(master_->statistics().wkcErrors, 0u);
  EXPECT_EQ(master_->statistics().framesLost, 0u);
  checkVariablesByEniName();
  ASSERT_TRUE(master_->stop().ok());
  for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kInit) << i;
}

// The same network as a TwinCAT-style ENI would describe it (ETG.2100 images): the LRW at
// logical 0x01000000, process images of 1536 bytes that hold each Cmd's data at its
// OutputOffs/InputOffs (26: where the data lies in the frame), and every <Send>/<Recv> BitStart
// and variable BitOffs in those images, not at logical addresses.
TEST_F(EniCyclicTest, Etg2100ImagesMapThroughTheCmdOffsets) {
  EniConfig eni = exportedEni();
  constexpr std::uint32_t kLogical = 0x01000000;
  constexpr std::uint32_t kImageBits = 26 * 8;  // the data's place in the frame and the image
  ASSERT_EQ(cmdsOf(eni, 0).size(), 1u);
  EniCyclicCmd& lrw = cmdsOf(eni, 0)[0];
  ASSERT_EQ(*lrw.addr, 0u);
  ASSERT_EQ(lrw.inputOffs, 26u);
  ASSERT_EQ(lrw.outputOffs, 26u);
  *lrw.addr = kLogical;
  eni.processImage.outputByteSize = 1536;
  eni.processImage.inputByteSize = 1536;
  for (auto& s : eni.slaves) {
    for (auto& r : s.processData.send) r.bitStart += kImageBits;
    for (auto& r : s.processData.recv) r.bitStart += kImageBits;
  }
  for (auto& v : eni.processImage.outputs) v.bitOffs += kImageBits;
  for (auto& v : eni.processImage.inputs) v.bitOffs += kImageBits;
  auto status = startWith(eni);
  ASSERT_TRUE(status.ok()) << status.error().message();
  for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kOp) << i;
  EXPECT_EQ(master_->layout().logicalBase, kLogical);
  EXPECT_EQ(master_->layout().outputBytes, 27u);
  EXPECT_EQ(master_->layout().inputBytes, 39u);
  // DO1's outputs were at image byte 26 + 0: logical 0x01000000; DI1's inputs at 26 + 27.
  auto fmmu = master_->readRegisters(kDo, 0x0600, 16);
  ASSERT_TRUE(fmmu.ok()) << fmmu.error().message();
  EXPECT_EQ(readLe32(*fmmu, 0), kLogical);
  fmmu = master_->readRegisters(kDi, 0x0600, 16);
  ASSERT_TRUE(fmmu.ok()) << fmmu.error().message();
  EXPECT_EQ(readLe32(*fmmu, 0), kLogical + 27);
  const auto frames = runCaptured(1000);
  ASSERT_EQ(frames.size(), 1000u);
  const std::vector<WireDatagram> want{{Command::kLrw, kLogical, 66}};
  for (const auto& f : frames) ASSERT_EQ(f, want) << describe(f);
  checkVariablesByEniName();
}

// The exported single LRW becomes an LWR of the outputs in frame 0 and an LRD of the inputs in
// frame 1, followed there by a BRD of AL status that only OP sends.
EniConfig splitWithAlStatusBrd(EniConfig eni) {
  const EniCyclicCmd lrw = eni.cyclic.at(0).frames.at(0).cmds.at(0);
  const std::uint32_t outputs = *eni.processImage.outputByteSize;
  const std::uint32_t inputs = *eni.processImage.inputByteSize;
  EniCyclicCmd lwr = lrw;
  lwr.cmd = static_cast<std::uint8_t>(Command::kLwr);
  lwr.dataLength = static_cast<std::uint16_t>(outputs);
  lwr.cnt = 3;  // DO1, Drive1, Drive2 written: 1 each
  lwr.inputOffs.reset();
  lwr.outputOffs = 26;
  EniCyclicCmd lrd = lrw;
  lrd.cmd = static_cast<std::uint8_t>(Command::kLrd);
  *lrd.addr += outputs;
  lrd.dataLength = static_cast<std::uint16_t>(inputs);
  lrd.cnt = 4;  // DI1, AI1, Drive1, Drive2 read
  lrd.inputOffs = 26;
  lrd.outputOffs.reset();
  EniCyclicCmd brd;
  brd.state = "OP";
  brd.cmd = static_cast<std::uint8_t>(Command::kBrd);
  brd.adp = 0;
  brd.ado = 0x0130;
  brd.dataLength = 2;
  brd.cnt = 6;
  eni.cyclic[0].frames.assign(2, {});
  eni.cyclic[0].frames[0].cmds = {lwr};
  eni.cyclic[0].frames[1].cmds = {lrd, brd};
  return eni;
}

TEST_F(EniCyclicTest, TwoFramesWithAnLwrAnLrdAndABrdOfAlStatusInOp) {
  EniConfig eni = splitWithAlStatusBrd(exportedEni());
  capture_.capturing = true;  // from the start: the BRD must wait for OP
  auto status = startWith(eni);
  capture_.capturing = false;
  ASSERT_TRUE(status.ok()) << status.error().message();
  for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kOp) << i;

  const WireDatagram lwr{Command::kLwr, 0, 27};
  const WireDatagram lrd{Command::kLrd, 27, 39};
  const WireDatagram brd{Command::kBrd, DatagramHeader::physical(0, 0x0130), 2};
  // While start() cycled in SAFEOP the input frame went without the BRD; with it once in OP.
  std::size_t without = 0;
  std::size_t with = 0;
  for (const auto& f : capture_.sent) {
    const auto d = datagramsOf(f);
    if (d.empty() || d[0] != lrd) continue;
    if (d.size() == 1) {
      EXPECT_EQ(with, 0u) << "an input frame without the BRD after one with it";
      ++without;
    } else {
      EXPECT_EQ(d, (std::vector<WireDatagram>{lrd, brd})) << describe(d);
      ++with;
    }
  }
  EXPECT_GT(without, 0u);

  const auto frames = runCaptured(10000);
  ASSERT_EQ(frames.size(), 20000u);
  for (std::size_t k = 0; k < frames.size(); k += 2) {
    ASSERT_EQ(frames[k], std::vector<WireDatagram>{lwr}) << k << ": " << describe(frames[k]);
    ASSERT_EQ(frames[k + 1], (std::vector<WireDatagram>{lrd, brd}))
        << k + 1 << ": " << describe(frames[k + 1]);
  }
  EXPECT_EQ(master_->statistics().wkcErrors, 0u);
  EXPECT_EQ(master_->statistics().framesLost, 0u);
  checkVariablesByEniName();

  // AI1 loses its configuration: the LRD comes back one short and the error names the LRD's
  // ENI line and the slaves whose inputs it reads; the LWR and the BRD are still right.
  sim(kAi).esc().powerOnReset();
  auto cycle = master_->exchange();
  ASSERT_FALSE(cycle.ok());
  EXPECT_EQ(cycle.error().code, ErrorCode::kWorkingCounter);
  const std::string& text = cycle.error().context;
  const int line = loaded().cyclic[0].frames[1].cmds[0].line;
  EXPECT_NE(text.find("LRD 0x0000001B+39 (ENI line " + std::to_string(line) +
                      "): working counter 3, expected 4"),
            std::string::npos)
      << text;
  for (std::size_t i : {kDi, kAi, kDrive, kDrive2}) {
    EXPECT_NE(text.find(master_->slaves()[i].label()), std::string::npos) << i << ": " << text;
  }
  EXPECT_EQ(text.find(master_->slaves()[kDo].label()), std::string::npos) << text;
  EXPECT_EQ(master_->lastCycle().wkcErrors, 1u);
}

// A slave that disappears takes its own share out of each Cmd's working counter: 1 from the
// LWR (it was written), 1 from the LRD (it was read), 1 from the BRD; the others keep running
// clean, and the master exports the Cmds it runs, not LRWs.
TEST_F(EniCyclicTest, ALostSlaveTakesItsShareOutOfEachCmdAndTheExportKeepsTheCmds) {
  ASSERT_TRUE(startWith(splitWithAlStatusBrd(exportedEni())).ok());
  for (int c = 0; c < 100; ++c) ASSERT_TRUE(master_->cycle().ok()) << c;
  net_.segment().setLinkUp(kDrive, 1, false);  // Drive2, last in the line, is cut off
  bool lost = false;
  for (int c = 0; c < 300 && !lost; ++c) {
    (void)master_->cycle();
    lost = master_->health().slaves[kDrive2].condition == master::SlaveCondition::kLost;
  }
  ASSERT_TRUE(lost);
  const std::uint64_t errorsBefore = master_->statistics().wkcErrors;
  for (int c = 0; c < 1000; ++c) {
    auto s = master_->cycle();
    ASSERT_TRUE(s.ok()) << c << ": " << s.error().message();
  }
  EXPECT_EQ(master_->statistics().wkcErrors, errorsBefore);

  const EniConfig exported = master::eniFromMaster(*master_);
  ASSERT_EQ(exported.cyclic.size(), 1u);
  ASSERT_EQ(exported.cyclic[0].frames.size(), 2u);
  const auto& f0 = exported.cyclic[0].frames[0].cmds;
  const auto& f1 = exported.cyclic[0].frames[1].cmds;
  ASSERT_EQ(f0.size(), 1u);
  ASSERT_EQ(f1.size(), 2u);
  EXPECT_EQ(f0[0].cmd, static_cast<std::uint8_t>(Command::kLwr));
  EXPECT_EQ(f0[0].cnt, std::optional<std::uint16_t>(3));
  EXPECT_EQ(f1[0].cmd, static_cast<std::uint8_t>(Command::kLrd));
  EXPECT_EQ(f1[0].cnt, std::optional<std::uint16_t>(4));
  EXPECT_EQ(f1[1].cmd, static_cast<std::uint8_t>(Command::kBrd));
  EXPECT_EQ(f1[1].state, "OP");
  EXPECT_FALSE(f1[1].addr.has_value());
  EXPECT_EQ(f1[1].adp, std::optional<std::uint16_t>(0));
  EXPECT_EQ(f1[1].ado, std::optional<std::uint16_t>(0x0130));
  EXPECT_EQ(f1[1].cnt, std::optional<std::uint16_t>(6));
}

// ---- errors in the ENI: each names the file and the Cmd's line --------------------------------

class EniCyclicErrorTest : public EniCyclicTest {
 protected:
  // Starts with `eni`; expects an error naming bad-eni.xml and the line of cmds[frame][cmd].
  void expectError(const EniConfig& eni, std::size_t frame, std::size_t cmd,
                   const std::string& text) {
    auto status = startWith(eni, "bad-eni.xml");
    ASSERT_FALSE(status.ok());
    const int line = loaded().cyclic.at(0).frames.at(frame).cmds.at(cmd).line;
    ASSERT_GT(line, 0);
    const std::string& context = status.error().context;
    EXPECT_NE(context.find("bad-eni.xml line " + std::to_string(line) + ": "), std::string::npos)
        << context;
    EXPECT_NE(context.find(text), std::string::npos) << context;
    // Nothing cyclic was sent: the slaves stayed in PREOP.
    for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kPreOp) << i;
  }
};

TEST_F(EniCyclicErrorTest, ACommandTheMasterCannotSend) {
  EniConfig eni = exportedEni();
  cmdsOf(eni, 0)[0].cmd = 15;
  expectError(eni, 0, 0, "cyclic Cmd 15 is no EtherCAT command the master can send");
}

TEST_F(EniCyclicErrorTest, DataLengthBeyondTheFrame) {
  EniConfig eni = splitWithAlStatusBrd(exportedEni());
  cmdsOf(eni, 1)[1].dataLength = 1450;  // after the 39-byte LRD: 51 + 1462 > 1498
  expectError(eni, 1, 1, "DataLength 1450 does not fit in frame 1 (51 of 1498 bytes");
}

TEST_F(EniCyclicErrorTest, LogicalDataOutsideTheImage) {
  EniConfig eni = exportedEni();
  *cmdsOf(eni, 0)[0].addr += 4;
  expectError(eni, 0, 0,
              "LRW 0x00000004+66 reaches outside the process image (logical 0x00000000 to "
              "0x00000042)");
}

TEST_F(EniCyclicErrorTest, AnInputOffsetNeitherInTheFrameNorInTheImage) {
  EniConfig eni = exportedEni();
  cmdsOf(eni, 0)[0].inputOffs = 30;
  expectError(eni, 0, 0,
              "InputOffs 30 is neither the data's offset in the frame (26) nor, with DataLength "
              "66, inside the 39-byte process image");
}

TEST_F(EniCyclicErrorTest, AnLrwWorkingCounterThatCannotBeRight) {
  EniConfig eni = exportedEni();
  cmdsOf(eni, 0)[0].cnt = 11;
  expectError(eni, 0, 0, "Cnt 11 cannot be right: the slaves mapped there give 10");
}

TEST_F(EniCyclicErrorTest, ABrdWorkingCounterAboveTheSlaveCount) {
  EniConfig eni = splitWithAlStatusBrd(exportedEni());
  cmdsOf(eni, 1)[1].cnt = 7;
  expectError(eni, 1, 1, "Cnt 7 cannot be right: the slaves it addresses can add at most 6");
}

TEST_F(EniCyclicErrorTest, AStateTheMasterDoesNotKnow) {
  EniConfig eni = splitWithAlStatusBrd(exportedEni());
  cmdsOf(eni, 1)[1].state = "OP RUN";
  expectError(eni, 1, 1, "cyclic Cmd <State> 'RUN' is not INIT, PREOP, SAFEOP, OP or BOOT");
}

}  // namespace
}  // namespace ecsim::testing
