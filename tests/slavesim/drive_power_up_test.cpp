// Power-up values a vendor's ESI leaves out: a dictionary object without a default reads 0, and
// for the following error window 0x6065 that would make every count of deviation a following
// error (0x8611) the moment a master enables the drive (Copley's XE2 ESI gives 0x6065 no
// default; its CSP move through SOEM faulted at once). A drive ships with a window, so 0 at
// power-up is taken as unset (ecsim's 10000 counts); 0xFFFFFFFF still switches the check off
// (CiA 402-2 0x6065) and a value the ESI gives stays.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/esi_variant.hpp"
#include "tests/slavesim/one_slave_topology.hpp"

namespace ecsim::testing {
namespace {

class DrivePowerUp : public OneSlaveTopology {
 protected:
  std::uint32_t windowWith(const std::string& esiDefault) {
    EsiVariant v;
    v.replacements = {
        {"<Name>Following error window</Name>\n                <Type>UDINT</Type>\n"
         "                <BitSize>32</BitSize>\n"
         "                <Info><DefaultValue>10000</DefaultValue></Info>",
         "<Name>Following error window</Name>\n                <Type>UDINT</Type>\n"
         "                <BitSize>32</BitSize>\n"
         "                <Info><DefaultValue>" +
             esiDefault + "</DefaultValue></Info>"}};
    const auto esi = writeEcs7201Variant(dir_ / "drives.xml", v);
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"t\">\n  <Slave name=\"Axis\" esi=\"" << esi.string()
                        << "\" product=\"" << kEcs7201 << "\"/>\n</Topology>\n";
    auto net = build(path);
    EXPECT_TRUE(net.ok()) << (net.ok() ? "" : net.error().message());
    if (!net.ok()) return 1;
    auto* od = slavesim::objectDictionaryOf(net->segment->slave(0));
    return *od->get<std::uint32_t>(0x6065, 0);
  }
};

TEST_F(DrivePowerUp, AFollowingErrorWindowOfZeroIsTakenAsUnset) {
  EXPECT_EQ(windowWith("0"), 10000u);
  EXPECT_EQ(windowWith("#xFFFFFFFF"), 0xFFFFFFFFu) << "the check stays off";
  EXPECT_EQ(windowWith("2500"), 2500u) << "the ESI's value stays";
}

}  // namespace
}  // namespace ecsim::testing
