#include "sim/case_config.h"

#include <sstream>

#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

// Every custom field of the scene must be one the table knows, under the tag
// of its kind: a number written as <text> (or a word as <numeric>) would
// otherwise be skipped and its default used without a word.
void check_custom_tags(const mjModel* m, const std::string& source) {
  auto check = [&](const char* name, bool as_text) {
    const ParamSpec* f = find_param(name);
    if (f == nullptr) {
      throw SimError(source + ": unknown <custom> field '" + name +
                     "' (known: " + param_names() + ")");
    }
    if (f->is_text != as_text) {
      throw SimError(source + ": <custom> field '" + name + "' must be a <" +
                     (f->is_text ? "text" : "numeric") + ">, not a <" +
                     (as_text ? "text" : "numeric") + ">");
    }
  };
  for (int i = 0; i < m->nnumeric; ++i) {
    check(m->names + m->name_numericadr[i], false);
  }
  for (int i = 0; i < m->ntext; ++i) {
    check(m->names + m->name_textadr[i], true);
  }
}

// The scene's values of the table's parameters, as text (numbers to full
// precision), in table order.
std::vector<ParamInput> scene_inputs(const mjModel* m,
                                     const std::string& source) {
  std::vector<ParamInput> inputs;
  for (const ParamSpec& f : case_fields()) {
    if (f.is_text) {
      const char* t = custom_text(m, f.name);
      if (t != nullptr) {
        inputs.push_back({f.name, t, ValueSource::kScene, source});
      }
      continue;
    }
    const std::vector<double> v = custom_numeric(m, f.name);
    if (v.empty()) continue;
    std::ostringstream s;
    s.precision(17);
    for (double x : v) s << x << ' ';
    inputs.push_back({f.name, s.str(), ValueSource::kScene, source});
  }
  return inputs;
}

}  // namespace

CaseConfig CaseConfig::from_model(const mjModel* m, const std::string& source,
                                  const std::vector<std::string>& overrides) {
  try {
    check_custom_tags(m, source);
    std::vector<ParamInput> inputs = scene_inputs(m, source);
    for (ParamInput& set : set_inputs(overrides)) {
      inputs.push_back(std::move(set));
    }
    CaseConfig c;
    static_cast<CaseParams&>(c) = load_case_params(source, inputs);
    return c;
  } catch (const ParamError& e) {
    throw SimError(e.what());
  }
}

}  // namespace vmh::sim
