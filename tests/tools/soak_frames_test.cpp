// ecsim-soak's frames and answer checks, without a network: the same seed gives the same
// frames, every malformed frame is one no parser may accept, and the checks accept the
// answers of an in-process segment of ET1100s while catching a wrong WKC or data byte.
#include <gtest/gtest.h>

#include <memory>

#include "slavesim/generic_slave.hpp"
#include "tools/ecsim-soak/frames.hpp"
#include "topology/segment.hpp"

namespace ecsim::soak {
namespace {

constexpr Network kFour{4, 0x11};

TEST(SoakFrames, SameSeedSameFrames) {
  FrameSource a(7, kFour, 20);
  FrameSource b(7, kFour, 20);
  FrameSource c(8, kFour, 20);
  SoakFrame fa, fb, fc;
  int differentSeedDiffers = 0;
  for (int i = 0; i < 1000; ++i) {
    a.next(fa);
    b.next(fb);
    c.next(fc);
    ASSERT_EQ(fa.length, fb.length) << "frame " << i;
    ASSERT_TRUE(std::equal(fa.bytes.begin(), fa.bytes.begin() + static_cast<long>(fa.length),
                           fb.bytes.begin()))
        << "frame " << i;
    differentSeedDiffers += fa.length != fc.length;
  }
  EXPECT_GT(differentSeedDiffers, 500);
}

TEST(SoakFrames, MalformedFramesAreRejectedValidOnesParse) {
  FrameSource source(1, kFour, 50);
  SoakFrame f;
  std::array<int, kMalformations> seen{};
  for (int i = 0; i < 20000; ++i) {
    source.next(f);
    ++seen[static_cast<std::size_t>(f.malformation)];
    auto parsed = ConstEtherCatFrame::parse(ConstBytes(f.bytes.data(), f.length));
    if (f.malformation == Malformation::kNone) {
      ASSERT_TRUE(parsed.ok()) << "valid frame " << f.sequence << ": " << parsed.error().message();
      EXPECT_LE(f.length, kMaxFrameSize);
      EXPECT_GE(f.opCount, 1u);
    } else if (f.malformation == Malformation::kOversized) {
      EXPECT_GT(f.length, kMaxFrameSize);
    } else {
      EXPECT_FALSE(parsed.ok()) << toString(f.malformation) << " frame " << f.sequence
                                << " parses";
    }
  }
  for (std::size_t k = 0; k < kMalformations; ++k) {
    EXPECT_GT(seen[k], 500) << toString(static_cast<Malformation>(k));
  }
}

class SoakAgainstSegment : public ::testing::Test {
 protected:
  void SetUp() override {
    for (unsigned i = 0; i < kFour.slaves; ++i) {
      seg_.addSlave(slavesim::makeGenericSlave("Slave" + std::to_string(i + 1), i + 1));
    }
    seg_.wireLine();
    SoakFrame f;
    for (std::uint16_t p = 0; p < kFour.slaves; ++p) {
      stationAddressFrame(f, p);
      ASSERT_TRUE(pass(f).what.empty()) << pass(f).what;
      fmmuFrame(f, p);
      ASSERT_TRUE(pass(f).what.empty()) << pass(f).what;
    }
  }
  // The frame through the segment, then checked.
  CheckResult pass(const SoakFrame& f, std::size_t corruptAt = 0) {
    SoakFrame answer = f;
    seg_.processFrame(Bytes(answer.bytes.data(), answer.length), now_);
    seg_.pollSlaves(now_);
    now_ += 100000;
    if (corruptAt != 0) answer.bytes[corruptAt] ^= 0x01;
    return checkAnswer(f, ConstBytes(answer.bytes.data(), answer.length), kFour);
  }

  topology::Segment seg_;
  SimTime now_{0};
};

TEST_F(SoakAgainstSegment, EveryValidFrameChecksOut) {
  FrameSource source(11, kFour, 0);
  SoakFrame f;
  for (int i = 0; i < 3000; ++i) {
    source.next(f);
    const CheckResult r = pass(f);
    ASSERT_FALSE(r.wkcError || r.dataError) << "frame " << f.sequence << ": " << r.what;
  }
}

TEST_F(SoakAgainstSegment, WrongWkcAndWrongDataAreCaught) {
  FrameSource source(12, kFour, 0);
  SoakFrame f;
  source.single(f, OpKind::kWriteRead, 2);
  // The FPRD's WKC is the last 2 bytes before padding; its data the bytes before it.
  const std::size_t end = kEthernetHeaderSize + kEtherCatHeaderSize;
  auto parsed = ConstEtherCatFrame::parse(ConstBytes(f.bytes.data(), f.length));
  ASSERT_TRUE(parsed.ok());
  auto it = parsed->begin();
  ++it;
  const std::size_t readAt = end + it.offset();
  const std::size_t wkcAt = readAt + kDatagramHeaderSize + (*it).length();
  const CheckResult wkc = pass(f, wkcAt);
  EXPECT_TRUE(wkc.wkcError) << wkc.what;
  EXPECT_NE(wkc.what.find("WKC 0, expected 1"), std::string::npos) << wkc.what;
  const CheckResult data = pass(f, readAt + kDatagramHeaderSize);
  EXPECT_TRUE(data.dataError) << data.what;
  EXPECT_NE(data.what.find("data byte 0"), std::string::npos) << data.what;
  EXPECT_FALSE(pass(f).dataError);
  // An answer nobody touched (the frame came back as sent): every WKC is wrong.
  source.single(f, OpKind::kTypeRead, 0);
  EXPECT_TRUE(checkAnswer(f, ConstBytes(f.bytes.data(), f.length), kFour).dataError ||
              checkAnswer(f, ConstBytes(f.bytes.data(), f.length), kFour).wkcError);
}

}  // namespace
}  // namespace ecsim::soak
