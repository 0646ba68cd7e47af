// The sensitivity study's plan: the table of what is uncertain, the sweep's
// points (one at a time and a Latin hypercube) and its shards. The runs of
// the points and the study are sensitivity_study.cc; the outputs (JSON,
// CSV, figure) sensitivity_output.cc; the partial files and their merge
// sensitivity_shards.cc.
#include "studies/sensitivity_study.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "output/parallel.h"
#include "sim/cases/case.h"
#include "sim/cases/case_params.h"
#include "sim/closed_loop.h"
#include "sim/omni_model_edit.h"
#include "thesis/claims.h"
#include "thesis/run_case.h"
#include "studies/study_numbers.h"

namespace vmh::studies {
namespace {

using detail::exact;

using sim::SimError;

SweepParameter row(const char* name, SweepKind kind, const char* field,
                   SweepScale scale, double low, double high,
                   const char* unit, const char* source) {
  SweepParameter p;
  p.name = name;
  p.kind = kind;
  p.field = field;
  p.scale = scale;
  p.low = low;
  p.high = high;
  p.unit = unit;
  p.source = source;
  return p;
}

// the value at u in [0, 1) of the parameter's range (samples)
SweepValue at_unit(const SweepParameter& p, double u) {
  SweepValue v;
  switch (p.scale) {
    case SweepScale::kLinear:
      v.number = p.low + u * (p.high - p.low);
      break;
    case SweepScale::kLog:
      v.number = p.low * std::pow(p.high / p.low, u);
      break;
    case SweepScale::kInteger: {
      const double n = p.high - p.low + 1.0;
      v.number = std::min(p.high, p.low + std::floor(u * n));
      break;
    }
    case SweepScale::kChoice: {
      const std::size_t n = p.choices.size();
      v.text = p.choices[std::min(n - 1, static_cast<std::size_t>(u * static_cast<double>(n)))];
      break;
    }
  }
  return v;
}

bool same(const SweepValue& a, const SweepValue& b) {
  return a.text == b.text && a.number == b.number;
}

// the one-at-a-time levels, ascending (choices in table order), the nominal
// left out
std::vector<SweepValue> levels(const SweepParameter& p, int count,
                               const SweepValue& nominal) {
  std::vector<SweepValue> out;
  if (p.scale == SweepScale::kChoice) {
    for (const std::string& c : p.choices) out.push_back({0.0, c});
  } else if (p.scale == SweepScale::kInteger) {
    if (count <= 2) {
      out = {{p.low, ""}, {p.high, ""}};
    } else {
      for (double x = p.low; x <= p.high; x += 1.0) out.push_back({x, ""});
    }
  } else {
    for (int i = 0; i < count; ++i) {
      const double u = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1);
      SweepValue v = at_unit(p, u);
      if (i == count - 1) v.number = p.high;  // exactly, not pow's rounding
      if (i == 0) v.number = p.low;
      out.push_back(v);
    }
  }
  std::vector<SweepValue> kept;
  for (const SweepValue& v : out) {
    if (!same(v, nominal)) kept.push_back(v);
  }
  return kept;
}

// mt19937_64 (the same sequence on every standard library) to [0, 1)
double unit_draw(std::mt19937_64* rng) {
  return static_cast<double>((*rng)() >> 11) * 0x1.0p-53;
}

// a Latin hypercube of `n` points in [0,1)^d: column j a permutation of the
// n strata with a uniform offset in each
std::vector<std::vector<double>> latin_hypercube(std::size_t n, std::size_t d,
                                                 std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<double>> u(n, std::vector<double>(d, 0.0));
  for (std::size_t j = 0; j < d; ++j) {
    std::vector<std::size_t> perm(n);
    for (std::size_t i = 0; i < n; ++i) perm[i] = i;
    for (std::size_t i = n; i > 1; --i) {  // Fisher-Yates
      const std::size_t k = static_cast<std::size_t>(rng() % i);
      std::swap(perm[i - 1], perm[k]);
    }
    for (std::size_t i = 0; i < n; ++i) {
      u[i][j] = (static_cast<double>(perm[i]) + unit_draw(&rng)) /
                static_cast<double>(n);
    }
  }
  return u;
}

void check_row(const SweepParameter& p) {
  const std::string where = "sensitivity parameter '" + p.name + "': ";
  if (p.scale == SweepScale::kChoice) {
    if (p.choices.empty()) throw SimError(where + "no choices");
    return;
  }
  if (!(std::isfinite(p.low) && std::isfinite(p.high) && p.low <= p.high)) {
    throw SimError(where + "needs finite low <= high");
  }
  if (p.scale == SweepScale::kLog && !(p.low > 0.0)) {
    throw SimError(where + "a logarithmic range needs low > 0");
  }
}

// 64-bit FNV-1a
std::string fnv1a_hex(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// whether h divides T (the loader's test, sim/closed_loop.cc)
bool divides(double h, double T) {
  const double n = std::round(T / h);
  return n >= 1.0 && std::abs(n * h - T) <= 1e-9 * T;
}

// the overrides and Omni scales of a point with `values`, against the
// case's nominal
void apply_values(const SweepPlan& plan, const SweepCase& c,
                  SweepPoint* point) {
  point->overrides = plan.options.overrides;
  for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
    const SweepParameter& p = plan.parameters[j];
    const SweepValue& v = point->values[j];
    if (same(v, c.nominal[j])) continue;
    switch (p.kind) {
      case SweepKind::kField:
        point->overrides.push_back(p.field + "=" + exact(v.number));
        if (p.field == "servo_period_s" && !divides(c.physics_step_s, v.number)) {
          // the scene's step must divide the period: the largest that does
          // below the scene's
          const double n = std::ceil(v.number / c.physics_step_s - 1e-9);
          point->overrides.push_back("physics_step_s=" +
                                     exact(v.number / std::max(1.0, n)));
        }
        break;
      case SweepKind::kFieldScale:  // plan_sweep scales the case's items
        break;
      case SweepKind::kOmniMass:
        point->omni_mass_scale = v.number;
        break;
      case SweepKind::kOmniFriction:
        point->omni_friction_scale = v.number;
        break;
      case SweepKind::kChoice:
        point->overrides.push_back(p.field + "=" + v.text);
        break;
    }
  }
}

}  // namespace

const char* point_kind_name(PointKind k) {
  switch (k) {
    case PointKind::kNominal: return "nominal";
    case PointKind::kOneAtATime: return "one_at_a_time";
    case PointKind::kSample: return "sample";
  }
  return "?";
}

const std::vector<SweepParameter>& sweep_parameters() {
  using K = SweepKind;
  using S = SweepScale;
  static const std::vector<SweepParameter> table = [] {
    std::vector<SweepParameter> t = {
        row("hand_k_pos_N_per_m", K::kField, "hand_k_pos_N_per_m", S::kLog,
            50, 400, "N/m",
            "a stylus in a pen grip reduced to one stage: 65, 88, 201 N/m "
            "along x, y, z, 49-353 over the 95% intervals (Fu & Cavusoglu "
            "2012, via a secondary table; docs/sources.md 10.1)"),
        row("hand_b_pos_Ns_per_m", K::kField, "hand_b_pos_Ns_per_m", S::kLog,
            2, 16, "N s/m",
            "the same reduction: 3.2-9.9 N s/m, about 2.5-16 over the "
            "intervals; Israr, Choi & Tan 2006 give 12.6-15.8 along a pen-"
            "held stylus (docs/sources.md 10.1)"),
        row("hand_mass_kg", K::kField, "hand_mass_kg", S::kLog, 0.1, 0.6,
            "kg",
            "mass coupled at the grip: 0.14-0.57 kg over the pen grip's "
            "intervals (Fu & Cavusoglu 2012); one trial of van Beek et al. "
            "2015 gives 0.554 (docs/sources.md 10, 10.1)"),
        row("hand_inertia_scale", K::kFieldScale, "hand_inertia_kgm2",
            S::kLog, 0.5, 2.0, "x",
            "estimate: the case's hand inertia halved to doubled, no "
            "pen-grip measurement found"),
        row("hand_k_rot_Nm_per_rad", K::kField, "hand_k_rot_Nm_per_rad",
            S::kLog, 0.05, 2.0, "N m/rad",
            "derived, not measured: roll of a pen grip 0.075-0.16, tilt "
            "0.4-0.6, a relaxed wrist 1.2-1.8 N m/rad (Formica et al. "
            "2012); docs/sources.md 10.1"),
        row("hand_b_rot_Nms_per_rad", K::kField, "hand_b_rot_Nms_per_rad",
            S::kLog, 0.005, 0.05, "N m s/rad",
            "estimate: a decade around the case's value; no measured "
            "rotational damping of a pen grip was found"),
        row("omni_mass_scale", K::kOmniMass, "", S::kLinear, 0.7, 1.3, "x",
            "every Omni link's mass and inertia x0.7-1.3: the model's "
            "masses are scaled from a PHANTOM Premium 1.5 model, not "
            "weighed (docs/sources.md 8)"),
        row("omni_friction_scale", K::kOmniFriction, "", S::kLinear, 0.0,
            2.0, "x",
            "the Omni joints' dry friction x0-2: none to twice the "
            "model's, which is estimated, not identified"),
        row("servo_period_s", K::kField, "servo_period_s", S::kLog, 0.0005,
            0.002, "s",
            "servo period 0.5-2 ms: OpenHaptics' 1 kHz scheduler and the "
            "rates a busy host or a slower loop reaches"),
        row("delay_ticks", K::kField, "delay_ticks", S::kInteger, 0, 3,
            "ticks",
            "ticks between a reading and its torque: none to the 3 a USB "
            "or FireWire round trip and a buffered write may add"),
    };
    SweepParameter limits = row(
        "torque_limits", K::kChoice, "torque_limits", S::kChoice, 0, 0, "-",
        "the motors' limits: the OpenHaptics samples' clamps (0.2, 0.35, "
        "0.2 N m) or those derived from the rated 3.3 N peak force");
    limits.choices = {"openhaptics_samples", "rated"};
    limits.optional = true;
    t.push_back(limits);
    return t;
  }();
  return table;
}

bool parse_shard(const std::string& text, int* k, int* n) {
  const auto slash = text.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == text.size()) {
    return false;
  }
  const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
  for (const std::string& s : {a, b}) {
    if (s.size() > 6) return false;
    for (char c : s) {
      if (c < '0' || c > '9') return false;
    }
  }
  *k = std::stoi(a);
  *n = std::stoi(b);
  return *k >= 1 && *n >= 1 && *k <= *n;
}

std::vector<std::size_t> shard_points(std::size_t points, int k, int n) {
  std::vector<std::size_t> out;
  if (k < 1 || n < 1 || k > n) return out;
  for (std::size_t i = static_cast<std::size_t>(k - 1); i < points;
       i += static_cast<std::size_t>(n)) {
    out.push_back(i);
  }
  return out;
}

namespace {

// The table swept: options.parameters or sweep_parameters(), each row
// checked; an optional row whose case field this build lacks goes into
// plan->omitted, a required one is an error.
void plan_parameters(const SweepOptions& options, SweepPlan* plan) {
  const std::vector<SweepParameter>& table =
      options.parameters.empty() ? sweep_parameters() : options.parameters;
  for (const SweepParameter& p : table) {
    check_row(p);
    if (!p.field.empty() && sim::find_param(p.field) == nullptr) {
      if (p.optional) {
        plan->omitted.push_back(p.name + ": the case table has no field '" +
                                p.field + "' in this build");
        continue;
      }
      throw SimError("sensitivity parameter '" + p.name +
                     "': no case field '" + p.field + "'");
    }
    plan->parameters.push_back(p);
  }
}

// A case by its name, with its nominal values read from the case as loaded
// with the overrides: a field's own value, 1 for a scale.
SweepCase plan_case(const std::string& name,
                    const std::vector<std::string>& overrides,
                    const std::vector<SweepParameter>& parameters) {
  SweepCase c;
  c.scene = sim::resolve_scene(name, &c.name);
  const sim::Case probe = sim::load_case(c.scene, overrides);
  c.physics_step_s = probe.physics_step_s();
  for (const SweepParameter& p : parameters) {
    SweepValue v;
    switch (p.kind) {
      case SweepKind::kField:
        v.number = probe.config().value(*sim::find_param(p.field)).numbers.at(0);
        break;
      case SweepKind::kChoice:
        v.text = probe.config().value(*sim::find_param(p.field)).text;
        break;
      default:
        v.number = 1.0;
    }
    c.nominal.push_back(v);
  }
  return c;
}

// Case by case: the nominal point, each parameter over its `count`
// one-at-a-time levels, and the Latin hypercube's `samples` points (the
// same unit draws for every case), numbered in that order.
void plan_points(int count, int samples, SweepPlan* plan) {
  const auto u = latin_hypercube(static_cast<std::size_t>(samples),
                                 plan->parameters.size(), plan->options.seed);
  for (std::size_t ci = 0; ci < plan->cases.size(); ++ci) {
    const SweepCase& c = plan->cases[ci];
    auto add = [&](PointKind kind, int parameter,
                   const std::vector<SweepValue>& values) {
      SweepPoint pt;
      pt.index = plan->points.size();
      pt.case_index = ci;
      pt.kind = kind;
      pt.parameter = parameter;
      pt.values = values;
      plan->points.push_back(pt);
    };
    add(PointKind::kNominal, -1, c.nominal);
    for (std::size_t j = 0; j < plan->parameters.size(); ++j) {
      for (const SweepValue& v : levels(plan->parameters[j], count, c.nominal[j])) {
        std::vector<SweepValue> values = c.nominal;
        values[j] = v;
        add(PointKind::kOneAtATime, static_cast<int>(j), values);
      }
    }
    for (const std::vector<double>& row_u : u) {
      std::vector<SweepValue> values;
      for (std::size_t j = 0; j < plan->parameters.size(); ++j) {
        values.push_back(at_unit(plan->parameters[j], row_u[j]));
      }
      add(PointKind::kSample, -1, values);
    }
  }
}

// Every point's overrides and Omni scales (apply_values), and for a scale
// of a vector field the case's items, as loaded, each times the value.
void plan_settings(SweepPlan* plan) {
  std::vector<std::vector<std::vector<double>>> scaled_items(plan->cases.size());
  for (std::size_t ci = 0; ci < plan->cases.size(); ++ci) {
    const sim::Case probe =
        sim::load_case(plan->cases[ci].scene, plan->options.overrides);
    for (const SweepParameter& p : plan->parameters) {
      scaled_items[ci].push_back(
          p.kind == SweepKind::kFieldScale
              ? probe.config().value(*sim::find_param(p.field)).numbers
              : std::vector<double>{});
    }
  }
  for (SweepPoint& pt : plan->points) {
    const SweepCase& c = plan->cases[pt.case_index];
    apply_values(*plan, c, &pt);
    for (std::size_t j = 0; j < plan->parameters.size(); ++j) {
      const SweepParameter& p = plan->parameters[j];
      if (p.kind != SweepKind::kFieldScale || same(pt.values[j], c.nominal[j])) {
        continue;
      }
      std::string items;
      for (double x : scaled_items[pt.case_index][j]) {
        items += (items.empty() ? "" : " ") + exact(x * pt.values[j].number);
      }
      pt.overrides.push_back(p.field + "=" + items);
    }
  }
}

// The definition the id hashes: what was asked and every point's settings.
nlohmann::ordered_json plan_definition(const SweepPlan& plan) {
  using IdJson = nlohmann::ordered_json;
  const SweepOptions& options = plan.options;
  IdJson params = IdJson::array();
  for (const SweepParameter& p : plan.parameters) {
    IdJson j = {{"name", p.name}, {"field", p.field.empty() ? IdJson() : IdJson(p.field)}};
    if (p.scale == SweepScale::kChoice) {
      j["choices"] = p.choices;
    } else {
      j["low"] = p.low;
      j["high"] = p.high;
    }
    j["scale"] = p.scale == SweepScale::kLog ? "log"
                 : p.scale == SweepScale::kInteger ? "integer"
                 : p.scale == SweepScale::kChoice ? "choice" : "linear";
    j["unit"] = p.unit;
    j["source"] = p.source;
    params.push_back(j);
  }
  IdJson points = IdJson::array();
  for (const SweepPoint& pt : plan.points) {
    points.push_back({pt.index, plan.cases[pt.case_index].name,
                      point_kind_name(pt.kind), pt.overrides,
                      exact(pt.omni_mass_scale), exact(pt.omni_friction_scale)});
  }
  IdJson case_names = IdJson::array();
  for (const SweepCase& c : plan.cases) case_names.push_back(c.name);
  return {{"software", options.software},
          {"cases", case_names},
          {"quick", options.quick},
          {"levels", options.levels},
          {"samples", options.samples},
          {"seed", options.seed},
          {"set", options.overrides},
          {"parameters", params},
          {"omitted", plan.omitted},
          {"points", points}};
}

}  // namespace

SweepPlan plan_sweep(const SweepOptions& options) {
  SweepPlan plan;
  plan.options = options;
  if (options.cases.empty()) throw SimError("sensitivity: no case to sweep");
  const int count = options.levels > 0 ? options.levels : (options.quick ? 2 : 5);
  const int samples =
      options.samples >= 0 ? options.samples : (options.quick ? 16 : 64);
  plan.options.levels = count;
  plan.options.samples = samples;
  plan_parameters(options, &plan);
  for (const std::string& name : options.cases) {
    plan.cases.push_back(plan_case(name, options.overrides, plan.parameters));
  }
  plan_points(count, samples, &plan);
  plan_settings(&plan);
  plan.definition = plan_definition(plan);
  plan.id = fnv1a_hex(plan.definition.dump());
  return plan;
}

}  // namespace vmh::studies
