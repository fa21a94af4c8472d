// IO terminals: input scripts (constant, square, sine, ramp, CSV table and their text form),
// the ECS1008 digital inputs, the ECS2008 digital outputs (getter, observer, log) and the
// ECS3102 analog inputs (scaling, status bits, filter), through their dictionaries and, for
// each device, through frames (examples/README.md gives the process-data layouts).
#include "slavesim/devices/io_terminals.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "slavesim/devices/device_models.hpp"
#include "support/fifo.hpp"
#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

constexpr std::uint32_t kEcs1008 = 0x00001008;
constexpr std::uint32_t kEcs2008 = 0x00002008;
constexpr std::uint32_t kEcs3102 = 0x00003102;

SimTime ms(double v) {
  return static_cast<SimTime>(v * kNsPerMs);
}

// ---- signals ------------------------------------------------------------------------------------

TEST(Signal, ShapesAsFunctionsOfTime) {
  const auto c = dev::Signal::constant(2.5);
  EXPECT_EQ(c.value(0), 2.5);
  EXPECT_EQ(c.value(ms(12345)), 2.5);

  const auto sq = dev::Signal::square(0.1, -1.0, 3.0, 0.25, 0.01);  // 100 ms, high 25 ms
  EXPECT_EQ(sq.value(ms(5)), -1.0) << "before the first period starts at 10 ms: the previous one";
  EXPECT_EQ(sq.value(ms(10)), 3.0);
  EXPECT_EQ(sq.value(ms(34)), 3.0);
  EXPECT_EQ(sq.value(ms(36)), -1.0);
  EXPECT_EQ(sq.value(ms(110)), 3.0);

  const auto s = dev::Signal::sine(2.0, 5.0, 1.0);
  EXPECT_NEAR(s.value(0), 1.0, 1e-12);
  EXPECT_NEAR(s.value(ms(50)), 3.0, 1e-12) << "a quarter period of 5 Hz";
  EXPECT_NEAR(s.value(ms(150)), -1.0, 1e-12);

  const auto r = dev::Signal::ramp(-1.0, 10.0, -5.0, 4.0);
  EXPECT_NEAR(r.value(ms(100)), 0.0, 1e-12);
  EXPECT_EQ(r.value(ms(1000)), 4.0) << "clamped";
  const auto saw = dev::Signal::ramp(0.0, 1.0, -1e9, 1e9, 0.5);
  EXPECT_NEAR(saw.value(ms(400)), 0.4, 1e-12);
  EXPECT_NEAR(saw.value(ms(600)), 0.1, 1e-12) << "restarts every period";
}

TEST(Signal, TablesInterpolateStepAndLoop) {
  const std::vector<dev::Signal::Point> points = {{0.0, 0.0}, {1.0, 10.0}, {2.0, 0.0}};
  const auto lin = dev::Signal::table(points);
  EXPECT_NEAR(lin.value(ms(250)), 2.5, 1e-12);
  EXPECT_NEAR(lin.value(ms(1500)), 5.0, 1e-12);
  EXPECT_EQ(lin.value(ms(5000)), 0.0) << "held after the end";
  const auto step = dev::Signal::table(points, false, true);
  EXPECT_EQ(step.value(ms(999)), 0.0);
  EXPECT_EQ(step.value(ms(1000)), 10.0);
  const auto loop = dev::Signal::table(points, true);
  EXPECT_NEAR(loop.value(ms(2250)), 2.5, 1e-9) << "repeats with period 2 s";
}

class SignalFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-io-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  std::filesystem::path dir_;
};

TEST_F(SignalFiles, CsvWithHeaderAndComments) {
  write("trace.csv", "time_s,volts\n# a comment\n0,0\n\n0.5;1.0\n1.0, 4\n");
  auto s = dev::Signal::fromCsv(dir_ / "trace.csv");
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_EQ(s->points().size(), 3u);
  EXPECT_NEAR(s->value(ms(750)), 2.5, 1e-12);
  write("bad.csv", "0,1\n1,2\nx,3\n");
  auto bad = dev::Signal::fromCsv(dir_ / "bad.csv");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().context.find("bad.csv:3"), std::string::npos) << bad.error().context;
  write("back.csv", "0,1\n2,2\n1,3\n");
  auto back = dev::Signal::fromCsv(dir_ / "back.csv");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().context.find("back.csv:3: time goes backwards"), std::string::npos);
  EXPECT_EQ(dev::Signal::fromCsv(dir_ / "none.csv").error().code, ErrorCode::kNotFound);
}

// `ecsim ctl input ... signal="csv file=PATH"` is read by the single serve loop: a FIFO there
// must be refused at once, not wait for a writer (and a device must not be read without end).
TEST_F(SignalFiles, CsvThatIsAFifoOrADeviceIsRefusedWithoutBlocking) {
  const auto fifo = dir_ / "trace.csv";
  ASSERT_TRUE(ecsim::testing::makeFifo(fifo));
  auto s = ecsim::testing::readWithoutHanging(
      fifo, [&] { return dev::parseSignal("csv file=" + fifo.string()); });
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().context, fifo.string() + ": is a FIFO, not a regular file");
  auto zero = dev::parseSignal("csv file=/dev/zero");
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.error().context, "/dev/zero: is a character device, not a regular file");
}

TEST_F(SignalFiles, TextForms) {
  write("t.csv", "0,0\n1,1\n");
  struct Case {
    const char* text;
    SimTime at;
    double value;
  };
  const Case cases[] = {
      {"1.5", 0, 1.5},
      {"constant value=-2", ms(7), -2.0},
      {"square period=0.2 low=0 high=1 duty=0.5", ms(50), 1.0},
      {"square period=0.2 low=0 high=1 duty=0.5", ms(150), 0.0},
      {"sine amplitude=5 frequency=1", ms(250), 5.0},
      {"ramp start=1 slope=2 max=2", ms(2000), 2.0},
      {"csv file=t.csv", ms(500), 0.5},
      {"csv file=t.csv step=1", ms(500), 0.0},
  };
  for (const Case& c : cases) {
    auto s = dev::parseSignal(c.text, dir_);
    ASSERT_TRUE(s.ok()) << c.text << ": " << s.error().message();
    EXPECT_NEAR(s->value(c.at), c.value, 1e-9) << c.text;
  }
  for (const char* bad : {"wobble period=1", "sine amplitude", "sine amplitude=x",
                          "square period=0", "ramp min=3 max=1", "sine colour=red", "csv"}) {
    auto s = dev::parseSignal(bad, dir_);
    EXPECT_FALSE(s.ok()) << bad;
    if (!s.ok()) {
      EXPECT_EQ(s.error().code, ErrorCode::kParse) << bad;
    }
  }
}

// ---- digital inputs ----------------------------------------------------------------------------

TEST(DigitalInputs, ScriptsDriveTheirChannelsOthersKeepTheirValue) {
  auto slave = makeExampleSlave(kEcs1008);
  ASSERT_NE(slave, nullptr);
  dev::DigitalInputTerminal* di = dev::digitalInputsOf(*slave);
  ASSERT_NE(di, nullptr);
  EXPECT_EQ(di->channels(), 8u);
  auto* od = slavesim::objectDictionaryOf(*slave);
  ASSERT_TRUE(od->set<bool>(0x6000, 8, true).ok());   // as a topology <Input> sets it
  di->setScript(1, dev::Signal::square(0.01, 0, 1));  // 10 ms period
  di->setInput(3, true);
  di->step(*od, AlState::kOp, ms(2));
  EXPECT_TRUE(di->input(1));
  EXPECT_FALSE(di->input(2));
  EXPECT_TRUE(di->input(3));
  EXPECT_TRUE(di->input(8)) << "unscripted: untouched";
  di->step(*od, AlState::kOp, ms(7));
  EXPECT_FALSE(di->input(1));
  di->clearScript(3);
  ASSERT_TRUE(od->set<bool>(0x6000, 3, false).ok());
  di->step(*od, AlState::kOp, ms(8));
  EXPECT_FALSE(di->input(3));
}

TEST(DigitalInputs, ThroughFramesTheByteFollowsTheScripts) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs1008));
  dev::DigitalInputTerminal* di = dev::digitalInputsOf(seg.slave(0));
  ASSERT_NE(di, nullptr);
  for (unsigned c = 1; c <= 8; ++c) {
    // Channel c: a square wave of period 2^c ms, high in the second half, so the byte counts
    // milliseconds in binary (edges half a millisecond before the samples).
    const double period = std::ldexp(1e-3, static_cast<int>(c));
    di->setScript(c, dev::Signal::square(period, 0, 1, 0.5, period / 2 - 0.5e-3));
  }
  OpSlave op = bringToOp(seg, {{0, false, 1}});
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  for (int k = 0; k < 300; ++k) {
    x.cycle();
    ASSERT_EQ(x.wkc, 1);
    EXPECT_EQ(x.in8(0), static_cast<std::uint8_t>(x.now / kNsPerMs)) << "at " << x.now;
  }
}

// ---- digital outputs
// -----------------------------------------------------------------------------

TEST(DigitalOutputs, ThroughFramesWithObserverAndLog) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs2008));
  dev::DigitalOutputTerminal* dout = dev::digitalOutputsOf(seg.slave(0));
  ASSERT_NE(dout, nullptr);
  dout->enableLog(3);
  std::vector<std::pair<SimTime, std::uint32_t>> seen;
  dout->setObserver([&](SimTime t, std::uint32_t v) { seen.emplace_back(t, v); });
  OpSlave op = bringToOp(seg, {{0, true, 1}});
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  x.put8(0, 0xA5);
  x.cycle();
  EXPECT_EQ(x.wkc, 2);
  EXPECT_EQ(dout->outputs(), 0xA5u);
  EXPECT_TRUE(dout->output(1));
  EXPECT_FALSE(dout->output(2));
  EXPECT_TRUE(dout->output(8));
  x.cycle();
  x.put8(0, 0x0F);
  x.cycle();
  x.put8(0, 0xF0);
  x.cycle();
  x.put8(0, 0x01);
  x.cycle();
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[0], (std::pair<SimTime, std::uint32_t>{ms(1), 0xA5}));
  EXPECT_EQ(seen[1], (std::pair<SimTime, std::uint32_t>{ms(3), 0x0F}));
  EXPECT_EQ(seen[3].second, 0x01u);
  ASSERT_EQ(dout->log().size(), 3u) << "the log keeps its capacity";
  EXPECT_EQ(dout->log()[2].outputs, 0xF0u);
  // Leaving OP: the outputs go to their safe state.
  one(seg, Command::kFpwr, phys(kStation, reg::kAlControl.address), le16(0x0004), ms(10));
  EXPECT_EQ(dout->outputs(), 0u);
  EXPECT_EQ(seen.back(), (std::pair<SimTime, std::uint32_t>{ms(10), 0}));
  const auto csv = std::filesystem::temp_directory_path() /
                   ("ecsim-do-log-" + std::to_string(::getpid()) + ".csv");
  ASSERT_TRUE(dout->writeLogCsv(csv).ok());
  std::ifstream in(csv);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(),
            "time_ns,outputs,out1,out2,out3,out4,out5,out6,out7,out8\n"
            "1000000,165,1,0,1,0,0,1,0,1\n"
            "3000000,15,1,1,1,1,0,0,0,0\n"
            "4000000,240,0,0,0,0,1,1,1,1\n");
  std::filesystem::remove(csv);
}

// ---- analog inputs -----------------------------------------------------------------------------

struct AnalogBench {
  std::unique_ptr<slavesim::Slave> slave = makeExampleSlave(kEcs3102);
  slavesim::coe::ObjectDictionary* od = slavesim::objectDictionaryOf(*slave);
  dev::AnalogInputTerminal* ai = dev::analogInputsOf(*slave);
  SimTime now{0};
  // Steps every millisecond until the absolute time `until`.
  void run(SimTime until) {
    while (now < until) {
      now += kNsPerMs;
      ai->step(*od, AlState::kOp, now);
    }
  }
  std::int16_t value(unsigned ch) const {
    return od->get<std::int16_t>(static_cast<std::uint16_t>(0x6000 + 0x10 * (ch - 1)), 0x11)
        .value();
  }
  std::uint16_t status(unsigned ch) const {
    return od->get<std::uint16_t>(static_cast<std::uint16_t>(0x6000 + 0x10 * (ch - 1)), 0x01)
        .value();
  }
};

TEST(AnalogInputs, ScalingAndRangeBits) {
  AnalogBench b;
  ASSERT_NE(b.ai, nullptr);
  struct Case {
    double volts;
    std::int16_t raw;
    std::uint16_t bits;  // status without the toggle bit
  };
  const Case cases[] = {{0.0, 0, 0},           {5.0, 16384, 0},    {-5.0, -16384, 0},
                        {10.0, 32767, 0},      {-10.0, -32767, 0}, {10.5, 32767, 0x42},
                        {-11.0, -32768, 0x41}, {2.5e-4, 1, 0}};
  for (const Case& c : cases) {
    b.ai->setScript(1, dev::Signal::constant(c.volts));
    b.run(b.now + 2 * kNsPerMs);
    EXPECT_EQ(b.value(1), c.raw) << c.volts << " V";
    EXPECT_EQ(b.status(1) & 0x7FFF, c.bits) << c.volts << " V";
  }
  EXPECT_EQ(b.value(2), 0) << "channel 2 has no script";
  EXPECT_EQ(b.status(2), 0);
}

TEST(AnalogInputs, ToggleBitFlipsWithEachConversion) {
  AnalogBench b;
  b.ai->setScript(2, dev::Signal::constant(1.0));
  b.run(kNsPerMs);
  const bool first = (b.status(2) & 0x8000) != 0;
  b.run(2 * kNsPerMs);
  EXPECT_NE((b.status(2) & 0x8000) != 0, first);
  b.run(4 * kNsPerMs);  // two more conversions
  EXPECT_NE((b.status(2) & 0x8000) != 0, first);
}

TEST(AnalogInputs, LimitsCompareTheRawValue) {
  AnalogBench b;
  ASSERT_TRUE(b.od->set<bool>(0x8000, 0x02, true).ok());
  ASSERT_TRUE(b.od->set<bool>(0x8000, 0x03, true).ok());
  ASSERT_TRUE(b.od->set<std::int16_t>(0x8000, 0x11, 1000).ok());
  ASSERT_TRUE(b.od->set<std::int16_t>(0x8000, 0x12, 16384).ok());
  const std::pair<double, std::uint16_t> cases[] = {
      {0.0, (2u << 2) | (2u << 4)},   // below both
      {1.0, (1u << 2) | (2u << 4)},   // 3277: above limit 1, below limit 2
      {5.0, (1u << 2) | (3u << 4)},   // 16384: equal to limit 2
      {9.0, (1u << 2) | (1u << 4)}};  // above both
  for (const auto& [volts, bits] : cases) {
    b.ai->setScript(1, dev::Signal::constant(volts));
    b.run(b.now + 2 * kNsPerMs);
    EXPECT_EQ(b.status(1) & 0x3C, bits) << volts << " V";
  }
}

TEST(AnalogInputs, FilterIsAFirstOrderLag) {
  AnalogBench b;
  ASSERT_TRUE(b.od->set<bool>(0x8010, 0x01, true).ok());
  ASSERT_TRUE(b.od->set<std::uint16_t>(0x8010, 0x13, 20).ok());  // 20 ms
  b.ai->setScript(2, dev::Signal::constant(0.0));
  b.run(5 * kNsPerMs);
  b.ai->setScript(2, dev::Signal::square(1.0, 0.0, 8.0, 0.5, 0.005));  // 8 V from 5 ms on
  b.run(25 * kNsPerMs);
  // 20 ms after the step (conversions at 1 ms, the step taken at 5 ms): 1 - e^-1.
  EXPECT_NEAR(b.ai->volts(2), 8.0 * (1.0 - std::exp(-1.0)), 0.05 * 8.0);
  b.run(400 * kNsPerMs);  // run() takes the absolute end time
  EXPECT_NEAR(b.ai->volts(2), 8.0, 1e-4);
  EXPECT_EQ(b.value(2), b.ai->rawValue(8.0));
}

TEST(AnalogInputs, ThroughFramesBothChannels) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs3102));
  dev::AnalogInputTerminal* ai = dev::analogInputsOf(seg.slave(0));
  ASSERT_NE(ai, nullptr);
  ai->setScript(1, dev::Signal::sine(10.0, 2.0));  // +-10 V at 2 Hz
  ai->setScript(2, dev::Signal::ramp(-10.0, 20.0, -10.0, 10.0));
  OpSlave op = bringToOp(seg, {{3, false, 8}});
  ASSERT_EQ(op.inBytes, 8);
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  for (int k = 0; k < 400; ++k) {
    x.cycle();
    ASSERT_EQ(x.wkc, 1);
    const double t = static_cast<double>(x.now) / kNsPerSecond;
    const double v1 = 10.0 * std::sin(2.0 * std::numbers::pi * 2.0 * t);
    const double v2 = std::clamp(-10.0 + 20.0 * t, -10.0, 10.0);
    EXPECT_NEAR(static_cast<std::int16_t>(x.in16(2)), v1 / 10.0 * 32767, 1.0) << t;
    EXPECT_NEAR(static_cast<std::int16_t>(x.in16(6)), v2 / 10.0 * 32767, 1.0) << t;
  }
}

}  // namespace
}  // namespace ecsim::testing
