#include "hw/served/served_region.h"

#include <cmath>
#include <cstring>

namespace vmh::hw::served {

const char* command_state_name(CommandState s) {
  switch (s) {
    case CommandState::kNone: return "none";
    case CommandState::kApplied: return "applied";
    case CommandState::kStale: return "stale";
  }
  return "unknown";
}

std::string served_name_error(const std::string& name) {
  if (name.empty()) return "a served name is empty";
  if (name.size() > kMaxNameLength) {
    return "a served name is at most " + std::to_string(kMaxNameLength) +
           " characters ('" + name.substr(0, 16) + "...' has " +
           std::to_string(name.size()) + ")";
  }
  if (name[0] == '.') return "a served name may not start with '.' ('" + name + "')";
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                    (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) {
      return "a served name takes letters, digits, '_', '-' and '.' only ('" +
             name + "')";
    }
  }
  return "";
}

std::string region_header_error(const void* bytes, std::size_t size) {
  if (bytes == nullptr || size < 16) {
    return "the shared-memory object is " + std::to_string(size) +
           " bytes, too small to be a served device";
  }
  std::uint64_t magic = 0;
  std::uint32_t version = 0, region_size = 0;
  const auto* p = static_cast<const unsigned char*>(bytes);
  std::memcpy(&magic, p, 8);
  std::memcpy(&version, p + 8, 4);
  std::memcpy(&region_size, p + 12, 4);
  if (magic != kServedMagic) {
    return "not a vmhaptics served device (no magic number: the server is "
           "still starting, or the object is someone else's)";
  }
  if (version != kServedVersion) {
    return "served by a vmhaptics whose layout is version " +
           std::to_string(version) + "; this build reads version " +
           std::to_string(kServedVersion) + " (use one build for both sides)";
  }
  if (region_size != sizeof(ServedRegion) || size < sizeof(ServedRegion)) {
    return "the served region is " + std::to_string(region_size) + " bytes (object " +
           std::to_string(size) + "); this build's is " +
           std::to_string(sizeof(ServedRegion)) + " (use one build for both sides)";
  }
  return "";
}

Vec3 command_to_apply(const ServedCommand& c, double now_s, double watchdog_s,
                      CommandState* state) noexcept {
  if (c.count == 0) {
    *state = CommandState::kNone;
    return Vec3::Zero();
  }
  if (!c.tau_Nm.allFinite() || !std::isfinite(c.client_s) ||
      now_s - c.client_s > watchdog_s) {
    *state = CommandState::kStale;
    return Vec3::Zero();
  }
  *state = CommandState::kApplied;
  return c.tau_Nm;
}

}  // namespace vmh::hw::served
