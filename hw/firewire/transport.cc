#include "hw/firewire/transport.h"

namespace vmh::hw::fw {

const char* transport_status_name(TransportStatus s) noexcept {
  switch (s) {
    case TransportStatus::kOk: return "ok";
    case TransportStatus::kTimeout: return "timeout";
    case TransportStatus::kBusReset: return "bus_reset";
    case TransportStatus::kDisconnected: return "disconnected";
    case TransportStatus::kIo: return "io";
    case TransportStatus::kBadPacket: return "bad_packet";
  }
  return "unknown";
}

}  // namespace vmh::hw::fw
