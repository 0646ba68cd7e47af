// The one fault vocabulary (sim/fault_vocabulary.h): one table, one grammar,
// one parser for the sensor injector, the emulator, the FireWire packets
// and the seeded faults; every kind of the table has its effect where it is
// taken, and the help lists every kind.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "sim/emulator.h"
#include "sim/emulator_firewire.h"
#include "sim/fault_injector.h"
#include "sim/fault_vocabulary.h"

namespace vmh::sim {
namespace {

std::string refusal(const std::string& text, FaultLayer layer) {
  try {
    parse_faults(text, layer);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(FaultVocabulary, NamesAreUniqueWithinALayer) {
  for (FaultLayer layer :
       {kSensorFaults, kTransportFaults, kWireFaults, kSeededFaults}) {
    std::set<std::string> names;
    int n = 0;
    for (const FaultKind& k : fault_kinds()) {
      if (!(k.layers & layer)) continue;
      EXPECT_TRUE(names.insert(k.name).second) << k.name;
      EXPECT_NE(std::string(k.doc), "") << k.name;
      ++n;
    }
    EXPECT_GT(n, 0) << fault_layer_name(layer);
  }
}

// every kind of every layer parses and has its effect where it is taken
TEST(FaultVocabulary, EveryKindOfTheTableIsTakenWhereItBelongs) {
  for (const FaultKind& k : fault_kinds()) {
    if (k.layers & kSensorFaults) {
      SensorFaultKind kind = SensorFaultKind::kNone;
      EXPECT_TRUE(parse_sensor_fault_kind(k.name, &kind)) << k.name;
      EXPECT_NE(kind, SensorFaultKind::kNone) << k.name;
    }
    // an example item of the kind, its fields at mid-range values
    std::string item = k.name;
    if (k.timed) {
      item += "@1";
      for (const FaultField& f : k.fields) item += f.whole ? ":2" : ":0.5";
    } else if (!k.fields.empty()) {
      const auto open = item.find('<');
      item.replace(open, item.find('>') - open + 1, k.fields[0].whole ? "2" : "5");
    }
    if (k.layers & kTransportFaults) {
      const auto f = parse_emulator_faults(item);
      ASSERT_EQ(f.size(), 1u) << item;
      EXPECT_EQ(std::string(emulator_fault_name(f[0].kind)), k.name);
    }
    if (k.layers & kWireFaults) {
      const auto f = parse_wire_faults(item);
      ASSERT_EQ(f.size(), 1u) << item;
      EXPECT_EQ(std::string(wire_fault_name(f[0].kind)), k.name);
    }
    if (k.layers & kSeededFaults) {
      const SeededFaults f = parse_seeded_faults(item);
      ASSERT_EQ(f.items.size(), 1u) << item;
      EXPECT_EQ(f.items[0], item);
    }
  }
}

TEST(FaultVocabulary, RefusalsNameTheItemWhyAndTheKinds) {
  const std::string m = refusal("drop@1:5,fizz@1", kTransportFaults);
  EXPECT_NE(m.find("emulator fault 'fizz@1': unknown kind 'fizz'"),
            std::string::npos) << m;
  EXPECT_NE(m.find("drop@t:N"), std::string::npos) << m;
  EXPECT_NE(refusal("late@1:0.5:64", kWireFaults).find("[1, 63]"), std::string::npos);
  EXPECT_NE(refusal("unplug@1:0", kTransportFaults).find("duration_s '0' must be > 0"),
            std::string::npos);
  EXPECT_NE(refusal("stall@-1:1", kTransportFaults).find("at_s '-1' must be >= 0"),
            std::string::npos);
  EXPECT_NE(refusal("reset@1:2", kWireFaults).find("reset takes reset@t"),
            std::string::npos);
  EXPECT_NE(refusal("drop5", kTransportFaults).find("expected kind@at_s"),
            std::string::npos);
  EXPECT_NE(refusal("joint7_sign", kSeededFaults).find("N '7' must be a whole number in [1, 6]"),
            std::string::npos);
  EXPECT_NE(refusal("mass_x2,mass_x3", kSeededFaults).find("mass given twice"),
            std::string::npos);
  EXPECT_NE(refusal("torque_units_Nm,torque_units_mNm", kSeededFaults).find("twice"),
            std::string::npos);
  EXPECT_NE(refusal("joint1_sign,,gimbal_swap", kSeededFaults).find("empty item"),
            std::string::npos);
  // a kind of another layer is unknown here
  EXPECT_NE(refusal("loss@1:5", kTransportFaults).find("unknown kind 'loss'"),
            std::string::npos);
  EXPECT_NE(refusal("drop@1:5", kWireFaults).find("unknown kind 'drop'"),
            std::string::npos);
  EXPECT_EQ(refusal("", kSeededFaults), "(accepted)");
  EXPECT_EQ(refusal(" , ", kWireFaults), "(accepted)");
}

TEST(FaultVocabulary, TheHelpListsEveryKindOfTheLayer) {
  for (FaultLayer layer : {kTransportFaults, kWireFaults, kSeededFaults}) {
    const std::string help = fault_help(layer);
    for (const FaultKind& k : fault_kinds()) {
      if (k.layers & layer) {
        EXPECT_NE(help.find(k.name), std::string::npos) << k.name;
      }
    }
  }
  EXPECT_EQ(fault_forms(kWireFaults),
            "loss@t:N, late@t:dur:K, length@t:N, reset@t, stall@t:dur, "
            "unplug@t:dur");
}

}  // namespace
}  // namespace vmh::sim
