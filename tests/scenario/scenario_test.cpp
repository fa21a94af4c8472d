// The scenario format (errors name file and line), the runner on the demo network, and the
// determinism a CI system relies on: the same scenario and seed give the same report and pcap.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "scenario/engine.hpp"
#include "scenario/scenario.hpp"
#include "support/fifo.hpp"

namespace ecsim::scenario {
namespace {

const std::filesystem::path kDir = std::filesystem::path(ECSIM_SOURCE_DIR) / "scenarios";

std::string wrap(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<Scenario name=\"t\" topology=\"demo.xml\" cycleUs=\"1000\" "
         "durationMs=\"100\">\n" +
         body + "</Scenario>\n";
}

TEST(ScenarioFile, ReadsActionsAndExpectations) {
  auto s =
      parseScenario(wrap("<Timeline>\n"
                         "  <Action cycle=\"5\" do=\"link-down\" cable=\"drives\"/>\n"
                         "  <Action timeMs=\"7.5\" do=\"link-up\" cable=\"drives\"/>\n"
                         "</Timeline>\n<Expect>\n"
                         "  <State slave=\"DI1\" state=\"OP\" atMs=\"50\"/>\n"
                         "  <Register slave=\"DI1\" address=\"0x0310\" op=\"ge\" value=\"1\"/>\n"
                         "</Expect>\n"),
                    "/x/s.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_EQ(s->topology, std::filesystem::path("/x/demo.xml"));
  ASSERT_EQ(s->actions.size(), 2u);
  EXPECT_EQ(s->actions[0].cycle, 5u);
  EXPECT_EQ(s->actions[1].time, 7500000);
  EXPECT_EQ(s->actions[1].action.args.at("cable"), "drives");
  ASSERT_EQ(s->expectations.size(), 2u);
  EXPECT_EQ(s->expectations[1].compare, Compare::kGe);
  EXPECT_EQ(s->expectations[1].address, 0x0310);
  EXPECT_EQ(s->expectations[0].line, 8);
}

// Issue #16: moments and spans in ms or in cycles; ours converts one into the other with its
// cycle time (here 1000 us; a time between two cycle starts means the next cycle).
TEST(ScenarioFile, TimesInMillisecondsOrCycles) {
  auto s = parseScenario(
      wrap("<Timeline>\n"
           "  <Action cycle=\"5\" do=\"delay\" cable=\"drives\" ns=\"800\" durationCycles=\"30\"/>\n"
           "  <Action cycle=\"40\" do=\"pause-master\" durationCycles=\"12\"/>\n"
           "</Timeline>\n<Expect>\n"
           "  <Detected condition=\"slave-lost\" afterMs=\"40.5\" withinMs=\"10\"/>\n"
           "  <BackInOp afterMs=\"60\" withinCycles=\"25\"/>\n"
           "</Expect>\n"),
      "/x/s.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_EQ(std::get<topology::Delay>(s->actions[0].fault).duration, 30 * kNsPerMs);
  EXPECT_EQ(std::get<topology::PauseMaster>(s->actions[1].fault).duration, 12 * kNsPerMs);
  EXPECT_EQ(s->expectations[0].afterCycle, 41u);
  EXPECT_EQ(s->expectations[0].withinCycles, 10u);
  EXPECT_EQ(s->expectations[1].afterCycle, 60u);
  EXPECT_FALSE(s->expectations[1].afterTime) << "ours counts cycles";
  EXPECT_EQ(s->expectations[1].within, 25 * kNsPerMs);
}

// A CSV file of an input action is found beside the scenario, as a topology's CSV files are
// beside the topology (docs/scenarios.md), not in the directory ecsim runs in.
TEST(ScenarioFile, InputCsvFilesAreFoundBesideTheScenario) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim_scenario_csv_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "trace.csv") << "0,0\n1,10\n";
  auto s = parseScenario(
      wrap("<Timeline>\n"
           "  <Action cycle=\"5\" do=\"input\" slave=\"DI1\" channel=\"1\" "
           "signal=\"csv file=trace.csv\"/>\n"
           "</Timeline>\n<Expect>\n  <State slave=\"DI1\" state=\"OP\"/>\n</Expect>\n"),
      dir / "s.xml");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto& input = std::get<topology::Input>(s->actions[0].fault);
  EXPECT_DOUBLE_EQ(input.signal.value(kNsPerSecond / 2), 5.0);
}

TEST(ScenarioFile, ErrorsNameFileAndLine) {
  auto s = parseScenario(wrap("<Timeline>\n  <Action do=\"link-down\"/>\n</Timeline>\n"
                              "<Expect><State slave=\"A\" state=\"OP\"/></Expect>\n"),
                         "bad.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().context.find("bad.xml, line 4"), std::string::npos) << s.error().context;
  s = parseScenario(wrap("<Expect>\n<State slave=\"A\" state=\"RUNNING\"/></Expect>\n"), "b.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().context.find("b.xml, line 4"), std::string::npos) << s.error().context;
  s = parseScenario(wrap("<Timeline><Action cycle=\"1\" do=\"explode\"/></Timeline>"
                         "<Expect><State slave=\"A\" state=\"OP\"/></Expect>"),
                    "c.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().context.find("explode"), std::string::npos);
  // The master's events are conditions too; an unknown one is named with the line.
  s = parseScenario(wrap("<Expect>\n<Detected condition=\"slave-recovered\" withinCycles=\"5\"/>\n"
                         "<Detected condition=\"slave-exploded\" withinCycles=\"5\"/></Expect>\n"),
                    "d.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().context.find("d.xml, line 5"), std::string::npos) << s.error().context;
  EXPECT_NE(s.error().context.find("recovery-failed"), std::string::npos) << s.error().context;
}

// Issue #21: a scenario's numbers have ranges; NaN, infinities, values beyond the range
// (durationMs="1e300" was an unchecked double to int64 cast) and integers that do not fit their
// field (code, mask: truncated before) are refused with the range and the line.
TEST(ScenarioFile, NumbersOutOfRangeAreRefusedWithTheRange) {
  const std::string expect = "<Expect><State slave=\"A\" state=\"OP\"/></Expect>\n";
  auto root = [&](const std::string& attributes) {
    return "<?xml version=\"1.0\"?>\n<Scenario name=\"t\" topology=\"demo.xml\" " + attributes +
           ">\n" + expect + "</Scenario>\n";
  };
  struct Case {
    std::string xml;
    const char* expected;
  };
  const Case cases[] = {
      {root("durationMs=\"1e300\""),
       "line 2: durationMs=\"1e300\" is not a number in [0, 86400000]"},
      {root("durationMs=\"nan\""), "durationMs=\"nan\" is not a number in [0, 86400000]"},
      {root("durationMs=\"-inf\""), "[0, 86400000]"},
      {root("cycleUs=\"18446744073709551615\""),
       "cycleUs=\"18446744073709551615\" is not a "
       "number in [50, 1000000]"},
      {root("cycleUs=\"10\""), "[50, 1000000]"},
      {wrap("<Timeline>\n<Action timeMs=\"1e20\" do=\"link-down\" cable=\"c\"/>\n</Timeline>\n" +
            expect),
       "line 4: timeMs=\"1e20\" is not a number in [0, 86400000]"},
      {wrap("<Timeline>\n<Action cycle=\"99999999999\" do=\"link-down\" cable=\"c\"/>\n"
            "</Timeline>\n" +
            expect),
       "line 4: cycle=\"99999999999\" is not a number in [0, 2000000000]"},
      {wrap("<Expect>\n<State slave=\"A\" state=\"OP\" code=\"0x1FFFFFFFFFF\"/></Expect>\n"),
       "line 4: code=\"0x1FFFFFFFFFF\" is not a number in [0, 65535]"},
      {wrap("<Expect>\n<Register slave=\"A\" address=\"0x310\" value=\"1\" "
            "mask=\"0x1FFFFFFFF\"/></Expect>\n"),
       "line 4: mask=\"0x1FFFFFFFF\" is not a number in [0, 4294967295]"},
      {wrap("<Expect>\n<BackInOp withinMs=\"inf\"/></Expect>\n"),
       "line 4: withinMs=\"inf\" is not a number in [0, 86400000]"},
      {wrap("<Expect>\n<Register slave=\"A\" address=\"0x310\" value=\"nan\"/></Expect>\n"),
       "line 4: value=\"nan\" is not a finite number"},
      {wrap("<Expect>\n<Register slave=\"A\" address=\"0x310\" value=\"1\" "
            "tolerance=\"-1\"/></Expect>\n"),
       "line 4: tolerance=\"-1\" is not a finite number >= 0"},
  };
  for (const Case& c : cases) {
    auto s = parseScenario(c.xml, "n.xml");
    ASSERT_FALSE(s.ok()) << c.xml;
    EXPECT_NE(s.error().context.find(c.expected), std::string::npos)
        << c.expected << "\n  got: " << s.error().context;
  }
}

TEST(Runner, AFailingExpectationSaysWhatWhenAndWhat) {
  auto s = loadScenario(kDir / "cable_break.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  // Ask for the impossible: Drive1 in OP while its cable is pulled.
  Expectation x;
  x.line = 999;
  x.kind = ExpectKind::kState;
  x.slave = "Drive1";
  x.state = "OP";
  x.atCycle = 700;
  s->expectations.push_back(x);
  s->duration = 1000 * kNsPerMs;
  auto r = runScenario(*s);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_FALSE(r.passed());
  const std::string report = formatReport(r);
  EXPECT_NE(report.find("FAIL  cable_break.xml, line 999: State Drive1 is OP at cycle 700"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("at 700.000 ms: SAFEOP"), std::string::npos) << report;
  const std::string junit = formatJunit({r});
  EXPECT_NE(junit.find("<failure message=\"at 700.000 ms: SAFEOP"), std::string::npos) << junit;
}

// Issue #16 item 3: a <Variable> by the name the master gives it from the topology's slave
// names; the names exist once the master has scanned, so the runner checks them when the run
// starts and a name not found is a scenario error listing the closest names.
TEST(Runner, VariablesByTheirNames) {
  auto s = loadScenario(kDir / "drive_fault.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  s->duration = 400 * kNsPerMs;
  s->actions.clear();
  s->expectations.clear();
  Expectation x;
  x.line = 41;
  x.kind = ExpectKind::kVariable;
  x.variable = "Drive1.Statusword";
  // The runner writes no controlword: the drive stays in Switch on disabled (CiA 402,
  // statusword xxxx xxxx x1xx 0000).
  x.mask = 0x004F;
  x.value = 0x0040;
  x.atCycle = 300;
  s->expectations.push_back(x);
  auto r = runScenario(*s);
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.results.size(), 1u);
  EXPECT_TRUE(r.results[0].passed) << r.results[0].observed;
  EXPECT_EQ(r.results[0].what, "Variable Drive1.Statusword == 64 at cycle 300");

  s->expectations[0].variable = "Drive1.StatusWord";
  r = runScenario(*s);
  // The engine reports a start error as Error::message() ("not found: FILE, line N: ...").
  EXPECT_NE(r.error.find((kDir / "drive_fault.xml").string() + ", line 41: "), std::string::npos)
      << r.error;
  EXPECT_NE(r.error.find("'Drive1.StatusWord'; closest: Drive1.Statusword"), std::string::npos)
      << r.error;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A scenario path that names a FIFO is refused at once (readRegularFile), not waited on.
TEST(ScenarioFile, AFifoIsRefused) {
  const auto fifo = std::filesystem::temp_directory_path() /
                    ("ecsim-scenario-fifo-" + std::to_string(::getpid()) + ".xml");
  ASSERT_TRUE(ecsim::testing::makeFifo(fifo));
  auto s = ecsim::testing::readWithoutHanging(fifo, [&] { return loadScenario(fifo); });
  std::filesystem::remove(fifo);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().context, fifo.string() + ": is a FIFO, not a regular file");
}

// An Action attribute its verb does not take is an error naming the closest valid one (it was
// ignored: a misspelt durationMs left the fault in place for ever).
TEST(ScenarioFile, AnArgumentTheActionDoesNotTakeIsAnError) {
  auto s = parseScenario(
      "<Scenario name=\"x\" topology=\"t.xml\" cycleUs=\"1000\" durationMs=\"100\">\n"
      "  <Master kind=\"in-process\"/>\n"
      "  <Timeline>\n"
      "    <Action cycle=\"1\" do=\"delay\" cable=\"master\" ns=\"10\" durationMS=\"5\"/>\n"
      "  </Timeline>\n"
      "</Scenario>\n",
      "/x/s.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().context,
            "/x/s.xml, line 4: delay: unknown argument 'durationMS'; did you mean 'durationMs'?");
}

TEST(Runner, SameSeedSameReportAndCapture) {
  auto s = loadScenario(kDir / "frame_loss.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  s->duration = 700 * kNsPerMs;
  const auto dir = std::filesystem::temp_directory_path() / "ecsim_scenario_test";
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  RunOptions a;
  a.pcapDir = dir / "a";
  RunOptions b;
  b.pcapDir = dir / "b";
  const auto ra = formatReport(runScenario(*s, a));
  const auto rb = formatReport(runScenario(*s, b));
  EXPECT_EQ(ra, rb);
  const auto pa = slurp(dir / "a" / "frame_loss.pcap");
  EXPECT_GT(pa.size(), 10000u);
  EXPECT_EQ(pa, slurp(dir / "b" / "frame_loss.pcap"));
  RunOptions c;
  c.seed = 99;
  EXPECT_NE(formatReport(runScenario(*s, c)), ra);  // another seed, other losses
  std::filesystem::remove_all(dir);
}

// The acceptance of issue #9: every shipped scenario passes with our master, and fails when the
// master does not react (MasterOptions::recovery off) - only on expectations marked
// needsRecovery, so each failure is for the right reason.
TEST(Runner, ShippedScenariosPassWithRecoveryAndFailWithoutOnlyWhereMarked) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(kDir)) {
    if (entry.path().extension() == ".xml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 15u);
  for (const auto& file : files) {
    auto s = loadScenario(file);
    ASSERT_TRUE(s.ok()) << s.error().message();
    if (s->masterKind != "in-process") continue;
    const auto with = runScenario(*s);
    EXPECT_TRUE(with.passed()) << formatReport(with);
    RunOptions off;
    off.recovery = false;
    const auto without = runScenario(*s, off);
    ASSERT_TRUE(without.error.empty()) << without.error;
    // A scenario that marks nothing needsRecovery is about what the master sees, not how it
    // reacts (redundancy_break: the ring keeps every slave reachable): it passes without.
    const bool needsRecovery = std::any_of(s->expectations.begin(), s->expectations.end(),
                                           [](const Expectation& x) { return x.needsRecovery; });
    if (needsRecovery) {
      EXPECT_GE(without.failures(), 1u) << file << " passes without recovery";
    } else {
      EXPECT_TRUE(without.passed()) << formatReport(without);
    }
    for (const auto& x : without.results) {
      EXPECT_TRUE(x.passed || x.needsRecovery)
          << file.filename() << " line " << x.line << " fails without recovery but is not marked "
          << "needsRecovery: " << x.what << ": " << x.observed;
    }
  }
}

// The redundancy scenario could not pass on a line: the same file with the topology of the
// demo line (the same slaves and cables, no second master port) fails on the ring's events, on
// the master's failed cycles and on the drives lost behind each break.
TEST(Runner, TheRedundancyScenarioFailsOnALine) {
  auto s = loadScenario(kDir / "redundancy_break.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto ring = runScenario(*s);
  EXPECT_TRUE(ring.passed()) << formatReport(ring);
  s->topology = kDir.parent_path() / "examples/topologies/demo.xml";
  const auto line = runScenario(*s);
  ASSERT_TRUE(line.error.empty()) << line.error;
  std::set<std::string> failed;
  for (const auto& x : line.results) {
    if (!x.passed) failed.insert(x.what.substr(0, x.what.find(" within")));
  }
  EXPECT_TRUE(failed.count("Detected ring-broken of AI1")) << formatReport(line);
  EXPECT_TRUE(failed.count("Detected ring-whole")) << formatReport(line);
  EXPECT_TRUE(failed.count("Statistic cyclesWithErrors == 0 at the end")) << formatReport(line);
  EXPECT_TRUE(failed.count("Statistic slavesLost == 0 at the end")) << formatReport(line);
}

// The report shows what the master reported (its events), and Statistic counts them by name.
TEST(Runner, ReportsTheMastersEventsAndCountsThem) {
  auto s = loadScenario(kDir / "power_cycle_drive.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  Expectation x;
  x.line = 998;
  x.kind = ExpectKind::kStatistic;
  x.name = "slave-lost";
  x.slave = "Drive2";
  x.value = 1;
  s->expectations.push_back(x);
  x.line = 999;
  x.name = "slave-lost";
  x.slave = "Drive1";  // not lost: it only lost its link at port 1
  x.value = 0;
  s->expectations.push_back(x);
  const auto r = runScenario(*s);
  const std::string report = formatReport(r);
  EXPECT_TRUE(r.passed()) << report;
  EXPECT_NE(report.find("master: slave 5 (0x1006 'Drive2') lost"), std::string::npos) << report;
  EXPECT_NE(report.find("answers at its position with station address 0 (power cycle)"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("back in OP"), std::string::npos) << report;
  EXPECT_EQ(report.find("restart"), std::string::npos) << report;  // the runner restarts nothing
}

// <Master kind="veth"> is our master over veth: a scenario for ours, with ours' rules
// (Detected is judged, Output is refused), and --master switches only between our two.
TEST(Engine, VethIsOurMasterAndMasterOverridesOnlyBetweenOurTwo) {
  auto s = parseScenario(wrap("<Master kind=\"veth\"/>\n<Expect>\n"
                              "<Detected condition=\"wkc-error\" withinCycles=\"5\"/>\n"
                              "</Expect>\n"),
                         "v.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_EQ(s->masterKind, "veth");
  auto refused = parseScenario(wrap("<Master kind=\"veth\"/>\n<Expect>\n"
                                    "<Output contains=\"x\"/>\n</Expect>\n"),
                               "o.xml");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().context.find("o.xml, line 5"), std::string::npos)
      << refused.error().context;
  auto unknown = parseScenario(wrap("<Master kind=\"vteh\"/>\n<Expect>\n"
                                    "<State slave=\"A\" state=\"OP\"/>\n</Expect>\n"),
                               "k.xml");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().context.find("in-process, veth or external"), std::string::npos)
      << unknown.error().context;

  RunOptions o;
  EXPECT_EQ(*masterKindFor(*s, o), "veth");
  o.master = "in-process";
  EXPECT_EQ(*masterKindFor(*s, o), "in-process");
  o.master = "external";
  auto noCommand = masterKindFor(*s, o);
  ASSERT_FALSE(noCommand.ok());
  EXPECT_NE(noCommand.error().message().find("v.xml, line 3"), std::string::npos)
      << noCommand.error().message();
  Scenario external = *s;
  external.masterKind = "external";
  external.masterCommand = "true";
  o.master = "veth";
  auto ours = masterKindFor(external, o);
  ASSERT_FALSE(ours.ok());
  EXPECT_NE(ours.error().message().find("written for an external master"), std::string::npos)
      << ours.error().message();
  // The run says so too, judging nothing.
  const auto r = runScenario(external, o);
  EXPECT_FALSE(r.error.empty());
  EXPECT_TRUE(r.results.empty());
}

}  // namespace
}  // namespace ecsim::scenario
