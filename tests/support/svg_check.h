// Checks on SVG documents the testbed writes (plot_svg, svg_chart), without
// an XML library: well-formedness to the extent these writers need, and
// counting.
#ifndef VMHAPTICS_TESTS_SUPPORT_SVG_CHECK_H_
#define VMHAPTICS_TESTS_SUPPORT_SVG_CHECK_H_

#include <cstddef>
#include <regex>
#include <string>
#include <vector>

namespace vmh::testing {

// "" when every element is closed in order under one <svg> root, attribute
// quotes pair up, and text holds no raw '<', '>' or bare '&'; else what is
// wrong.
inline std::string tag_problems(const std::string& s) {
  static const std::regex kEntity(R"(^&(amp|lt|gt|quot|apos|#[0-9]+);)");
  std::vector<std::string> open;
  bool root_done = false;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t lt = s.find('<', i);
    const std::string text = s.substr(i, lt == std::string::npos ? std::string::npos : lt - i);
    if (text.find('>') != std::string::npos) return "raw '>' in text near " + std::to_string(i);
    for (std::size_t a = text.find('&'); a != std::string::npos; a = text.find('&', a + 1)) {
      if (!std::regex_search(text.substr(a, 10), kEntity)) {
        return "bare '&' near " + std::to_string(i + a);
      }
    }
    if (open.empty() && root_done && text.find_first_not_of(" \n") != std::string::npos) {
      return "text after the root element";
    }
    if (lt == std::string::npos) break;
    const std::size_t gt = s.find('>', lt);
    if (gt == std::string::npos) return "unclosed '<' at " + std::to_string(lt);
    const std::string tag = s.substr(lt + 1, gt - lt - 1);
    if (tag.find('<') != std::string::npos) return "'<' inside a tag at " + std::to_string(lt);
    std::size_t quotes = 0;
    for (char c : tag) quotes += c == '"' ? 1 : 0;
    if (quotes % 2 != 0) return "unpaired quote in <" + tag + ">";
    if (tag.empty()) return "empty tag at " + std::to_string(lt);
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (open.empty() || open.back() != name) {
        return "</" + name + "> closes " + (open.empty() ? "nothing" : "<" + open.back() + ">");
      }
      open.pop_back();
      if (open.empty()) root_done = true;
    } else {
      const std::string name = tag.substr(0, tag.find_first_of(" \n/"));
      if (open.empty() && (root_done || name != "svg")) return "root is not one <svg>";
      if (tag.back() != '/') open.push_back(name);
    }
    i = gt + 1;
  }
  if (!open.empty()) return "<" + open.back() + "> never closed";
  if (!root_done) return "no root element";
  return "";
}

inline std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_SVG_CHECK_H_
