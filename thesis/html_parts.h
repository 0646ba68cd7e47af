// The page's building blocks that know nothing of cases or studies: a
// file read back from an earlier run, base64, an SVG made ready to sit
// inside HTML, and the check for what an SVG holds that the page does not
// carry. Used by thesis/report_html.
#ifndef VMHAPTICS_THESIS_HTML_PARTS_H_
#define VMHAPTICS_THESIS_HTML_PARTS_H_

#include <cstdint>
#include <string>

namespace vmh::thesis {

// A whole file's bytes, "" when there is no file. Only a regular file of
// at most kMaxReusedFileBytes is read (opened without blocking): anything
// else throws std::runtime_error naming it (a FIFO, a device, its size).
inline constexpr std::uint64_t kMaxReusedFileBytes = std::uint64_t{1} << 30;
std::string read_file_text(const std::string& path);

// RFC 4648 base64, with padding
std::string base64(const std::string& bytes);

// An SVG document ready to sit inside HTML: any XML prolog or DOCTYPE before
// the <svg> element dropped, and, with a non-empty `id_prefix`, every id it
// defines and every reference to one (url(#x), href="#x") prefixed, so that
// figures inlined in one page cannot share an id. (Two figures that each
// define id="plot-clip" would otherwise both be clipped by the first
// definition's rectangle, and lose points: issue 31.)
std::string inline_svg(const std::string& svg_document,
                       const std::string& id_prefix = "");

// What in an SVG would run or load something on the page, "" if nothing:
// a <script>, an element that embeds a document (foreignObject, iframe,
// object, embed), an event handler attribute (onload=, onclick=, ...) or
// a javascript: link. The project's SVG writers make none of these; an SVG
// read back from a folder (report --reuse) may hold any, and the page
// promises no scripts.
std::string active_content(const std::string& svg);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_HTML_PARTS_H_
