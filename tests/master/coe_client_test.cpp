// Mailbox and CoE client against simulated CoE slaves built from ecsim's own ESI file
// (examples/esi/ecsim_devices.xml: ECS3102 analog input, ECS7201 drive) with the simulator's
// CoE server: SDO upload/download expedited, normal and segmented, complete access, aborts
// decoded to text, SDO information (fragmented OD list), emergencies, lost responses
// recovered by the mailbox repeat request, the mailbox counter.
#include "master/coe_client.hpp"

#include <gtest/gtest.h>

#include "slavesim/coe/standard_objects.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::SdoInfoTask;
using master::SdoTask;

constexpr std::uint16_t kLongText = 0x2100;  // added to the dictionary by the test

class CoeClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    net_.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
    net_.segment().addSlave(makeDemoSlave(0x7201, "Drive1"));
    // A slave of ours whose server offers complete access (the demo devices do not).
    auto od = std::make_shared<slavesim::coe::ObjectDictionary>();
    slavesim::coe::addIdentityObject(*od, {kTestVendor, 0xCA, 1, 2});
    net_.segment().addSlave(makeCoeSlave("Ca", 0xCA, od));
    net_.segment().wireLine();
    od_ = slavesim::objectDictionaryOf(net_.segment().slave(0));
    ASSERT_NE(od_, nullptr);
    od_->addString(kLongText, "Long text", std::string(300, 'x'),
                   slavesim::coe::access::kReadWrite);
    net_.start();
    auto status = scanAndPreOp(net_, transport_, slaves_);
    ASSERT_TRUE(status.ok()) << status.error().message();
  }
  SimTime now() { return net_.clock().now(); }

  Status run(master::Task& task) {
    return master::runTask(task, transport_, net_.bus(), 5 * kNsPerSecond);
  }
  Status upload(std::size_t position, std::uint16_t index, std::uint8_t sub, bool ca,
                std::vector<std::uint8_t>& out, SdoTask** keep = nullptr) {
    sdo_ = std::make_unique<SdoTask>(transport_, slaves_[position], &emergencies_);
    ECSIM_TRY(sdo_->startUpload(index, sub, ca, now()));
    ECSIM_TRY(run(*sdo_));
    out = sdo_->data();
    if (keep != nullptr) *keep = sdo_.get();
    return sdo_->status();
  }
  Status download(std::size_t position, std::uint16_t index, std::uint8_t sub,
                  std::vector<std::uint8_t> data, bool ca = false) {
    sdo_ = std::make_unique<SdoTask>(transport_, slaves_[position], &emergencies_);
    ECSIM_TRY(sdo_->startDownload(index, sub, data, ca, now()));
    ECSIM_TRY(run(*sdo_));
    return sdo_->status();
  }

  SimNetwork net_;
  master::Transport transport_{net_.masterLink()};
  std::vector<master::SlaveInfo> slaves_;
  std::vector<master::ReceivedEmergency> emergencies_;
  slavesim::coe::ObjectDictionary* od_{nullptr};
  std::unique_ptr<SdoTask> sdo_;
};

TEST_F(CoeClientTest, ExpeditedUploadOfIdentity) {
  std::vector<std::uint8_t> data;
  SdoTask* task = nullptr;
  ASSERT_TRUE(upload(0, 0x1018, 1, false, data, &task).ok());
  EXPECT_TRUE(task->expedited());
  ASSERT_EQ(data.size(), 4u);
  EXPECT_EQ(readLe32(data, 0), 0x00000E5Cu);  // vendor id of examples/esi
  ASSERT_TRUE(upload(1, 0x1018, 2, false, data).ok());
  EXPECT_EQ(readLe32(data, 0), 0x00007201u);
}

TEST_F(CoeClientTest, NormalUploadOfDeviceName) {
  std::vector<std::uint8_t> data;
  SdoTask* task = nullptr;
  ASSERT_TRUE(upload(0, 0x1008, 0, false, data, &task).ok());
  EXPECT_FALSE(task->expedited());
  EXPECT_EQ(task->segments(), 0u);
  ConstBytes expected = od_->bytes(0x1008, 0);
  EXPECT_GT(expected.size(), 4u);
  EXPECT_EQ(data, std::vector<std::uint8_t>(expected.begin(), expected.end()));
}

TEST_F(CoeClientTest, SegmentedUploadAndDownloadOfALongObject) {
  std::vector<std::uint8_t> data;
  SdoTask* task = nullptr;
  ASSERT_TRUE(upload(0, kLongText, 0, false, data, &task).ok());
  EXPECT_EQ(data, std::vector<std::uint8_t>(300, 'x'));
  EXPECT_GT(task->segments(), 0u);

  std::vector<std::uint8_t> text(300);
  for (std::size_t i = 0; i < text.size(); ++i) text[i] = static_cast<std::uint8_t>('a' + i % 26);
  ASSERT_TRUE(download(0, kLongText, 0, text).ok());
  EXPECT_GT(sdo_->segments(), 0u);
  ConstBytes stored = od_->bytes(kLongText, 0);
  EXPECT_EQ(std::vector<std::uint8_t>(stored.begin(), stored.end()), text);
}

TEST_F(CoeClientTest, ExpeditedDownloadThenReadBack) {
  ASSERT_TRUE(download(0, 0x8000, 0x13, {250, 0}).ok());
  EXPECT_TRUE(sdo_->expedited());
  EXPECT_EQ(od_->get<std::uint16_t>(0x8000, 0x13).valueOr(0), 250);
  std::vector<std::uint8_t> data;
  ASSERT_TRUE(upload(0, 0x8000, 0x13, false, data).ok());
  EXPECT_EQ(data, (std::vector<std::uint8_t>{250, 0}));
}

TEST_F(CoeClientTest, AbortsAreDecodedToText) {
  std::vector<std::uint8_t> data;
  auto missing = upload(0, 0x5555, 0, false, data);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kAborted);
  EXPECT_EQ(sdo_->abortCode(), 0x06020000u);
  const std::string& text = missing.error().context;
  EXPECT_NE(text.find("SDO upload of 0x5555:00 from slave 0 (0x1001 "), std::string::npos) << text;
  EXPECT_NE(text.find("abort 0x06020000 (" + std::string(sdoAbortText(0x06020000)) + ")"),
            std::string::npos)
      << text;

  auto readOnly = download(0, 0x1018, 1, {1, 2, 3, 4});
  ASSERT_FALSE(readOnly.ok());
  EXPECT_EQ(sdo_->abortCode(), 0x06010002u);
  EXPECT_NE(readOnly.error().context.find(std::string(sdoAbortText(0x06010002))), std::string::npos)
      << readOnly.error().context;
}

// A slave that answers every SDO request with an abort (0x06010002 for the requested
// index:subindex) under a chosen CoE service: 2 as ETG.1000.6 and SOES send it, or 3 as some
// slaves in the field do.
class AbortingMailbox : public slavesim::MailboxServer {
 public:
  explicit AbortingMailbox(std::uint8_t service) : service_(service) {}
  void onRequest(slavesim::Esc& esc, ConstBytes mailbox, SimTime) override {
    if (mailbox.size() < 12) return;
    const std::uint8_t answer[16] = {
        0x0a, 0x00, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(0x03 | (mailbox[5] & 0x70)),
        0x00, static_cast<std::uint8_t>(service_ << 4), 0x80, mailbox[9], mailbox[10],
        mailbox[11], 0x02, 0x00, 0x01, 0x06};
    (void)esc.pdiMailboxSend(answer);
  }

 private:
  std::uint8_t service_;
};

TEST_F(CoeClientTest, AbortIsAcceptedUnderCoeServiceTwoOrThree) {
  for (std::uint8_t service : {std::uint8_t{2}, std::uint8_t{3}}) {
    net_.segment().slave(1).setMailboxServer(std::make_unique<AbortingMailbox>(service));
    auto status = download(1, 0x6040, 0, {0x0F, 0x00});
    ASSERT_FALSE(status.ok()) << "service " << int(service);
    EXPECT_EQ(status.error().code, ErrorCode::kAborted) << status.error().message();
    EXPECT_EQ(sdo_->abortCode(), 0x06010002u) << "service " << int(service);
    std::vector<std::uint8_t> data;
    status = upload(1, 0x1018, 1, false, data);
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(sdo_->abortCode(), 0x06010002u) << "service " << int(service);
    EXPECT_NE(status.error().context.find("0x1018:01"), std::string::npos)
        << status.error().context;
  }
}

TEST_F(CoeClientTest, CompleteAccessUploadOfARecord) {
  std::vector<std::uint8_t> data;
  auto status = upload(2, 0x1018, 0, true, data);
  ASSERT_TRUE(status.ok()) << status.error().message();
  // Subindex 0 then the four UDINTs: vendor, product, revision, serial.
  ASSERT_GE(data.size(), 17u);
  EXPECT_EQ(data[0], 4);
  EXPECT_EQ(readLe32(data, data.size() - 16), kTestVendor);
  EXPECT_EQ(readLe32(data, data.size() - 12), 0xCAu);
  EXPECT_EQ(readLe32(data, data.size() - 4), 2u);
  // A device without complete access aborts with 0x06010004, decoded.
  auto refused = upload(1, 0x1018, 0, true, data);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(sdo_->abortCode(), 0x06010004u);
  EXPECT_NE(refused.error().context.find("(complete)"), std::string::npos);
}

TEST_F(CoeClientTest, SdoInformationListsAndDescribes) {
  for (std::uint16_t i = 0; i < 80; ++i) {  // a long OD list: more than one mailbox
    od_->addVar(static_cast<std::uint16_t>(0x3000 + i), "Filler", 0x0007, 32,
                slavesim::coe::access::kReadOnly);
  }
  SdoInfoTask info(transport_, slaves_[0], &emergencies_);
  ASSERT_TRUE(info.startOdList(OdListType::kAll, now()).ok());
  ASSERT_TRUE(run(info).ok());
  ASSERT_TRUE(info.status().ok()) << info.status().error().message();
  EXPECT_GT(info.fragments(), 1u);
  const auto& list = std::get<OdList>(*info.response());
  EXPECT_EQ(list.indexes.size(), od_->size());
  EXPECT_NE(std::find(list.indexes.begin(), list.indexes.end(), 0x1018), list.indexes.end());
  EXPECT_NE(std::find(list.indexes.begin(), list.indexes.end(), 0x304F), list.indexes.end());

  ASSERT_TRUE(info.startObjectDescription(0x1018, now()).ok());
  ASSERT_TRUE(run(info).ok());
  const auto& object = std::get<ObjectDescription>(*info.response());
  EXPECT_EQ(object.maxSubindex, 4);
  EXPECT_EQ(object.objectCode, static_cast<std::uint8_t>(ObjectCode::kRecord));
  EXPECT_EQ(object.name, od_->find(0x1018)->name);

  ASSERT_TRUE(info.startEntryDescription(0x1018, 1, 0x07, now()).ok());
  ASSERT_TRUE(run(info).ok());
  const auto& entry = std::get<EntryDescription>(*info.response());
  EXPECT_EQ(entry.bitLength, 32);
  EXPECT_EQ(entry.dataType, 0x0007);

  ASSERT_TRUE(info.startObjectDescription(0x5555, now()).ok());
  ASSERT_TRUE(run(info).ok());
  ASSERT_FALSE(info.status().ok());
  EXPECT_EQ(info.status().error().code, ErrorCode::kAborted);
  EXPECT_NE(info.status().error().context.find("0x06020000"), std::string::npos);
}

TEST_F(CoeClientTest, EmergencyIsCollectedWhileWaitingForAResponse) {
  Emergency e;
  e.errorCode = 0x8130;
  e.errorRegister = 0x11;
  e.data = {1, 2, 3, 4, 5};
  slavesim::coeServerOf(net_.segment().slave(1))->pushEmergency(e);
  std::vector<std::uint8_t> data;
  ASSERT_TRUE(upload(1, 0x1018, 2, false, data).ok());
  EXPECT_EQ(readLe32(data, 0), 0x00007201u);
  ASSERT_EQ(emergencies_.size(), 1u);
  EXPECT_EQ(emergencies_[0].position, 1u);
  EXPECT_EQ(emergencies_[0].emergency, e);
}

TEST_F(CoeClientTest, LostResponseIsRecoveredWithRepeatRequest) {
  // Drop the first answer to a read of AI1's SM1 buffer (0x1080) that carried the response:
  // the transport resends the read, which finds SM1 empty (WKC 0): repeat request.
  const std::uint16_t inStart = slaves_[0].mailbox->inStart;
  bool dropped = false;
  net_.fault().dropReceiveIf = [&](ConstBytes frame) {
    if (dropped) return false;
    auto parsed = ConstEtherCatFrame::parse(frame);
    if (!parsed.ok()) return false;
    for (auto d : *parsed) {
      if (d.command() == Command::kFprd && d.ado() == inStart && d.wkc() == 1) {
        dropped = true;
        return true;
      }
    }
    return false;
  };
  std::vector<std::uint8_t> data;
  SdoTask* task = nullptr;
  auto status = upload(0, 0x1018, 2, false, data, &task);
  ASSERT_TRUE(status.ok()) << status.error().message();
  EXPECT_TRUE(dropped);
  EXPECT_EQ(task->repeats(), 1u);
  EXPECT_EQ(readLe32(data, 0), 0x00003102u);
}

TEST_F(CoeClientTest, MailboxCounterCyclesOneToSeven) {
  std::vector<std::uint8_t> data;
  std::vector<std::uint8_t> counters;
  const std::uint16_t outStart = slaves_[0].mailbox->outStart;
  net_.fault().dropReceiveIf = [&](ConstBytes frame) {
    auto parsed = ConstEtherCatFrame::parse(frame);
    if (!parsed.ok()) return false;
    for (auto d : *parsed) {
      if (d.command() == Command::kFpwr && d.ado() == outStart && d.adp() == 0x1001) {
        counters.push_back(static_cast<std::uint8_t>((d.data()[5] >> 4) & 0x07));
      }
    }
    return false;
  };
  for (int i = 0; i < 9; ++i) ASSERT_TRUE(upload(0, 0x1018, 1, false, data).ok());
  EXPECT_EQ(counters, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 1, 2}));
}

TEST_F(CoeClientTest, SlaveWithoutMailboxIsRefusedAtOnce) {
  master::SlaveInfo plain;
  SdoTask task(transport_, plain, nullptr);
  auto status = task.startUpload(0x1000, 0, false, now());
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kUnsupported);
}

}  // namespace
}  // namespace ecsim::testing
