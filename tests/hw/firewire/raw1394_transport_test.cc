// The libraw1394 transport's edges: loading the library (the stand-in by
// path, a missing file, a file without libraw1394's symbols), an empty
// bus, the real libraw1394 on a machine without FireWire (skipped where an
// adapter is present or the library is not installed), and the text of
// GUIDs and serial numbers. The bus itself: raw1394_bus_test.cc.
#include <gtest/gtest.h>

#include <glob.h>

#include <string>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_library.h"
#include "hw/firewire/raw1394_transport.h"

namespace {

using namespace vmh::hw::fw;  // NOLINT

// /dev/fw* nodes: one per adapter and per remote node
int dev_fw_nodes() {
  glob_t g{};
  const int rc = glob("/dev/fw[0-9]*", 0, nullptr, &g);
  const int n = rc == 0 ? static_cast<int>(g.gl_pathc) : 0;
  globfree(&g);
  return n;
}

bool real_library_loads() {
  try {
    Raw1394Library::load(Raw1394Library::kDefaultName);
    return true;
  } catch (const vmh::DeviceOpenError&) {
    return false;
  }
}

std::string open_error(const Raw1394Options& o) {
  try {
    Raw1394Transport t(o);
  } catch (const vmh::DeviceOpenError& e) {
    return e.what();
  }
  return "";
}

TEST(FirewireRaw1394, OpeningWithoutAnAdapterNamesTheCause) {
  if (dev_fw_nodes() > 0) {
    GTEST_SKIP() << "this machine has /dev/fw* (a FireWire adapter): the "
                    "no-adapter messages cannot be checked here";
  }
  if (!real_library_loads()) GTEST_SKIP() << "libraw1394.so.11 is not installed";
  Raw1394Options o;
  o.library = Raw1394Library::kDefaultName;
  const std::string m = open_error(o);
  EXPECT_EQ(m.rfind("firewire: ", 0), 0u) << m;
  EXPECT_NE(m.find("no IEEE 1394 adapter"), std::string::npos) << m;
  EXPECT_NE(m.find("0 ports"), std::string::npos) << m;
  EXPECT_NE(m.find("firewire-ohci"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
  // with a GUID and a port asked for, the same cause
  o.guid = 0x000b990000001234ull;
  o.port = 0;
  EXPECT_NE(open_error(o).find("no IEEE 1394 adapter"), std::string::npos);
}

TEST(FirewireRaw1394, ListingWithoutAnAdapterIsEmptyWithAReason) {
  if (dev_fw_nodes() > 0) {
    GTEST_SKIP() << "this machine has /dev/fw* (a FireWire adapter)";
  }
  if (!real_library_loads()) GTEST_SKIP() << "libraw1394.so.11 is not installed";
  Raw1394Options o;
  o.library = Raw1394Library::kDefaultName;
  std::string why = "unchanged";
  const std::vector<NodeInfo> nodes = list_omni_nodes(&why, o);
  EXPECT_TRUE(nodes.empty());
  EXPECT_NE(why.find("no IEEE 1394 adapter"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  // a null reason is allowed
  EXPECT_TRUE(list_omni_nodes(nullptr, o).empty());
}

TEST(FirewireRaw1394, AnEmptyBusHasNoPorts) {
  // the stand-in with no port configured: zero ports, as a machine with no
  // adapter; the cause names the adapter (or its absence)
  Raw1394Options o;
  o.library = VMH_FWSIM_LIBRARY;
  auto lib = Raw1394Library::load(o.library);
  using Configure = int (*)(const char*);
  const auto configure = reinterpret_cast<Configure>(lib->symbol("fwsim_configure"));
  ASSERT_NE(configure, nullptr);
  ASSERT_EQ(configure(""), 0);
  std::string why;
  EXPECT_TRUE(list_omni_nodes(&why, o).empty());
  EXPECT_NE(why.find("adapter"), std::string::npos) << why;
  EXPECT_NE(open_error(o).find("adapter"), std::string::npos);
}

TEST(FirewireRaw1394, ALibraryThatCannotBeLoadedIsNamed) {
  Raw1394Options o;
  o.library = "/nonexistent/libraw1394.so.11";
  const std::string m = open_error(o);
  EXPECT_EQ(m.rfind("firewire: cannot load /nonexistent/libraw1394.so.11: ", 0), 0u)
      << m;
  std::string why;
  EXPECT_TRUE(list_omni_nodes(&why, o).empty());
  EXPECT_EQ(why, m);
  // a shared library that is not libraw1394: the first missing symbol
  o.library = "libm.so.6";
  const std::string not_raw = open_error(o);
  EXPECT_NE(not_raw.find("has no symbol raw1394_new_handle"), std::string::npos)
      << not_raw;
}

TEST(FirewireRaw1394, TheEnvironmentVariableChoosesTheLibrary) {
  // VMH_LIBRAW1394 is an exact path; without it, the soname is searched
  unsetenv(Raw1394Library::kPathVariable);
  EXPECT_NE(Raw1394Library::describe_search().find("libraw1394.so.11 on the "
                                                   "loader's search path"),
            std::string::npos);
  setenv(Raw1394Library::kPathVariable, VMH_FWSIM_LIBRARY, 1);
  EXPECT_EQ(Raw1394Library::describe_search(),
            std::string("VMH_LIBRAW1394=") + VMH_FWSIM_LIBRARY);
  const auto lib = Raw1394Library::load();
  EXPECT_EQ(lib->file(), VMH_FWSIM_LIBRARY);
  EXPECT_NE(lib->symbol("fwsim_configure"), nullptr);
  // one instance a file: the same library again
  EXPECT_EQ(Raw1394Library::load(VMH_FWSIM_LIBRARY).get(), lib.get());
  unsetenv(Raw1394Library::kPathVariable);
}

TEST(FirewireRaw1394, OptionsAreValidated) {
  Raw1394Options o;
  o.library = VMH_FWSIM_LIBRARY;
  o.eagain_tries = 0;
  EXPECT_THROW(Raw1394Transport{o}, std::invalid_argument);
  o.eagain_tries = 3;
  o.late_after_s = 0.0;
  EXPECT_THROW(Raw1394Transport{o}, std::invalid_argument);
  o.late_after_s = 1e-3;
  o.eagain_delay_s = -1.0;
  EXPECT_THROW(Raw1394Transport{o}, std::invalid_argument);
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

TEST(FirewireRaw1394, SerialAsTheDriversUnpackIt) {
  // fields a..e packed by hand: 1 | 0 0000 0 | a=3 b=12 c=17 d=5 e=678 | 1
  const std::uint32_t q = 0x80000001u | (3u << 23) | (12u << 19) | (17u << 14) |
                          (5u << 11) | (678u << 1);
  EXPECT_EQ(serial_text(q), "31217500678");
  // the smallest and largest fields
  EXPECT_EQ(serial_text(0x80000001u), "00000000000");
  EXPECT_EQ(serial_text(0x83ffffffu), "71531701023");
  // a quadlet without the drivers' framing bits is not theirs: hex
  EXPECT_EQ(serial_text(0x0ed8a683u), "0x0ed8a683");
  EXPECT_EQ(serial_text(0x80000000u), "0x80000000");
  EXPECT_EQ(serial_text(0xc0000001u), "0xc0000001");
}

TEST(FirewireRaw1394, UdevRulesFileIsNamed) {
  EXPECT_STREQ(kUdevRulesFile, "hw/udev/60-vmhaptics.rules");
}

}  // namespace
