#include "sim/cases/scene_fields.h"

#include <sys/stat.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "output/output_file.h"

namespace vmh::sim {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxIncludeDepth = 16;

struct Attribute {
  std::string name;
  std::string value;
};

class SceneReader {
 public:
  explicit SceneReader(const std::string& main_path)
      : main_dir_(fs::path(main_path).parent_path()) {}

  void read(const std::string& path, bool in_custom, int depth) {
    if (depth > kMaxIncludeDepth) {
      throw ParamError(path + ": includes nested more than " +
                       std::to_string(kMaxIncludeDepth) + " deep");
    }
    const std::string key = identity(path);
    for (const std::string& open : open_files_) {
      if (open == key) throw ParamError(path + ": includes itself (a cycle)");
    }
    open_files_.push_back(key);
    parse(load(path), path, in_custom, depth);
    open_files_.pop_back();
  }

  std::vector<CustomField> fields;
  SceneCensus census;

 private:
  // the file's identity for cycle detection: device and inode
  static std::string identity(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return path;
    return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  }

  // the file's text: a regular file only (a FIFO or a device would block
  // the read or never end), opened without blocking, within the bound
  std::string load(const std::string& path) {
    bool missing = false;
    std::string text;
    try {
      text = output::read_regular_file(path, kMaxSceneBytes - census.bytes, &missing);
    } catch (const std::runtime_error& e) {
      const bool size = std::string(e.what()).find("bound") != std::string::npos;
      throw ParamError(std::string(e.what()) +
                       (size && census.bytes > 0 ? " (a scene's files together are at most " +
                                               output::bytes_text(kMaxSceneBytes) + ")"
                                         : std::string()));
    }
    if (missing) throw ParamError(path + ": no such file");
    census.bytes += text.size();
    census.files.push_back(path);
    return text;
  }

  [[noreturn]] static void fail(const std::string& path, const std::string& text,
                                std::size_t pos, const std::string& why) {
    int line = 1;
    for (std::size_t i = 0; i < pos && i < text.size(); ++i) {
      if (text[i] == '\n') ++line;
    }
    throw ParamError(path + ": line " + std::to_string(line) + ": " + why);
  }

  static bool name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' ||
           c == '-' || c == '.';
  }

  // the five predefined entities and numeric references
  static std::string decode(const std::string& v, const std::string& path,
                            const std::string& text, std::size_t pos) {
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] != '&') {
        out += v[i];
        continue;
      }
      const std::size_t end = v.find(';', i);
      if (end == std::string::npos) fail(path, text, pos, "'&' without ';' in an attribute");
      const std::string e = v.substr(i + 1, end - i - 1);
      if (e == "amp") out += '&';
      else if (e == "lt") out += '<';
      else if (e == "gt") out += '>';
      else if (e == "quot") out += '"';
      else if (e == "apos") out += '\'';
      else if (e.size() > 1 && e[0] == '#') {
        const bool hex = e[1] == 'x';
        char* stop = nullptr;
        const long c = std::strtol(e.c_str() + (hex ? 2 : 1), &stop, hex ? 16 : 10);
        if (*stop != '\0' || c <= 0 || c > 127) {
          fail(path, text, pos, "character reference &" + e + "; is not ASCII");
        }
        out += static_cast<char>(c);
      } else {
        fail(path, text, pos, "unknown entity &" + e + ";");
      }
      i = end;
    }
    return out;
  }

  static const std::string* find(const std::vector<Attribute>& attrs,
                                 const char* name) {
    for (const Attribute& a : attrs) {
      if (a.name == name) return &a.value;
    }
    return nullptr;
  }

  void element(const std::string& name, const std::vector<Attribute>& attrs,
               bool in_custom, int depth, const std::string& path,
               const std::string& text, std::size_t pos) {
    if (name == "body") ++census.bodies;
    if (name == "mesh" || name == "texture" || name == "hfield" || name == "skin") {
      if (const std::string* file = find(attrs, "file"); file != nullptr && !file->empty()) {
        census.assets.push_back(*file);
      }
    }
    if (name == "compiler") {
      for (const char* dir : {"meshdir", "texturedir", "assetdir"}) {
        if (const std::string* d = find(attrs, dir)) census.asset_dirs.push_back(*d);
      }
    }
    if (name == "include") {
      const std::string* file = find(attrs, "file");
      if (file == nullptr || file->empty()) {
        fail(path, text, pos, "<include> without a file");
      }
      const fs::path p = fs::path(*file).is_absolute() ? fs::path(*file)
                                                      : main_dir_ / *file;
      // a refusal inside the included file names the file that included
      // it and where, up to the scene given: an absolute include may lie
      // anywhere, and its name alone does not say which scene failed
      try {
        read(p.string(), in_custom, depth + 1);
      } catch (const ParamError& e) {
        fail(path, text, pos, "<include file=\"" + *file + "\">: " + e.what());
      }
      return;
    }
    if (!in_custom || (name != "numeric" && name != "text")) return;
    const std::string* field = find(attrs, "name");
    if (field == nullptr || field->empty()) {
      fail(path, text, pos, "<" + name + "> without a name");
    }
    CustomField f;
    f.name = *field;
    f.is_text = name == "text";
    const std::string* data = find(attrs, "data");
    if (f.is_text) {
      if (data == nullptr) fail(path, text, pos, "<text name=\"" + f.name + "\"> without data");
      f.value = *data;
      fields.push_back(std::move(f));
      return;
    }
    std::vector<std::string> numbers;
    if (data != nullptr) {
      std::istringstream in(*data);
      std::string n;
      while (in >> n) numbers.push_back(n);
    }
    const std::string* size_text = find(attrs, "size");
    std::size_t size = numbers.size();
    if (size_text != nullptr) {
      char* stop = nullptr;
      const long s = std::strtol(size_text->c_str(), &stop, 10);
      if (size_text->empty() || *stop != '\0' || s < 0 || s > 1000000) {
        fail(path, text, pos, "<numeric name=\"" + f.name + "\"> size '" +
                                  *size_text + "' is not a count");
      }
      if (numbers.size() > static_cast<std::size_t>(s)) {
        fail(path, text, pos, "<numeric name=\"" + f.name +
                                  "\"> has more data than its size");
      }
      size = static_cast<std::size_t>(s);
    } else if (data == nullptr) {
      fail(path, text, pos, "<numeric name=\"" + f.name + "\"> has neither data nor size");
    }
    if (size == 0) return;  // no values: as if not given
    while (numbers.size() < size) numbers.push_back("0");
    for (const std::string& n : numbers) f.value += n + " ";
    fields.push_back(std::move(f));
  }

  // Where parse() is in one file: its text, its path (for errors) and
  // the position in the text
  struct Cursor {
    const std::string& text;
    const std::string& path;
    std::size_t i = 0;

    void skip_space() {
      while (i < text.size() &&
             std::isspace(static_cast<unsigned char>(text[i])))
        ++i;
    }
  };

  // Steps over a comment or a processing instruction at c->i (true);
  // refuses a DTD or CDATA; false at anything else
  static bool skip_markup(Cursor* c) {
    const std::string& text = c->text;
    const std::string& path = c->path;
    std::size_t& i = c->i;
    if (text.compare(i, 4, "<!--") == 0) {
      const std::size_t end = text.find("-->", i + 4);
      if (end == std::string::npos)
        fail(path, text, i, "a comment is not closed");
      i = end + 3;
      return true;
    }
    if (text.compare(i, 2, "<?") == 0) {
      const std::size_t end = text.find("?>", i + 2);
      if (end == std::string::npos) fail(path, text, i, "'<?' is not closed");
      i = end + 2;
      return true;
    }
    if (text.compare(i, 2, "<!") == 0) {
      fail(path, text, i, "DTDs and CDATA are not MJCF");
    }
    return false;
  }

  // The closing tag at c->i, which must close the innermost open element
  // (the top of *stack, popped)
  static void close_element(Cursor* c, std::vector<std::string>* stack,
                            int* custom_open) {
    const std::string& text = c->text;
    const std::string& path = c->path;
    std::size_t& i = c->i;
    i += 2;
    const std::size_t start = i;
    while (i < text.size() && name_char(text[i])) ++i;
    const std::string name = text.substr(start, i - start);
    c->skip_space();
    if (i >= text.size() || text[i] != '>')
      fail(path, text, start, "bad closing tag");
    ++i;
    if (stack->empty() || stack->back() != name) {
      fail(path, text, start,
           "</" + name + "> closes " +
               (stack->empty() ? "nothing" : "<" + stack->back() + ">"));
    }
    if (name == "custom") --*custom_open;
    stack->pop_back();
  }

  // One attribute name="value" (or 'value') at c->i of the element
  // `name`, its value decoded; refused when attrs has it already
  static Attribute attribute(Cursor* c, const std::string& name,
                             const std::vector<Attribute>& attrs) {
    const std::string& text = c->text;
    const std::string& path = c->path;
    std::size_t& i = c->i;
    const std::size_t a = i;
    while (i < text.size() && name_char(text[i])) ++i;
    if (i == a)
      fail(path, text, i,
           "unexpected '" + std::string(1, text[i]) + "' in <" + name + ">");
    Attribute attr;
    attr.name = text.substr(a, i - a);
    c->skip_space();
    if (i >= text.size() || text[i] != '=') {
      fail(path, text, a, "attribute '" + attr.name + "' without a value");
    }
    ++i;
    c->skip_space();
    if (i >= text.size() || (text[i] != '"' && text[i] != '\'')) {
      fail(path, text, a, "attribute '" + attr.name + "' is not quoted");
    }
    const char quote = text[i++];
    const std::size_t end = text.find(quote, i);
    if (end == std::string::npos)
      fail(path, text, a, "attribute '" + attr.name + "' is not closed");
    attr.value = decode(text.substr(i, end - i), path, text, a);
    i = end + 1;
    for (const Attribute& other : attrs) {
      if (other.name == attr.name)
        fail(path, text, a, "attribute '" + attr.name + "' given twice");
    }
    return attr;
  }

  // The attributes of the element `name` opened at `tag`, up to its '>',
  // or its '/>' (*self_closing)
  static std::vector<Attribute> attributes(Cursor* c, const std::string& name,
                                           std::size_t tag,
                                           bool* self_closing) {
    const std::string& text = c->text;
    std::size_t& i = c->i;
    std::vector<Attribute> attrs;
    while (true) {
      c->skip_space();
      if (i >= text.size())
        fail(c->path, text, tag, "<" + name + "> is not closed");
      if (text[i] == '>') {
        ++i;
        break;
      }
      if (text.compare(i, 2, "/>") == 0) {
        i += 2;
        *self_closing = true;
        break;
      }
      attrs.push_back(attribute(c, name, attrs));
    }
    return attrs;
  }

  void parse(const std::string& text, const std::string& path,
             bool base_in_custom, int depth) {
    Cursor c{text, path};
    std::size_t& i = c.i;
    std::vector<std::string> stack;
    int custom_open = 0;
    while (true) {
      const std::size_t lt = text.find('<', i);
      if (lt == std::string::npos) break;
      i = lt;
      if (skip_markup(&c)) continue;
      if (text.compare(i, 2, "</") == 0) {
        close_element(&c, &stack, &custom_open);
        continue;
      }
      const std::size_t tag = i;
      ++i;
      const std::size_t start = i;
      while (i < text.size() && name_char(text[i])) ++i;
      const std::string name = text.substr(start, i - start);
      if (name.empty()) fail(path, text, tag, "'<' without an element name");
      bool self_closing = false;
      const std::vector<Attribute> attrs =
          attributes(&c, name, tag, &self_closing);
      element(name, attrs, base_in_custom || custom_open > 0, depth, path, text,
              tag);
      if (!self_closing) {
        stack.push_back(name);
        if (name == "custom") ++custom_open;
      }
    }
    if (!stack.empty())
      fail(path, text, text.size(), "<" + stack.back() + "> is not closed");
  }

  fs::path main_dir_;
  std::vector<std::string> open_files_;
};

}  // namespace

SceneCensus scan_scene(const std::string& scene_path) {
  SceneReader reader(scene_path);
  reader.read(scene_path, false, 0);
  return std::move(reader.census);
}

std::vector<CustomField> read_scene_fields(const std::string& scene_path) {
  SceneReader reader(scene_path);
  reader.read(scene_path, false, 0);
  return std::move(reader.fields);
}

CaseParams load_scene_params(const std::string& scene_path,
                             const std::vector<std::string>& overrides) {
  return case_params_from_fields(read_scene_fields(scene_path), scene_path,
                                 overrides);
}

}  // namespace vmh::sim
