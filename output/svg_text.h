// Helpers shared by the SVG writers (plot_svg.cc, svg_chart.cc): numbers as
// SVG wants them, XML escaping, and the step between an axis's ticks.
#ifndef VMHAPTICS_OUTPUT_SVG_TEXT_H_
#define VMHAPTICS_OUTPUT_SVG_TEXT_H_

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace vmh::output::svg {

// one number through printf's format f
inline std::string format(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// a pixel coordinate: two decimals, far below what a screen shows; a
// non-finite value is drawn at 0 rather than breaking the document
// (std::to_chars gives printf's "%.2f" text, C++17 [utility.to.chars], at
// a fraction of snprintf's cost: the figures have thousands of points)
inline std::string px(double v) {
  if (!std::isfinite(v)) v = 0.0;
  char buf[352];  // "%.2f" of the largest double: 309 digits and 3 more
  const std::to_chars_result r = std::to_chars(
      buf, buf + sizeof buf, v, std::chars_format::fixed, 2);
  std::string s(buf, r.ptr);
  if (s == "-0.00") s = "0.00";
  return s;
}

// text escaped for XML content and attribute values
inline std::string escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

// ` name="value"`, the value escaped
inline std::string attr(const char* name, const std::string& value) {
  return std::string(" ") + name + "=\"" + escape(value) + "\"";
}

// 1, 2, 2.5 or 5 x 10^k, the smallest giving at most about `ticks` steps
inline double nice_step(double span, double ticks) {
  if (!(span > 0.0) || !std::isfinite(span)) return 1.0;
  const double raw = span / ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0}) {
    if (m * mag >= raw * (1.0 - 1e-9)) return m * mag;
  }
  return 10.0 * mag;
}

}  // namespace vmh::output::svg

#endif  // VMHAPTICS_OUTPUT_SVG_TEXT_H_
