// The libraw1394 transport on a machine without FireWire: opening fails
// with a one-line cause, listing finds nothing and says why. Skipped (with
// the reason) where an adapter is present, and where libraw1394 was not
// found at build time.
#include <gtest/gtest.h>

#include <glob.h>

#include <string>

#include "device/device_backend.h"

#ifdef VMH_HAVE_RAW1394
#include "hw/firewire/raw1394_transport.h"
#endif

namespace {

#ifdef VMH_HAVE_RAW1394

using namespace vmh::hw::fw;  // NOLINT

// /dev/fw* nodes: one per adapter and per remote node
int dev_fw_nodes() {
  glob_t g{};
  const int rc = glob("/dev/fw[0-9]*", 0, nullptr, &g);
  const int n = rc == 0 ? static_cast<int>(g.gl_pathc) : 0;
  globfree(&g);
  return n;
}

TEST(FirewireRaw1394, OpeningWithoutAnAdapterNamesTheCause) {
  if (dev_fw_nodes() > 0) {
    GTEST_SKIP() << "this machine has /dev/fw* (a FireWire adapter): the "
                    "no-adapter messages cannot be checked here";
  }
  try {
    Raw1394Transport t;
    ADD_FAILURE() << "opened a FireWire transport with no adapter";
  } catch (const vmh::DeviceOpenError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("firewire: ", 0), 0u) << m;
    EXPECT_NE(m.find("no IEEE 1394 adapter"), std::string::npos) << m;
    EXPECT_NE(m.find("0 ports"), std::string::npos) << m;
    EXPECT_NE(m.find("firewire-ohci"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
  }
  // with a GUID and a port asked for, the same cause
  Raw1394Options o;
  o.guid = 0x000b990000001234ull;
  o.port = 0;
  EXPECT_THROW(Raw1394Transport{o}, vmh::DeviceOpenError);
}

TEST(FirewireRaw1394, ListingWithoutAnAdapterIsEmptyWithAReason) {
  if (dev_fw_nodes() > 0) {
    GTEST_SKIP() << "this machine has /dev/fw* (a FireWire adapter)";
  }
  std::string why = "unchanged";
  const std::vector<NodeInfo> nodes = list_omni_nodes(&why);
  EXPECT_TRUE(nodes.empty());
  EXPECT_NE(why.find("no IEEE 1394 adapter"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  // a null reason is allowed
  EXPECT_TRUE(list_omni_nodes(nullptr).empty());
}

TEST(FirewireRaw1394, GuidText) {
  EXPECT_EQ(parse_guid("0x000b990012345678"), 0x000b990012345678ull);
  EXPECT_EQ(parse_guid("000B99ABCDEF0123"), 0x000b99abcdef0123ull);
  EXPECT_EQ(parse_guid("1f"), 0x1full);
  EXPECT_EQ(parse_guid("ffffffffffffffff"), ~0ull);
  EXPECT_THROW(parse_guid(""), std::invalid_argument);
  EXPECT_THROW(parse_guid("0x"), std::invalid_argument);
  EXPECT_THROW(parse_guid("12345678901234567"), std::invalid_argument);
  EXPECT_THROW(parse_guid("00zz"), std::invalid_argument);
  EXPECT_EQ(guid_text(0x000b990012345678ull), "000b990012345678");
  EXPECT_EQ(guid_text(0x1full), "000000000000001f");
}

TEST(FirewireRaw1394, UdevRulesFileIsNamed) {
  EXPECT_STREQ(kUdevRulesFile, "hw/udev/60-vmhaptics.rules");
}

#else

TEST(FirewireRaw1394, NotBuilt) {
  GTEST_SKIP() << "not built: libraw1394-dev missing (pkg-config libraw1394)";
}

#endif

}  // namespace
