#include "thesis/html_parts.h"

#include <algorithm>
#include <cctype>

#include "output/output_file.h"

namespace vmh::thesis {

std::string read_file_text(const std::string& path) {
  // what --reuse reads is a file of an earlier run: a regular file, read
  // without blocking and within a bound (a FIFO or /dev/zero in its place
  // is refused, not waited on or read for ever)
  bool missing = false;
  std::string text = output::read_regular_file(path, kMaxReusedFileBytes, &missing);
  return missing ? std::string() : text;
}

std::string base64(const std::string& bytes) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16 |
                       static_cast<unsigned char>(bytes[i + 1]) << 8 |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 18; k >= 0; k -= 6) out += kAlphabet[(v >> k) & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string inline_svg(const std::string& svg_document,
                       const std::string& id_prefix) {
  const std::size_t start = svg_document.find("<svg");
  if (start == std::string::npos) return std::string();
  const std::string svg = svg_document.substr(start);
  if (id_prefix.empty()) return svg;
  // the three forms the project's SVG writers use: an attribute id="x"
  // (after white space, so that data-id= and the like are left alone), a
  // paint or clip reference url(#x), and a link href="#x" / xlink:href="#x"
  std::string out;
  out.reserve(svg.size() + svg.size() / 20);
  std::size_t i = 0;
  while (i < svg.size()) {
    std::size_t skip = 0;
    if ((svg[i] == ' ' || svg[i] == '\n' || svg[i] == '\t') &&
        svg.compare(i + 1, 4, "id=\"") == 0) {
      skip = 5;
    } else if (svg.compare(i, 5, "url(#") == 0) {
      skip = 5;
    } else if (svg.compare(i, 7, "href=\"#") == 0) {
      skip = 7;
    }
    if (skip == 0) {
      out += svg[i++];
      continue;
    }
    out.append(svg, i, skip);
    out += id_prefix;
    i += skip;
  }
  return out;
}

std::string active_content(const std::string& svg) {
  std::string low(svg.size(), ' ');
  std::transform(svg.begin(), svg.end(), low.begin(), [](char ch) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  });
  for (const char* tag : {"<script", "<foreignobject", "<iframe", "<object",
                          "<embed", "javascript:"}) {
    if (low.find(tag) != std::string::npos) {
      return tag[0] == '<' ? std::string("a ") + tag + "> element"
                           : std::string("a javascript: link");
    }
  }
  // on...= after white space: an event handler attribute
  for (std::size_t i = low.find("on"); i != std::string::npos;
       i = low.find("on", i + 2)) {
    if (i == 0 || !std::isspace(static_cast<unsigned char>(low[i - 1]))) continue;
    std::size_t k = i + 2;
    while (k < low.size() && std::isalpha(static_cast<unsigned char>(low[k]))) ++k;
    while (k < low.size() && std::isspace(static_cast<unsigned char>(low[k]))) ++k;
    if (k > i + 2 && k < low.size() && low[k] == '=') {
      return "an event handler (" + svg.substr(i, k - i) + "=)";
    }
  }
  return "";
}

}  // namespace vmh::thesis
