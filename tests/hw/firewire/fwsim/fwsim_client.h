// The stand-in's control functions (fwsim.h), taken from the libraw1394
// the transport loaded (the same library instance, so the same bus).
#ifndef VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_CLIENT_H_
#define VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_CLIENT_H_

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "hw/firewire/raw1394_library.h"
#include "tests/hw/firewire/fwsim/fwsim.h"

namespace vmh::testing {

class Fwsim {
 public:
  explicit Fwsim(const std::string& file)
      : lib_(hw::fw::Raw1394Library::load(file)) {
    take(configure, "fwsim_configure");
    take(last_error, "fwsim_last_error");
    take(now_ns, "fwsim_now_ns");
    take(advance_ns, "fwsim_advance_ns");
    take(bus_reset, "fwsim_bus_reset");
    take(node_info, "fwsim_get_node");
    take(set_encoder_speed, "fwsim_set_encoder_speed");
    take(set_docked, "fwsim_set_docked");
    take(attach_device, "fwsim_attach_device");
    take(eagain, "fwsim_eagain");
    take(eagain_count, "fwsim_eagain_count");
    take(underruns, "fwsim_underruns");
    take(log_size, "fwsim_log_size");
    take(log_entry, "fwsim_log_entry");
    take(log_clear, "fwsim_log_clear");
  }

  // configures the bus or throws naming what the stand-in refused
  void setup(const std::string& text) const {
    if (configure(text.c_str()) != 0) throw std::runtime_error(last_error());
  }
  fwsim_node_info info(std::uint64_t guid) const {
    fwsim_node_info i{};
    if (node_info(guid, &i) != 0) throw std::runtime_error("fwsim: no such node");
    return i;
  }
  std::vector<fwsim_transaction> log() const {
    std::vector<fwsim_transaction> out;
    for (long i = 0; i < log_size(); ++i) {
      fwsim_transaction t{};
      log_entry(i, &t);
      out.push_back(t);
    }
    return out;
  }
  void advance_ms(double ms) const {
    advance_ns(static_cast<std::int64_t>(ms * 1e6 + 0.5));
  }
  const std::string& file() const { return lib_->file(); }

  int (*configure)(const char*) = nullptr;
  const char* (*last_error)() = nullptr;
  std::int64_t (*now_ns)() = nullptr;
  void (*advance_ns)(std::int64_t) = nullptr;
  int (*bus_reset)(int) = nullptr;
  int (*node_info)(std::uint64_t, fwsim_node_info*) = nullptr;
  int (*set_encoder_speed)(std::uint64_t, double, double, double) = nullptr;
  int (*set_docked)(std::uint64_t, int) = nullptr;
  int (*attach_device)(std::uint64_t, const fwsim_device_ops*) = nullptr;
  void (*eagain)(int, int) = nullptr;
  long (*eagain_count)() = nullptr;
  long (*underruns)() = nullptr;
  long (*log_size)() = nullptr;
  int (*log_entry)(long, fwsim_transaction*) = nullptr;
  void (*log_clear)() = nullptr;

 private:
  template <typename F>
  void take(F& slot, const char* name) {
    void* p = lib_->symbol(name);
    if (p == nullptr) {
      throw std::runtime_error(lib_->file() + " has no " + name +
                               ": not the fwsim stand-in");
    }
    slot = reinterpret_cast<F>(p);
  }
  std::shared_ptr<const hw::fw::Raw1394Library> lib_;
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_CLIENT_H_
