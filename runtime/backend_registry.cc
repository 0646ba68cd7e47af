#include "runtime/backend_registry.h"

#include <algorithm>

namespace vmh::runtime {

std::string OpenRequest::option(const std::string& key) const {
  if (auto it = options.find(key); it != options.end()) return it->second;
  if (auto it = defaults.find(key); it != defaults.end()) return it->second;
  return {};
}

BackendRegistry& BackendRegistry::global() {
  static BackendRegistry registry;
  return registry;
}

void BackendRegistry::add(BackendInfo info) {
  if (info.name.empty() || !info.list || (!info.open && !info.probe)) {
    throw std::logic_error("BackendRegistry: backend '" + info.name +
                           "' needs a name, a list function and an open or "
                           "probe function");
  }
  if (find(info.name) != nullptr) {
    throw std::logic_error("BackendRegistry: backend '" + info.name +
                           "' registered twice");
  }
  backends_.push_back(std::move(info));
}

const BackendInfo* BackendRegistry::find(const std::string& name) const {
  for (const BackendInfo& b : backends_) {
    if (b.name == name) return &b;
  }
  return nullptr;
}

std::string BackendRegistry::grammars() const {
  std::string s;
  for (const BackendInfo& b : backends_) {
    s += (s.empty() ? "" : ", ") + b.grammar;
  }
  return s;
}

const BackendInfo& BackendRegistry::resolve(const std::string& spec,
                                            std::string* argument) const {
  const BackendInfo* best = nullptr;
  for (const BackendInfo& b : backends_) {
    const bool whole = spec == b.name;
    const bool prefix = spec.size() > b.name.size() &&
                        spec.compare(0, b.name.size(), b.name) == 0 &&
                        (spec[b.name.size()] == ':' || spec[b.name.size()] == '?');
    if ((whole || prefix) &&
        (best == nullptr || b.name.size() > best->name.size())) {
      best = &b;
    }
  }
  if (best == nullptr) {
    const std::string name = spec.substr(0, spec.find_first_of(":?"));
    throw RequestError("--device: unknown backend '" + name + "' (expected " +
                       grammars() +
                       "; `vmhaptics hw list` shows what is available)");
  }
  // NAME:ARGUMENT gives ARGUMENT; NAME?OPTIONS gives "?OPTIONS"
  *argument = spec.size() <= best->name.size() ? std::string()
              : spec[best->name.size()] == ':'
                  ? spec.substr(best->name.size() + 1)
                  : spec.substr(best->name.size());
  return *best;
}

OpenedDevice BackendRegistry::open(const std::string& spec,
                                   OpenRequest request, bool servo) const {
  std::string argument;
  const BackendInfo& b = resolve(spec, &argument);
  for (const auto& option : request.options) {
    const std::string& key = option.first;
    const bool takes = std::any_of(
        b.options.begin(), b.options.end(),
        [&](const BackendOption& o) { return o.key == key; });
    if (takes) continue;
    std::string who;
    for (const OptionUse& u : option_uses()) {
      if (u.key == key) who = u.backends;
    }
    throw RequestError("--" + key + ": " +
                       (who.empty() ? std::string("no backend takes it")
                                    : "only " + who + " take" +
                                          (who.find(',') == std::string::npos
                                               ? "s"
                                               : "") +
                                          " it") +
                       ", not --device " + spec);
  }
  if (servo && !b.servo) {
    throw RequestError("--device " + spec + ": " + b.summary +
                       "; it runs no servo loop (hw list, hw probe and hw "
                       "capture only)");
  }
  if (!b.open) {
    throw RequestError("--device " + spec + ": cannot be opened, only probed");
  }
  request.argument = argument;
  return b.open(request);
}

Json BackendRegistry::list() const {
  Json rows = Json::array();
  for (const BackendInfo& b : backends_) {
    Json row{{"name", b.name}, {"device", b.grammar}};
    Json more;
    try {
      more = b.list();
    } catch (const std::exception& e) {
      more = Json{{"available", false}, {"why_not", e.what()}};
    }
    for (auto it = more.begin(); it != more.end(); ++it) {
      row[it.key()] = it.value();
    }
    rows.push_back(std::move(row));
  }
  return Json{{"backends", rows}};
}

std::vector<BackendRegistry::OptionUse> BackendRegistry::option_uses() const {
  std::vector<OptionUse> uses;
  for (const BackendInfo& b : backends_) {
    for (const BackendOption& o : b.options) {
      auto it = std::find_if(uses.begin(), uses.end(),
                             [&](const OptionUse& u) { return u.key == o.key; });
      if (it == uses.end()) {
        uses.push_back({o.key, o.help, b.name});
      } else {
        it->backends += ", " + b.name;
      }
    }
  }
  return uses;
}

}  // namespace vmh::runtime
