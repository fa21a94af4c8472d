// The control socket's JSON protocol (docs/control.md, issue #19 item 5) against the demo
// network in process: requests by the names a master gives (master/variables.hpp), objects,
// registers through the register map, state, faults, and subscriptions pushed on change; and
// the refusals of our strict format, each naming what was wrong and the closest valid name.
#include "tools/ecsim/control_api.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "config/topology_file.hpp"
#include "embed/slave_variables.hpp"
#include "link/fd.hpp"
#include "protocol/registers.hpp"
#include "slavesim/esi_slave.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::tools {
namespace {

using nlohmann::json;

class ControlApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto config = loadTopologyFile(ECSIM_SOURCE_DIR "/examples/topologies/demo.xml");
    ASSERT_TRUE(config.ok()) << config.error().message();
    auto built = topology::buildNetwork(*config);
    ASSERT_TRUE(built.ok()) << built.error().message();
    network_ = std::move(built).value();
    api_.emplace(network_);
  }
  json ask(const std::string& line, topology::ControlServer::ClientId client = 1) {
    const std::string answer = api_->answer(line, client, 0);
    auto j = json::parse(answer, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << answer;
    return j;
  }
  std::string error(const std::string& line) {
    json j = ask(line);
    EXPECT_EQ(j.value("ok", true), false) << j.dump();
    return j.value("error", std::string());
  }
  slavesim::Slave& slave(const std::string& name) {
    for (std::size_t i = 0; i < network_.segment->size(); ++i) {
      if (network_.segment->slave(i).name() == name) return network_.segment->slave(i);
    }
    ADD_FAILURE() << "no slave " << name;
    return network_.segment->slave(0);
  }

  topology::Network network_;
  std::optional<ControlApi> api_;
};

TEST_F(ControlApiTest, SlaveSideNamesAreTheMastersNames) {
  const auto vars = embed::slaveVariables(*network_.segment);
  auto out8 = master::findVariable(vars, "DO1.Output 8");
  ASSERT_TRUE(out8.ok()) << out8.error().message();
  EXPECT_TRUE(out8->output);
  EXPECT_EQ(out8->position, 2u);  // Coupler 0, DI1 1, DO1 2 (bus order)
  EXPECT_EQ(out8->bitLength, 1);
  // The aliases master::findVariable takes: bus position, hex index.
  EXPECT_TRUE(master::findVariable(vars, "2.Output 8").ok());
  EXPECT_TRUE(master::findVariable(vars, "DO1.0x7000:08").ok());
  EXPECT_TRUE(master::findVariable(vars, "Drive1.Statusword").ok());
}

TEST_F(ControlApiTest, GetsAnOutputTheMasterWroteByItsName) {
  // What the firmware copied from the master's SM buffer into DO1's dictionary.
  auto* od = slavesim::objectDictionaryOf(slave("DO1"));
  ASSERT_NE(od, nullptr);
  ASSERT_TRUE(od->set<bool>(0x7000, 8, true).ok());
  json j = ask(R"({"op":"get","slave":"DO1","entry":"Output 8"})");
  EXPECT_EQ(j["ok"], true) << j.dump();
  EXPECT_EQ(j["name"], "DO1.Output 8");
  EXPECT_EQ(j["value"], 1);
  EXPECT_EQ(j["output"], true);
  EXPECT_EQ(j["type"], "BOOL");
  EXPECT_EQ(ask(R"({"op":"get","name":"DO1.Output 7"})")["value"], 0);
}

TEST_F(ControlApiTest, SetsAnInputWithinItsRange) {
  // demo.xml sets DI1's Input 1 and 3; Input 2 starts at 0.
  EXPECT_EQ(ask(R"({"op":"get","slave":"DI1","entry":"Input 2"})")["value"], 0);
  json j = ask(R"({"op":"set","slave":"DI1","entry":"Input 2","value":true})");
  EXPECT_EQ(j["ok"], true) << j.dump();
  EXPECT_EQ(ask(R"({"op":"get","slave":"DI1","entry":"Input 2"})")["value"], 1);
  EXPECT_EQ(slavesim::objectDictionaryOf(slave("DI1"))->getOr<std::uint8_t>(0x6000, 2, 9), 1);
}

TEST_F(ControlApiTest, ObjectsAndRegisters) {
  // Drive1's Statusword (0x6041:00, CiA 402) read from its dictionary.
  auto* od = slavesim::objectDictionaryOf(slave("Drive1"));
  ASSERT_NE(od, nullptr);
  const auto statusword = od->getOr<std::uint16_t>(0x6041, 0, 0xFFFF);
  json j = ask(R"({"op":"get","slave":"Drive1","object":"0x6041:00"})");
  EXPECT_EQ(j["ok"], true) << j.dump();
  EXPECT_EQ(j["value"], statusword);
  // Registers by the register map's name (any case, spaces, a 'k') or start address.
  const std::uint16_t alStatus = slave("DO1").esc().read(reg::kAlStatus);
  for (const char* name : {"AlStatus", "kAlStatus", "AL Status", "0x0130"}) {
    json r = ask(std::string(R"({"op":"get","slave":"DO1","register":")") + name + "\"}");
    EXPECT_EQ(r["ok"], true) << r.dump();
    EXPECT_EQ(r["value"], alStatus) << name;
    EXPECT_EQ(r["address"], "0x0130");
  }
}

// A register set through the socket is written from the PDI side, as the slave's firmware
// writes it: AL Status Code (0x0134) is the PDI's to write (ESC datasheet section II, 0x0134:
// ECAT read-only, PDI read/write), and the master then reads what was written.
TEST_F(ControlApiTest, ARegisterIsSetFromThePdiSide) {
  json j = ask(R"({"op":"set","slave":"DO1","register":"AlStatusCode","value":27})");
  EXPECT_EQ(j["ok"], true) << j.dump();
  EXPECT_EQ(j["value"], 27);
  EXPECT_EQ(slave("DO1").esc().read(reg::kAlStatusCode), 0x001B);
  EXPECT_EQ(error(R"({"op":"set","slave":"DO1","register":"AlStatusCode","value":70000})"),
            "DO1 AL Status Code: value 70000 out of range 0..65535");
  // AL Control is the master's (ECAT read/write, PDI read-only): the firmware cannot write it.
  EXPECT_NE(error(R"({"op":"set","slave":"DO1","register":"AlControl","value":2})")
                .find("DO1 AL Control is read-only from the PDI"),
            std::string::npos);
  EXPECT_EQ(error(R"({"op":"set","slave":"DO1","register":"AlStatusCode"})"),
            "op 'set' needs \"value\"");
}

TEST_F(ControlApiTest, StateListsEverySlaveInBusOrder) {
  json j = ask(R"({"op":"state"})");
  ASSERT_EQ(j["slaves"].size(), 6u) << j.dump();
  EXPECT_EQ(j["slaves"][2]["name"], "DO1");
  EXPECT_EQ(j["slaves"][2]["state"], "INIT");  // no master has run (ETG.1000.6 power-on)
  EXPECT_EQ(j["slaves"][2]["alStatusCode"], 0);
}

TEST_F(ControlApiTest, FaultsAsTextAndAsJsonAreListed) {
  EXPECT_EQ(api_->answer("link-down cable=drives", 1, 5).rfind("ok ", 0), 0u);
  json j = ask(R"({"op":"fault","action":"link-up cable=drives"})");
  EXPECT_EQ(j["ok"], true) << j.dump();
  json f = ask(R"({"op":"faults"})");
  ASSERT_EQ(f["faults"].size(), 2u) << f.dump();
  EXPECT_EQ(f["faults"][0]["action"], "link-down cable=drives");
  EXPECT_EQ(f["faults"][0]["atNs"], 5);
  EXPECT_NE(error(R"({"op":"fault","action":"link-dwn cable=drives"})").find("link-down"),
            std::string::npos);
}

TEST_F(ControlApiTest, BadRequestsNameWhatIsWrong) {
  EXPECT_EQ(error(R"({"op":"gett"})"), "unknown op 'gett'; did you mean 'get'?");
  EXPECT_NE(error(R"({"op":"get","slave":"DO1","entry":"Output 9"})")
                .find("no process variable 'DO1.Output 9'; closest: DO1.Output 1"),
            std::string::npos);
  EXPECT_NE(error(R"({"op":"get","slave":"DO2","register":"AlStatus"})")
                .find("no slave named 'DO2'; did you mean 'DO1'?"),
            std::string::npos);
  EXPECT_EQ(error(R"({"op":"get","slave":"DO1","entri":"Output 8"})"),
            "op 'get' takes no key 'entri'; did you mean 'entry'?");
  EXPECT_EQ(error(R"({"op":"set","slave":"DI1","entry":"Input 2","value":2})"),
            "DI1.Input 2: value 2 out of range 0..1");
  EXPECT_NE(
      error(R"({"op":"set","slave":"DO1","entry":"Output 8","value":1})").find("is an output"),
      std::string::npos);
  EXPECT_EQ(error(R"({"op":"get",)").rfind("malformed JSON at byte 13", 0), 0u);
  EXPECT_NE(error(R"({"op":"get","slave":"DO1","register":"AlStatis"})")
                .find("did you mean 'AL Status'?"),
            std::string::npos);
  EXPECT_NE(error(R"({"op":"get","slave":"DO1","register":"0x0131"})").find("inside AL Status"),
            std::string::npos);
  EXPECT_NE(error(R"({"op":"get","slave":"Drive1","object":"0x6041"})").find("0xIIII:SS"),
            std::string::npos);
  EXPECT_NE(error(R"({"op":"set","slave":"Drive1","object":"0x6060:00","value":200})")
                .find("out of range -128..127"),
            std::string::npos);
  EXPECT_NE(error(R"({"op":"get","slave":"DO1"})").find("needs one of"), std::string::npos);
  EXPECT_NE(error(R"(["get"])").find("JSON object"), std::string::npos);
  EXPECT_NE(error(R"({"op":"get","slave":1,"entry":"Output 8"})").find("must be a string"),
            std::string::npos);
}

// ---- subscriptions over a real control socket ------------------------------------------------

class ControlSubscribeTest : public ControlApiTest {
 protected:
  void SetUp() override {
    ControlApiTest::SetUp();
    path_ = std::filesystem::temp_directory_path() /
            ("ecsim-ctlapi-" + std::to_string(::getpid()) + ".sock");
    auto server = topology::ControlServer::open(path_);
    ASSERT_TRUE(server.ok()) << server.error().message();
    server_.emplace(std::move(server).value());
    auto c = topology::ControlConnection::open(path_, std::chrono::milliseconds(500));
    ASSERT_TRUE(c.ok()) << c.error().message();
    client_.emplace(std::move(c).value());
  }
  void serve() {
    server_->poll(topology::ControlServer::ClientHandler(
                      [this](std::string_view line, topology::ControlServer::ClientId id) {
                        return api_->answer(line, id, 0);
                      }),
                  0);
    api_->publish(*server_);
  }
  json next() {
    auto line = client_->readLine(std::chrono::milliseconds(200));
    EXPECT_TRUE(line.ok()) << line.error().message();
    return line.ok() ? json::parse(*line, nullptr, false) : json();
  }
  bool nothingMore() {
    auto line = client_->readLine(std::chrono::milliseconds(20));
    return !line.ok() && line.error().code == ErrorCode::kTimeout;
  }

  std::filesystem::path path_;
  std::optional<topology::ControlServer> server_;
  std::optional<topology::ControlConnection> client_;
};

TEST_F(ControlSubscribeTest, PushesEachChangeOnceAndNothingWithoutOne) {
  ASSERT_TRUE(client_
                  ->sendLine(R"({"op":"subscribe","slave":"DO1","entry":"Output 8"})",
                             std::chrono::milliseconds(200))
                  .ok());
  serve();
  json first = next();
  EXPECT_EQ(first["ok"], true) << first.dump();
  EXPECT_EQ(first["subscribed"], "DO1.Output 8");
  EXPECT_EQ(first["value"], 0);
  serve();
  EXPECT_TRUE(nothingMore());  // no change, no line
  auto* od = slavesim::objectDictionaryOf(slave("DO1"));
  ASSERT_TRUE(od->set<bool>(0x7000, 8, true).ok());
  serve();
  json pushed = next();
  EXPECT_EQ(pushed["event"], "change") << pushed.dump();
  EXPECT_EQ(pushed["name"], "DO1.Output 8");
  EXPECT_EQ(pushed["value"], 1);
  serve();
  EXPECT_TRUE(nothingMore());  // told once
  // Two changes between two batches: only the newest value is pushed.
  ASSERT_TRUE(od->set<bool>(0x7000, 8, false).ok());
  ASSERT_TRUE(od->set<bool>(0x7000, 8, true).ok());
  serve();
  EXPECT_TRUE(nothingMore());
  EXPECT_EQ(api_->subscriptions(), 1u);
  // A gone client's subscriptions are dropped.
  client_.reset();
  serve();
  serve();
  EXPECT_EQ(api_->subscriptions(), 0u);
}

TEST_F(ControlSubscribeTest, APushBeyondThePendingLimitIsRefused) {
  serve();  // accepts the client
  ASSERT_EQ(server_->clients(), 1u);
  // The client reads nothing: lines pile up until the pending-reply limit refuses more.
  const std::string line(1000, 'x');
  std::size_t accepted = 0;
  while (server_->push(1, line) && accepted < 10 * topology::kControlMaxPendingReply) ++accepted;
  EXPECT_LT(accepted, 10 * topology::kControlMaxPendingReply / line.size());
  EXPECT_FALSE(server_->push(1, line));
  EXPECT_FALSE(server_->push(99, line));  // no such client
}

}  // namespace
}  // namespace ecsim::tools
