#include "runtime/trace_writer.h"

#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace vmh::runtime {
namespace {

constexpr const char* kXyz[] = {"x", "y", "z"};

// Powers of ten that doubles hold exactly (10^22 is the last).
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                             1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                             1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// printf's "%.9g" text of a finite, non-zero double whose nine significant
// digits a scaling by an exact power of ten finds without doubt; nullptr
// otherwise (the caller then asks std::to_chars).
//
// The nine digits are n = round(|v| 10^(8-e)), for the e that puts n in
// [1e8, 1e9) (C11 7.21.6.1: %g takes the exponent after rounding). 10^|8-e|
// is exact for |8-e| <= 22, so the scaled value carries one rounding, at
// most 1.2e-7 off below 1e9 (the digits' range): only a fraction within 1e-6 of
// one half could round the other way (or be a tie, which printf rounds to
// even), and those go to std::to_chars.
char* write_g9_fast(char* out, double v) {
  const double a = std::fabs(v);
  if (!(a >= 1e-14 && a < 1e30)) return nullptr;
  // a in [2^b, 2^(b+1)): floor(log10 a) is floor(b log10 2) or one more
  // (78913 / 2^18 is log10 2 to 6e-7, exact in the floor for |b| < 1000)
  std::uint64_t bits = 0;
  std::memcpy(&bits, &a, sizeof bits);
  const int b = static_cast<int>((bits >> 52) & 0x7ff) - 1023;
  int e = (b * 78913) >> 18;
  std::int64_t n = 0;
  for (int pass = 0; pass < 3; ++pass) {
    const int k = 8 - e;
    if (k > 22 || k < -22) return nullptr;
    const double x = k >= 0 ? a * kPow10[k] : a / kPow10[-k];
    if (!(x < 1e10)) return nullptr;
    const auto whole = static_cast<std::int64_t>(x);
    const double f = x - static_cast<double>(whole);
    if (f > 0.5 - 1e-6 && f < 0.5 + 1e-6) return nullptr;
    n = whole + (f > 0.5 ? 1 : 0);
    if (n >= 1000000000) {
      ++e;
    } else if (n < 100000000) {
      --e;
    } else {
      break;
    }
  }
  if (n < 100000000 || n >= 1000000000) return nullptr;
  char d[9];
  auto u = static_cast<std::uint32_t>(n);
  for (int i = 8; i >= 0; --i) {
    d[i] = static_cast<char>('0' + u % 10);
    u /= 10;
  }
  int last = 8;  // the last digit kept: %g drops trailing zeros
  while (last > 0 && d[last] == '0') --last;
  char* p = out;
  if (v < 0) *p++ = '-';
  if (e >= -4 && e < 9) {  // fixed
    if (e >= 0) {
      for (int i = 0; i <= e; ++i) *p++ = d[i];
      if (last > e) {
        *p++ = '.';
        for (int i = e + 1; i <= last; ++i) *p++ = d[i];
      }
    } else {
      *p++ = '0';
      *p++ = '.';
      for (int i = 0; i < -e - 1; ++i) *p++ = '0';
      for (int i = 0; i <= last; ++i) *p++ = d[i];
    }
    return p;
  }
  *p++ = d[0];  // scientific: d.ddd e+XX, two exponent digits at least
  if (last > 0) {
    *p++ = '.';
    for (int i = 1; i <= last; ++i) *p++ = d[i];
  }
  *p++ = 'e';
  *p++ = e < 0 ? '-' : '+';
  const int ae = e < 0 ? -e : e;
  if (ae >= 100) *p++ = static_cast<char>('0' + ae / 100);
  *p++ = static_cast<char>('0' + ae / 10 % 10);
  *p++ = static_cast<char>('0' + ae % 10);
  return p;
}

// printf's "%.9g" (and "%ld") text, character for character: most
// numbers by write_g9_fast() (39 ns a number against std::to_chars's 61 on
// the trace's magnitudes, whose numbers were a tenth of a case run's
// time), the rest (zeros, non-finite, extreme magnitudes, near-ties) by
// std::to_chars, which the C++17 standard defines to give printf's text
void put(std::string* s, double v) {
  char buf[32];
  char* end = write_g9_fast(buf, v);
  if (end == nullptr) {
    end = std::to_chars(buf, buf + sizeof buf - 1, v,
                        std::chars_format::general, 9).ptr;
  }
  *end = ',';
  s->append(buf, static_cast<std::size_t>(end - buf + 1));
}
void put_int(std::string* s, long v) {
  char buf[24];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf - 1, v);
  *r.ptr = ',';
  s->append(buf, static_cast<std::size_t>(r.ptr - buf + 1));
}
void put_text(std::string* s, const char* t) {
  *s += t;
  *s += ',';
}
template <typename V>
void put_n(std::string* s, const V& v, int n) {
  for (int i = 0; i < n; ++i) put(s, v[i]);
}

}  // namespace

std::string safety_flags_text(SafetyStatus s) {
  if (s == kSafetyOk) return "ok";
  std::string out;
  for (int i = 0; i < kSafetyFlagCount; ++i) {
    const SafetyStatus f = 1u << i;
    if (s & f) {
      if (!out.empty()) out += '|';
      out += safety_flag_name(f);
    }
  }
  return out;
}

double trace_bytes_bound(std::int64_t ticks, std::size_t columns) {
  return static_cast<double>(ticks) * static_cast<double>(columns) * 16.0;
}

std::vector<std::string> trace_columns(const TraceLayout& l) {
  std::vector<std::string> c = {"t_s", "period_s"};
  for (int i = 1; i <= 6; ++i) c.push_back("q" + std::to_string(i) + "_rad");
  for (const char* a : kXyz) c.push_back(std::string("p_") + a + "_mm");
  for (const char* a : kXyz) c.push_back(std::string("a_") + a);
  if (l.controller) {
    for (const char* v : {"theta_v_", "theta_r_"}) {
      for (int i = 1; i <= l.vm_dof; ++i) c.push_back(v + std::to_string(i));
    }
    for (const char* v : {"xv_", "xr_"}) {
      for (const char* a : kXyz) c.push_back(std::string(v) + a + "_mm");
    }
    for (int i = 1; i <= 6; ++i) {
      c.push_back("e_" + std::to_string(i) + (i <= 3 ? "_mm" : "_rad"));
    }
    for (int i = 1; i <= 6; ++i) {
      c.push_back("f_" + std::to_string(i) + (i <= 3 ? "_N" : "_Nmm"));
    }
    for (const char* a : kXyz) c.push_back(std::string("F_") + a + "_N");
  }
  for (int i = 1; i <= 3; ++i) c.push_back("tau_" + std::to_string(i) + "_Nm");
  for (int i = 1; i <= 3; ++i) {
    c.push_back("tau_sent_" + std::to_string(i) + "_Nm");
  }
  if (l.truth) {
    for (int i = 1; i <= 3; ++i) {
      c.push_back("tau_applied_" + std::to_string(i) + "_Nm");
    }
    for (const char* a : kXyz) c.push_back(std::string("hand_") + a + "_mm");
    for (const char* a : kXyz) c.push_back(std::string("hand_F_") + a + "_N");
  }
  if (l.controller) {
    c.push_back("d_path_mm");
    c.push_back("status");
  }
  if (!l.phases.empty()) c.push_back("phase");
  for (const char* n :
       {"read_error", "write_error", "safety", "safety_flags", "ramp_scale"}) {
    c.push_back(n);
  }
  if (l.present & kStateButtons) c.push_back("buttons");
  if (l.present & kStateInkwell) c.push_back("docked");
  if (l.present & kStateTransform) {
    for (const char* a : kXyz) c.push_back(std::string("dev_p_") + a + "_mm");
    for (int r = 1; r <= 3; ++r) {
      for (int k = 1; k <= 3; ++k) {
        c.push_back("dev_R_" + std::to_string(r) + std::to_string(k));
      }
    }
  }
  if (l.present & kStateVelocity) {
    for (const char* a : kXyz) c.push_back(std::string("dev_v_") + a + "_mm_s");
  }
  if (l.present & kStateJacobian) {
    for (int r = 1; r <= 6; ++r) {
      for (int k = 1; k <= 6; ++k) {
        c.push_back("dev_J_" + std::to_string(r) + std::to_string(k));
      }
    }
  }
  if (l.present & kStateEncoders) {
    for (int i = 1; i <= 3; ++i) c.push_back("enc_" + std::to_string(i));
  }
  if (l.present & kStatePots) {
    for (int i = 4; i <= 6; ++i) c.push_back("pot_" + std::to_string(i));
  }
  return c;
}

std::string trace_header(const TraceLayout& layout) {
  const std::vector<std::string> cols = trace_columns(layout);
  std::string s;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    s += cols[i];
    s += i + 1 < cols.size() ? ',' : '\n';
  }
  return s;
}

void append_trace_row(const TickRecord& r, const TraceLayout& l,
                      std::string* out) {
  std::string& s = *out;
  const double nan = std::nan("");
  put(&s, r.t_s);
  put(&s, r.period_s);
  put_n(&s, r.q_dh, 6);
  put_n(&s, r.p_mm, 3);
  put_n(&s, r.axis, 3);
  if (l.controller) {
    const ControlOutput& o = r.out;
    for (int i = 0; i < l.vm_dof; ++i) {
      put(&s, i < o.theta_v.size() ? o.theta_v[i] : 0.0);
    }
    for (int i = 0; i < l.vm_dof; ++i) {
      put(&s, i < o.theta_r.size() ? o.theta_r[i] : 0.0);
    }
    put_n(&s, o.x_v_mm, 3);
    put_n(&s, o.x_r_mm, 3);
    put_n(&s, o.e, 6);
    put_n(&s, o.f_motion, 6);
    put_n(&s, o.force_device_N, 3);
  }
  put_n(&s, r.tau_cmd_Nm, 3);
  put_n(&s, r.tau_sent_Nm, 3);
  if (l.truth) {
    if (r.has_truth) {
      put_n(&s, r.motor_torque_Nm, 3);
      put_n(&s, r.hand_target.p_mm, 3);
      put_n(&s, r.hand_force_N, 3);
    } else {
      for (int i = 0; i < 9; ++i) put(&s, nan);
    }
  }
  if (l.controller) {
    put(&s, r.d_path_mm);
    put_int(&s, static_cast<long>(r.out.status));
  }
  if (!l.phases.empty()) {
    const auto k = static_cast<std::size_t>(r.segment);
    put_text(&s, r.has_truth && r.segment >= 0 && k < l.phases.size()
                     ? l.phases[k].c_str()
                     : "");
  }
  put_text(&s, device_error_name(r.servo.read));
  put_text(&s, device_error_name(r.servo.write));
  put_int(&s, static_cast<long>(r.safety));
  put_text(&s, safety_flags_text(r.safety).c_str());
  put(&s, r.ramp_scale);
  const DeviceState& st = r.state;
  if (l.present & kStateButtons) put_int(&s, static_cast<long>(st.buttons));
  if (l.present & kStateInkwell) put_int(&s, st.docked ? 1 : 0);
  if (l.present & kStateTransform) {
    const bool has = st.has(kStateTransform);
    for (int i = 0; i < 3; ++i) put(&s, has ? st.transform_mm(i, 3) : nan);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) {
        put(&s, has ? st.transform_mm(row, col) : nan);
      }
    }
  }
  if (l.present & kStateVelocity) {
    const bool has = st.has(kStateVelocity);
    for (int i = 0; i < 3; ++i) put(&s, has ? st.velocity_mm_s[i] : nan);
  }
  if (l.present & kStateJacobian) {
    const bool has = st.has(kStateJacobian);
    for (int row = 0; row < 6; ++row) {
      for (int col = 0; col < 6; ++col) {
        put(&s, has ? st.jacobian(row, col) : nan);
      }
    }
  }
  if (l.present & kStateEncoders) {
    for (int i = 0; i < 3; ++i) put_int(&s, st.encoder_counts[static_cast<std::size_t>(i)]);
  }
  if (l.present & kStatePots) {
    for (int i = 0; i < 3; ++i) put_int(&s, st.gimbal_pots[static_cast<std::size_t>(i)]);
  }
  s.back() = '\n';
}

TraceWriter::TraceWriter(const std::string& path, std::string shown,
                         TraceLayout layout)
    : shown_(std::move(shown)), layout_(std::move(layout)) {
  f_ = std::fopen(path.c_str(), "wb");
  if (!f_) fail();
  buf_ = trace_header(layout_);
}

TraceWriter::~TraceWriter() {
  if (f_) std::fclose(f_);
}

void TraceWriter::add(const TickRecord& r) {
  append_trace_row(r, layout_, &buf_);
  if (buf_.size() >= kFlushBytes) flush();
}

void TraceWriter::flush() {
  if (!buf_.empty() &&
      (std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size() ||
       std::fflush(f_) != 0)) {
    fail();
  }
  buf_.clear();
}

void TraceWriter::close() {
  if (f_ == nullptr) return;
  flush();
  std::FILE* f = f_;
  f_ = nullptr;
  if (std::fclose(f) != 0) fail();
}

void TraceWriter::fail() const {
  throw std::runtime_error(shown_ + ": " + std::strerror(errno));
}

}  // namespace vmh::runtime
