// The device model's configuration tokens (fake_hd_device.h), shared by
// both models behind the test libHD.so.
#include <sstream>
#include <stdexcept>

#include "tests/hw/fake_libhd/fake_hd_device.h"

namespace vmh::fake_hd {

ModelTokens parse_model_tokens(const std::string& config) {
  ModelTokens m;
  std::stringstream in(config);
  std::string t;
  while (std::getline(in, t, ',')) {
    if (t.empty()) {
      continue;
    } else if (t == "docked") {
      m.docked = true;
    } else if (t == "button1") {
      m.buttons |= kButton1;
    } else if (t == "button2") {
      m.buttons |= kButton2;
    } else if (t == "tour") {
      m.tour = true;
    } else {
      throw std::invalid_argument("fake libHD: unknown configuration token \"" +
                                  t + "\"");
    }
  }
  return m;
}

}  // namespace vmh::fake_hd
