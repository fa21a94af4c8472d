// Fault injection on a small line of generic slaves, through frames: corruption counted in the
// ESC error counters (0x0300 invalid frame at the receiving port, 0x0308 forwarded errors after
// it), seeded loss, link down and power cycle.
#include <gtest/gtest.h>

#include "protocol/ethernet.hpp"
#include "protocol/frame.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/control_server.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::topology {
namespace {

Network makeLine(std::size_t n) {
  Network net;
  net.segment = std::make_unique<Segment>();
  for (std::size_t i = 0; i < n; ++i) {
    net.segment->addSlave(
        slavesim::makeGenericSlave("S" + std::to_string(i), static_cast<std::uint32_t>(i)));
  }
  net.segment->wireLine();
  net.cables.push_back({"master", 0, 0});
  for (std::size_t i = 1; i < n; ++i) net.cables.push_back({"c" + std::to_string(i), i, 0});
  return net;
}

// A BRD of the type register: every slave it passes adds one to the WKC.
std::vector<std::uint8_t> brdFrame() {
  std::vector<std::uint8_t> buf(kMaxFrameSize);
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat});
  EXPECT_TRUE(b.add(Command::kBrd, 1, 0, 2).ok());
  auto len = b.finish();
  EXPECT_TRUE(len.ok());
  buf.resize(*len);
  return buf;
}

std::uint16_t firstWkc(std::vector<std::uint8_t>& frame) {
  auto parsed = EtherCatFrame::parse(frame);
  EXPECT_TRUE(parsed.ok());
  return parsed.ok() ? (*parsed->begin()).wkc() : 0;
}

Fault action(const std::string& line) {
  auto a = parseFaultLine(line);
  EXPECT_TRUE(a.ok()) << line << ": " << a.error().context;
  return a.ok() ? *a : Fault{};
}

TEST(Faults, CorruptionIsCountedAtTheReceiverAndForwardedAfterIt) {
  Network net = makeLine(4);
  FaultInjector faults(net, 1);
  ASSERT_TRUE(faults.apply(action("corrupt cable=c2 count=2"), 0).ok());
  for (int i = 0; i < 3; ++i) {
    auto frame = brdFrame();
    auto out = net.segment->processFrame(frame, static_cast<SimTime>(i) * 100000);
    EXPECT_EQ(out.delivered, i >= 2) << "frame " << i;
  }
  auto& seg = *net.segment;
  // S2 received the bad frames at port 0: invalid frame counter 0x0300.
  EXPECT_EQ(seg.slave(2).esc().reg8(0x0300), 2);
  // S3 after it: forwarded error at port 0; on the way back S2, S1, S0 at port 1.
  EXPECT_EQ(seg.slave(3).esc().reg8(0x0308), 2);
  EXPECT_EQ(seg.slave(2).esc().reg8(0x0309), 2);
  EXPECT_EQ(seg.slave(1).esc().reg8(0x0309), 2);
  EXPECT_EQ(seg.slave(0).esc().reg8(0x0309), 2);
  // Upstream of the fault nothing was wrong on the way down.
  EXPECT_EQ(seg.slave(1).esc().reg8(0x0300), 0);
  EXPECT_EQ(seg.slave(1).esc().reg8(0x0308), 0);
}

TEST(Faults, SeededLossIsRepeatable) {
  auto run = [](std::uint64_t seed) {
    Network net = makeLine(2);
    FaultInjector faults(net, seed);
    EXPECT_TRUE(faults.apply(action("loss rate=0.3"), 0).ok());
    std::string pattern;
    for (int i = 0; i < 200; ++i) {
      auto frame = brdFrame();
      pattern +=
          net.segment->processFrame(frame, static_cast<SimTime>(i) * 100000).delivered ? '1' : '0';
    }
    return pattern;
  };
  const std::string a = run(42);
  EXPECT_EQ(a, run(42));
  EXPECT_NE(a, run(43));
  const auto lost = std::count(a.begin(), a.end(), '0');
  EXPECT_GT(lost, 30);
  EXPECT_LT(lost, 90);
}

TEST(Faults, LinkDownClosesBothEndsAndCountsLostLinks) {
  Network net = makeLine(3);
  FaultInjector faults(net, 1);
  ASSERT_TRUE(faults.apply(action("link-down cable=c2"), 0).ok());
  auto frame = brdFrame();
  ASSERT_TRUE(net.segment->processFrame(frame, 0).delivered);
  EXPECT_EQ(firstWkc(frame), 2);  // S2 is cut off
  EXPECT_EQ(net.segment->slave(1).esc().reg8(0x0311), 1);
  EXPECT_EQ(net.segment->slave(2).esc().reg8(0x0310), 1);
  ASSERT_TRUE(faults.apply(action("link-up cable=c2"), 0).ok());
  frame = brdFrame();
  ASSERT_TRUE(net.segment->processFrame(frame, 0).delivered);
  EXPECT_EQ(firstWkc(frame), 3);
}

TEST(Faults, PowerCycleResetsRegistersAndEepromChecksumKeepsThePdiOff) {
  Network net = makeLine(2);
  FaultInjector faults(net, 1);
  auto& esc = net.segment->slave(1).esc();
  esc.pdiWrite16(0x0010, 0x1002);
  ASSERT_TRUE(faults.apply(action("power-off slave=S1"), 0).ok());
  auto frame = brdFrame();
  ASSERT_TRUE(net.segment->processFrame(frame, 0).delivered);
  EXPECT_EQ(firstWkc(frame), 1);
  ASSERT_TRUE(faults.apply(action("power-on slave=S1"), 0).ok());
  EXPECT_EQ(esc.reg16(0x0010), 0);
  EXPECT_NE(esc.reg16(0x0110) & 0x0001, 0);  // EEPROM loaded, PDI operational
  EXPECT_TRUE(net.segment->slave(1).firmwareRunning());
  ASSERT_TRUE(faults.apply(action("eeprom-checksum slave=S1"), 0).ok());
  EXPECT_EQ(esc.reg16(0x0110) & 0x0001, 0);
  EXPECT_NE(esc.reg16(0x0502) & 0x0800, 0);  // checksum error
  EXPECT_FALSE(net.segment->slave(1).firmwareRunning());
}

TEST(Faults, AlErrorSetsTheFlagAndCode) {
  Network net = makeLine(1);
  FaultInjector faults(net, 1);
  ASSERT_TRUE(faults.apply(action("al-error slave=S0 code=0x001A state=INIT"), 0).ok());
  EXPECT_EQ(net.segment->slave(0).esc().alStatus(), 0x0011);
  EXPECT_EQ(net.segment->slave(0).esc().reg16(0x0134), 0x001A);
}

TEST(Faults, ErrorsNameWhatIsWrong) {
  Network net = makeLine(1);
  FaultInjector faults(net, 1);
  auto r = faults.apply(action("link-down cable=nowhere"), 0);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().context.find("nowhere"), std::string::npos);
  // A missing argument is found when the line is parsed, before anything is applied.
  auto missing = parseFaultLine("al-error slave=S0");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().context, "control: al-error: missing argument 'code'");
  EXPECT_FALSE(FaultInjector::handles("explode"));
  EXPECT_FALSE(FaultInjector::handles("pause-master")) << "the runner's, not the network's";
}

TEST(FaultAction, ParsesQuotedValuesAndRoundTrips) {
  auto a = parseFaultAction("input slave=DI1 channel=2 signal=\"square period=0.2 low=0 high=1\"");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->verb, "input");
  EXPECT_EQ(a->args.at("signal"), "square period=0.2 low=0 high=1");
  auto again = parseFaultAction(a->text());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->args, a->args);
  EXPECT_FALSE(parseFaultAction("link-down cable").ok());
  EXPECT_FALSE(parseFaultAction("input signal=\"open").ok());
}

// Issue #21: every argument has a range, the error names it; NaN, infinities and integers that
// do not fit are refused, never truncated or wrapped.
// Issue #16: they are found when the action is parsed (a scenario loaded, a control line read),
// not when it is applied.
TEST(FaultArguments, OutOfRangeNumbersAreRefusedWithTheRange) {
  struct Case {
    const char* line;
    const char* expected;  // in the error
  };
  const Case cases[] = {
      {"loss rate=nan", "rate=nan is not a number in [0, 1]"},
      {"loss rate=inf", "[0, 1]"},
      {"loss rate=-0.5", "[0, 1]"},
      {"loss rate=1.5", "[0, 1]"},
      {"delay cable=master ns=9223372036854775807 durationMs=10", "ns=9223372036854775807"},
      {"delay cable=master ns=18446744073709551615 durationMs=10", "[0, 1000000000]"},
      {"delay cable=master ns=99999999999999999999999 durationMs=10", "[0, 1000000000]"},
      {"delay cable=master ns=-1 durationMs=10", "[0, 1000000000]"},
      {"delay cable=master ns=100 durationMs=1e300", "durationMs=1e300"},
      {"delay cable=master ns=100 durationMs=nan", "[0, 86400000]"},
      {"delay cable=master ns=100 durationMs=-5", "[0, 86400000]"},
      {"corrupt cable=master count=18446744073709551615", "[0, 1000000]"},
      {"al-error slave=S0 code=0x1FFFFFFFFFF", "code=0x1FFFFFFFFFF is not a number in [0, 0xffff]"},
      {"drive-fault slave=S0 code=0x10000", "[0, 0xffff]"},
      {"sdo-abort slave=S0 index=0x10000", "[0, 0xffff]"},
      {"sdo-abort slave=S0 index=0x6040 sub=256", "[0, 255]"},
      {"sdo-abort slave=S0 index=0x6040 code=0x100000000", "[0, 0xffffffff]"},
      {"mailbox-silent slave=S0 on=2", "[0, 1]"},
      {"link-down slave=S0 port=4294967296", "[0, 3]"},
  };
  for (const Case& c : cases) {
    auto r = parseFaultLine(c.line);
    ASSERT_FALSE(r.ok()) << c.line << " was accepted: " << describe(*r);
    EXPECT_NE(r.error().context.find(c.expected), std::string::npos)
        << c.line << ": " << r.error().context;
    EXPECT_EQ(r.error().context.rfind("control: ", 0), 0u) << r.error().context;
  }
}

TEST(FaultArguments, ZeroClearsTheFault) {
  Network net = makeLine(3);
  FaultInjector faults(net, 1);
  SimTime now = 0;
  auto send = [&] {  // a frame 100 us after the last: its outcome, times relative to its send
    auto frame = brdFrame();
    now += 100000;
    auto out = net.segment->processFrame(frame, now);
    out.returnTime -= now;
    return out;
  };
  auto apply = [&](const char* line) { return faults.apply(action(line), now).ok(); };
  const SimTime plain = send().returnTime;
  ASSERT_TRUE(apply("corrupt cable=c1 count=1000"));
  EXPECT_FALSE(send().delivered);
  ASSERT_TRUE(apply("corrupt cable=c1 count=0"));
  EXPECT_TRUE(send().delivered) << "corrupt count=0 clears";

  ASSERT_TRUE(apply("delay cable=c2 ns=5000 durationMs=1000"));
  ASSERT_TRUE(apply("delay cable=c2 ns=7000 durationMs=1000"));
  EXPECT_EQ(send().returnTime, plain + 24000) << "both spikes, both ways";
  ASSERT_TRUE(apply("delay cable=c2 ns=0 durationMs=0"));
  EXPECT_EQ(send().returnTime, plain) << "delay ns=0 removes the cable's spikes";

  ASSERT_TRUE(apply("loss rate=1 cable=c1"));
  EXPECT_FALSE(send().delivered);
  ASSERT_TRUE(apply("loss rate=0 cable=c1"));
  EXPECT_TRUE(send().delivered);
}

TEST(FaultArguments, CorruptCountsAddUpToTheBoundNotBeyond) {
  Network net = makeLine(2);
  FaultInjector faults(net, 1);
  ASSERT_TRUE(faults.apply(action("corrupt cable=c1 count=1000000"), 0).ok());
  ASSERT_TRUE(faults.apply(action("corrupt cable=c1 count=1000000"), 0).ok());
  ASSERT_TRUE(faults.apply(action("corrupt cable=c1 count=0"), 0).ok());
  auto frame = brdFrame();
  EXPECT_TRUE(net.segment->processFrame(frame, 0).delivered);
}

// The context of a refused control line ("" when it was accepted).
std::string refusal(std::string_view line) {
  auto a = parseFaultAction(line);
  return a.ok() ? std::string() : a.error().context;
}

TEST(FaultAction, MalformedLinesAreRefusedWithTheColumn) {
  EXPECT_EQ(refusal("link-down cable=\"drives"), "control: column 17: unterminated quote");
  EXPECT_EQ(refusal("link-down =drives"), "control: column 11: empty argument name");
  EXPECT_EQ(refusal("link-down cable=a cable=b"),
            "control: column 19: argument 'cable' given twice");
  EXPECT_EQ(refusal("link-down cable=dr\x01ves"),
            "control: column 19: byte 0x01 is not printable");
  EXPECT_EQ(refusal(std::string("link-down cable=dr\0ves", 22)),
            "control: column 19: byte 0x00 is not printable");
  EXPECT_EQ(refusal("link-down cable=drives\x7f"),
            "control: column 23: byte 0x7f is not printable");
  // A line ended by CR LF (nc -C, telnet) is fine.
  EXPECT_EQ(refusal("link-down cable=drives\r"), "");
  EXPECT_EQ(refusal("input slave=DI1 channel=1 signal=\"sine amplitude=5\"\r"), "");
}

TEST(FaultAction, UnknownNamesAreRefusedNamingTheClosestValidOne) {
  EXPECT_EQ(refusal("link-down cable=drives extra=1"),
            "control: link-down: unknown argument 'extra' (valid: cable, port, slave)");
  EXPECT_EQ(refusal("delay cable=master ns=5 durationMS=10"),
            "control: delay: unknown argument 'durationMS'; did you mean 'durationMs'?");
  EXPECT_EQ(refusal("power-off slave=S1 port=1"),
            "control: power-off: unknown argument 'port' (valid: slave)");
  EXPECT_EQ(refusal("link-dwn cable=drives"),
            "control: unknown action 'link-dwn'; did you mean 'link-down'?");
  // Every verb's own arguments are accepted.
  EXPECT_EQ(refusal("sdo-abort slave=S1 index=0x6040 sub=0 code=0x06020000"), "");
  EXPECT_EQ(refusal("encoder-fault slave=S1 kind=frame on=0 channel=2"), "");
  EXPECT_EQ(refusal("delay slave=S1 port=1 ns=100 durationMs=5"), "");
}

// Every verb parses into its typed fault, and describe() writes it back as a line that parses
// to the same fault (defaults written out, names of states and kinds kept).
TEST(TypedFaults, EveryVerbParsesAndDescribesItselfBack) {
  const std::pair<const char*, const char*> cases[] = {
      {"link-down cable=drives", "link-down cable=drives"},
      {"link-up slave=S1 port=1", "link-up slave=S1 port=1"},
      {"loss rate=0.25", "loss rate=0.25"},
      {"loss rate=1 cable=c1", "loss rate=1 cable=c1"},
      {"corrupt cable=c1", "corrupt cable=c1 count=1"},
      {"delay slave=S1 port=0 ns=5000 durationMs=2.5",
       "delay slave=S1 port=0 ns=5000 durationMs=2.5"},
      {"power-off slave=S1", "power-off slave=S1"},
      {"power-on slave=S1", "power-on slave=S1"},
      {"power-cycle slave=S1", "power-cycle slave=S1"},
      {"al-error slave=S1 code=27", "al-error slave=S1 code=0x001b"},
      {"al-error slave=S1 code=0x1A state=PREOP", "al-error slave=S1 code=0x001a state=PREOP"},
      {"eeprom-checksum slave=S1", "eeprom-checksum slave=S1"},
      {"mailbox-silent slave=S1", "mailbox-silent slave=S1"},
      {"mailbox-silent slave=S1 on=0", "mailbox-ok slave=S1"},
      {"mailbox-ok slave=S1", "mailbox-ok slave=S1"},
      {"sdo-abort slave=S1 index=0x1C12", "sdo-abort slave=S1 index=0x1c12 code=0x06020000"},
      {"sdo-abort slave=S1 index=0x1C12 sub=0 code=0x08000022",
       "sdo-abort slave=S1 index=0x1c12 sub=0 code=0x08000022"},
      {"sdo-ok slave=S1", "sdo-ok slave=S1"},
      {"drive-fault slave=S1", "drive-fault slave=S1 code=0x2310"},
      {"encoder-fault slave=S1", "encoder-fault slave=S1 kind=data on=1 channel=1"},
      {"encoder-fault slave=S1 kind=power on=0 channel=2",
       "encoder-fault slave=S1 kind=power on=0 channel=2"},
      {"input slave=S1 channel=2 signal=\"sine amplitude=5\"",
       "input slave=S1 channel=2 signal=\"sine amplitude=5\""},
      {"latch slave=S1 unit=1 level=1", "latch slave=S1 unit=1 level=1"},
  };
  for (const auto& [line, expected] : cases) {
    auto f = parseFaultLine(line);
    ASSERT_TRUE(f.ok()) << line << ": " << f.error().context;
    EXPECT_EQ(describe(*f), expected) << line;
    auto again = parseFaultLine(describe(*f));
    ASSERT_TRUE(again.ok()) << describe(*f) << ": " << again.error().context;
    EXPECT_EQ(describe(*again), expected);
  }
  // The typed values themselves.
  auto abort = parseFaultLine("sdo-abort slave=S1 index=0x1C12 sub=3 code=0x06010000");
  ASSERT_TRUE(abort.ok());
  const auto& a = std::get<SdoAbortFault>(*abort);
  EXPECT_EQ(a.index, 0x1C12);
  EXPECT_EQ(a.subindex, std::optional<std::uint8_t>(3));
  EXPECT_EQ(a.code, 0x06010000u);
  auto state = parseFaultLine("al-error slave=S1 code=0x1B state=INIT");
  ASSERT_TRUE(state.ok());
  EXPECT_EQ(std::get<AlError>(*state).state, std::optional<AlState>(AlState::kInit));
  auto input = parseFaultLine("input slave=S1 channel=1 signal=\"square period=0.5\"");
  ASSERT_TRUE(input.ok());
  EXPECT_EQ(std::get<Input>(*input).signal.kind(), slavesim::devices::Signal::Kind::kSquare);
}

// Names of states, kinds and signals are refused with the closest valid one; a cable and a
// slave port at once is refused (which one was meant?).
TEST(TypedFaults, NamesAndPlacesAreCheckedWhenParsed) {
  const std::pair<const char*, const char*> cases[] = {
      {"al-error slave=S1 code=1 state=SAFE-OP",
       "control: al-error: state=SAFE-OP is not INIT, PREOP, BOOT, SAFEOP or OP; did you mean "
       "'SAFEOP'?"},
      {"encoder-fault slave=S1 kind=fram",
       "control: encoder-fault: kind=fram is not data, frame or power; did you mean 'frame'?"},
      {"link-down cable=c1 slave=S1 port=1",
       "control: link-down: takes cable=NAME or slave=NAME port=N, not both"},
      {"link-down slave=S1", "control: link-down: missing argument 'port'"},
      {"corrupt count=3", "control: corrupt: needs cable=NAME or slave=NAME port=N"},
      {"input slave=S1 channel=1 signal=\"sqaure period=1\"", "did you mean 'square'?"},
      {"delay cable=c1 ns=5", "control: delay: needs durationMs=T or durationCycles=N"},
      // Cycles are the runner's: a control line has none.
      {"delay cable=c1 ns=5 durationCycles=3",
       "control: delay: unknown argument 'durationCycles' (valid: cable, durationMs, ns, port, "
       "slave)"},
      {"pause-master durationMs=5", "control: unknown action 'pause-master'"},
  };
  for (const auto& [line, expected] : cases) {
    auto f = parseFaultLine(line);
    ASSERT_FALSE(f.ok()) << line << " was accepted";
    EXPECT_NE(f.error().context.find(expected), std::string::npos)
        << line << ": " << f.error().context;
  }
}

// The control socket's answer to a line: parsed first (nothing applied when an argument is
// wrong), then applied; errors say "control" and the verb.
TEST(TypedFaults, ControlLinesAreParsedThenApplied) {
  Network net = makeLine(3);
  FaultInjector faults(net, 1);
  EXPECT_EQ(answerFaultLine(faults, "loss rate=1.5 cable=c1", 0),
            "error control: loss: rate=1.5 is not a number in [0, 1]");
  auto frame = brdFrame();
  EXPECT_TRUE(net.segment->processFrame(frame, 0).delivered) << "nothing was applied";
  EXPECT_EQ(answerFaultLine(faults, "link-down cable=c3", 0),
            "error control: link-down: no cable named 'c3'; did you mean 'c1'?");
  EXPECT_EQ(answerFaultLine(faults, "link-down cable=c2", 0), "ok link down at S2 port 0");
  EXPECT_EQ(answerFaultLine(faults, "pause-master durationMs=5", 0).rfind(
                "error control: unknown action 'pause-master'", 0),
            0u);
}

// A scenario's durations in cycles of its master: exactly one of durationMs and durationCycles.
TEST(TypedFaults, DurationsInMillisecondsOrCycles) {
  auto scenarioAction = [](std::map<std::string, std::string, std::less<>> args, SimTime cycle) {
    FaultAction a;
    a.verb = args.count("ns") != 0 ? "delay" : "pause-master";
    a.args = std::move(args);
    a.where = "s.xml, line 7";
    return parseFault(a, {FaultScope::kScenario, cycle});
  };
  auto d = scenarioAction({{"cable", "c1"}, {"ns", "500"}, {"durationCycles", "20"}}, 250'000);
  ASSERT_TRUE(d.ok()) << d.error().context;
  EXPECT_EQ(std::get<Delay>(*d).duration, 5 * kNsPerMs);
  auto p = scenarioAction({{"durationCycles", "8"}}, kNsPerMs);
  ASSERT_TRUE(p.ok()) << p.error().context;
  EXPECT_EQ(std::get<PauseMaster>(*p).duration, 8 * kNsPerMs);
  auto ms = scenarioAction({{"durationMs", "12.5"}}, kNsPerMs);
  ASSERT_TRUE(ms.ok());
  EXPECT_EQ(std::get<PauseMaster>(*ms).duration, 12'500'000);

  auto both = scenarioAction({{"durationMs", "5"}, {"durationCycles", "5"}}, kNsPerMs);
  ASSERT_FALSE(both.ok());
  EXPECT_EQ(both.error().context,
            "s.xml, line 7: pause-master: takes durationMs=T or durationCycles=N, not both");
  auto external = scenarioAction({{"durationCycles", "5"}}, 0);
  ASSERT_FALSE(external.ok());
  EXPECT_NE(external.error().context.find("durationCycles needs our master's cycle time"),
            std::string::npos);
  // At most a day, as durationMs.
  auto long_ = scenarioAction({{"durationCycles", "86400001"}}, kNsPerMs);
  ASSERT_FALSE(long_.ok());
  EXPECT_NE(long_.error().context.find("durationCycles=86400001 is not a number in [0, 86400000]"),
            std::string::npos)
      << long_.error().context;
}

}  // namespace
}  // namespace ecsim::topology
