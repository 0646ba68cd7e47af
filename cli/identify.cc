// vmhaptics identify <recording-dir>... [--out DIR] [--model-out FILE]
//                    [--fit mass,friction,damping,gains] [--serial S]
//
// Fits the MJCF Omni's uncertain scales to recordings' motor pulses
// (bringup/identify.h says how, and what cannot be identified),
// writes the calibrated model (default
// <models>/omni/calibrated/<serial>.xml) and, with --out, DIR/identify.json
// and DIR/identify_fit.svg. Prints one JSON object.
//
// Exit codes: 0 a converged, well-conditioned fit; 1 the fit did not
// converge or is poorly conditioned (the JSON says which, and is still
// printed and written); 2 bad input (a missing directory, not a
// recording, no motor pulse in any, an unknown --fit name); 130 / 143
// SIGINT / SIGTERM: before the model is written nothing is written (the
// fit polls between its batches of simulations); a signal while the files
// go out lets them finish (each is replaced whole) and then exits so.
#include <CLI/CLI.hpp>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/args.h"
#include "device/stop_signal.h"
#include "runtime/session.h"
#include "runtime/stop.h"
#include "runtime/json_util.h"
#include "output/output_file.h"
#include "output/svg_chart.h"
#include "bringup/identify.h"
#include "bringup/recording.h"
#include "sim/cases/case_catalogue.h"

namespace vmh::cli {
namespace {

struct IdentifyCliOptions {
  std::vector<std::string> dirs;
  std::string out;
  std::string model_out;
  std::string fit = "mass,friction,damping";
  std::string serial;
};

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');) {
    if (item.empty()) throw UsageError("identify: --fit has an empty name in '" + text + "'");
    if (item != "mass" && item != "friction" && item != "damping" && item != "gains") {
      throw UsageError("identify: --fit: unknown parameter '" + item +
                       "' (expected mass, friction, damping, gains)");
    }
    out.push_back(item);
  }
  if (out.empty()) throw UsageError("identify: --fit names nothing to fit");
  return out;
}

// A serial names the default model file (<models>/omni/calibrated/
// <serial>.xml), so it must be one file name: 1 to 64 letters, digits,
// '.', '_' or '-', starting with a letter or digit (no '/', no "..").
// Throws UsageError naming where it came from otherwise.
void check_serial(const std::string& serial, const std::string& where) {
  bool ok = !serial.empty() && serial.size() <= 64 &&
            std::isalnum(static_cast<unsigned char>(serial[0])) != 0;
  for (char ch : serial) {
    const auto u = static_cast<unsigned char>(ch);
    ok = ok && (std::isalnum(u) != 0 || ch == '.' || ch == '_' || ch == '-');
  }
  if (!ok) {
    std::string shown = serial.substr(0, 80);
    for (char& ch : shown) {
      if (!std::isprint(static_cast<unsigned char>(ch))) ch = '?';
    }
    throw UsageError("identify: " + where + ": serial '" + shown +
                     "' is not a device serial (1 to 64 letters, digits, '.', "
                     "'_' or '-', starting with a letter or digit); it names "
                     "the calibrated model's file");
  }
}

// the device serial of the first recording whose meta.json names one,
// checked (check_serial); "unknown" if none does
std::string serial_of(const std::vector<bringup::Recording>& recs,
                      const std::vector<std::string>& dirs) {
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const auto& m = recs[i].meta;
    if (m.contains("device") && m["device"].is_object() &&
        m["device"].contains("serial") && m["device"]["serial"].is_string()) {
      const std::string s = m["device"]["serial"].get<std::string>();
      check_serial(s, dirs[i] + "/meta.json's device.serial");
      return s;
    }
  }
  return "unknown";
}

// measured, nominal and fitted response of each window's pushed joint
std::string fit_figure(const bringup::IdentifyResult& r) {
  output::ChartGrid grid;
  grid.title = "identify: pushed joint, measured vs simulated before and after the fit";
  grid.notes.push_back("device angles t1..t3 (rad); nominal = the model as written");
  grid.notes.push_back("fitted: " + sim::omni_edit_text(r.edit));
  grid.columns = 3;
  for (const bringup::WindowTrace& w : r.traces) {
    output::Chart c;
    c.title = std::filesystem::path(r.recordings[w.recording].dir).filename().string() +
              ", motor " + std::to_string(w.motor);
    c.x.label = "time from window start (s)";
    c.y.label = "t" + std::to_string(w.motor) + " (rad, device)";
    std::vector<double> t;
    for (double ts : w.t_s) t.push_back(ts - w.t_s.front());
    c.series.push_back({"measured", t, w.measured_rad, "#222222", false, true, false});
    c.series.push_back({"nominal", t, w.before_rad, "#d62728", true, false, true});
    c.series.push_back({"fitted", t, w.after_rad, "#1f77b4", true, false, false});
    c.width_px = 420;
    c.height_px = 300;
    grid.panels.push_back(std::move(c));
  }
  return output::chart_grid_svg(grid);
}

Json result_json(const bringup::IdentifyResult& r, const std::vector<std::string>& fit) {
  Json out;
  out["fit"] = fit;
  Json params = Json::array();
  for (const bringup::FittedParameter& p : r.parameters) {
    params.push_back({{"name", p.name}, {"unit", p.unit}, {"nominal", p.nominal},
                      {"fitted", p.fitted}, {"sigma", p.sigma},
                      {"identified", p.identified}});
  }
  out["parameters"] = params;
  Json signs = Json::array();
  for (const bringup::MotorSign& s : r.signs) {
    signs.push_back({{"motor", s.motor}, {"sign", s.sign},
                     {"agreement", s.agreement}, {"determined", s.determined}});
  }
  out["motor_signs"] = signs;
  out["edit"] = sim::omni_edit_text(r.edit);
  out["correlation"] = to_json_rows(r.correlation);
  out["condition_number"] = r.condition_number;
  out["poorly_conditioned"] = r.poorly_conditioned;
  out["conditioning"] = r.conditioning;
  out["converged"] = r.converged;
  out["iterations"] = r.iterations;
  out["residuals"] = r.residuals;
  // weighted sums of squares per residual (1 = quantization noise)
  out["cost_before"] = r.cost_before;
  out["cost_after"] = r.cost_after;
  out["residual_lag1_correlation"] = r.residual_lag1_correlation;
  out["sigma_inflation"] = r.sigma_inflation;
  Json recs = Json::array();
  for (const bringup::RecordingFit& f : r.recordings) {
    recs.push_back({{"dir", f.dir}, {"windows", f.windows}, {"samples", f.samples},
                    {"rms_before_rad", f.rms_before_rad}, {"rms_after_rad", f.rms_after_rad},
                    {"rms_before_mm", f.rms_before_mm}, {"rms_after_mm", f.rms_after_mm}});
  }
  out["recordings"] = recs;
  out["notes"] = r.notes;
  return out;
}

// each directory's recording, in the order given, with the note on its
// analysis window on stderr; a missing directory or one that is not a
// recording is a UsageError
std::vector<bringup::Recording> recordings_to_fit(
    const std::vector<std::string>& dirs) {
  std::vector<bringup::Recording> recs;
  for (const std::string& d : dirs) {
    if (!std::filesystem::is_directory(d)) {
      throw UsageError("identify: " + d + " is not a directory");
    }
    runtime::throw_if_stopped("identify", "; nothing written");
    try {
      recs.push_back(bringup::load_recording(d));
      if (const std::string note = bringup::window_note(recs.back()); !note.empty()) {
        std::cerr << "identify: " << note << '\n';
      }
    } catch (const bringup::RecordingError& e) {
      throw UsageError(std::string("identify: not a recording: ") + e.what());
    }
  }
  return recs;
}

// the device's serial and the calibrated model's path
struct IdentifyTargets {
  std::string serial;
  std::string model;
};

// Where the results go, checked before the fit and before anything is
// written: a bad --out must not leave a model behind.
IdentifyTargets check_targets(const IdentifyCliOptions& o,
                              const std::vector<bringup::Recording>& recs) {
  if (!o.serial.empty()) check_serial(o.serial, "--serial");
  IdentifyTargets t;
  t.serial = o.serial.empty() ? serial_of(recs, o.dirs) : o.serial;
  t.model = o.model_out.empty()
                ? sim::models_dir() + "/omni/calibrated/" + t.serial + ".xml"
                : o.model_out;
  try {
    if (!o.out.empty()) output::check_writable_dir(o.out);
    const std::filesystem::path model_dir =
        std::filesystem::path(t.model).parent_path();
    if (!model_dir.empty()) output::check_writable_dir(model_dir.string());
    output::check_replaceable(t.model);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("identify: ") + e.what());
  }
  return t;
}

// the fit; what it cannot fit on (no pulse, the recordings' scene) is bad
// input
bringup::IdentifyResult fit_recordings(
    const std::vector<bringup::Recording>& recs,
    const bringup::IdentifyOptions& io) {
  try {
    return bringup::identify(recs, io);
  } catch (const bringup::IdentifyError& e) {
    throw UsageError(e.what());
  } catch (const sim::SimError& e) {
    // the scene a recording names (meta.json's emulator.scene) or its
    // parameters: bad input, as a bad recording is
    throw UsageError(std::string("identify: the recordings' scene: ") + e.what());
  }
}

// the calibrated model's provenance comment: who, when, from what, the fit
std::string provenance(const std::string& serial,
                       const bringup::IdentifyResult& r) {
  std::ostringstream prov;
  prov << "calibrated by vmhaptics identify: serial " << serial << ", " << utc_now()
       << "; recordings";
  for (const bringup::RecordingFit& f : r.recordings) prov << ' ' << f.dir;
  prov << "; fitted";
  for (const bringup::FittedParameter& p : r.parameters) {
    prov << ' ' << p.name << '=' << p.fitted << "+-" << p.sigma
         << (p.identified ? "" : " (not identified)");
  }
  prov << "; edit " << sim::omni_edit_text(r.edit) << "; " << r.conditioning;
  return prov.str();
}

// identify.json's object (also what is printed): the serial, the result,
// the model and every output, and the run time since `start`
Json identify_json(const IdentifyCliOptions& o, const IdentifyTargets& t,
                   const bringup::IdentifyResult& r,
                   const bringup::IdentifyOptions& io,
                   std::chrono::steady_clock::time_point start) {
  Json out;
  out["serial"] = t.serial;
  out.update(result_json(r, io.fit));
  out["model"] = t.model;
  Json outputs = Json::array({t.model});
  if (!o.out.empty()) {
    outputs.push_back(o.out + "/identify.json");
    outputs.push_back(o.out + "/identify_fit.svg");
  }
  out["outputs"] = outputs;
  out["run_time_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

// exit 1 when the fit did not converge or is poorly conditioned
void throw_if_poor_fit(const bringup::IdentifyResult& r) {
  if (!r.converged) {
    throw std::runtime_error("identify: the fit did not converge in " +
                             std::to_string(r.iterations) + " iterations");
  }
  if (r.poorly_conditioned) throw std::runtime_error("identify: " + r.conditioning);
}

void identify_verb(const IdentifyCliOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h), polled
  // between recordings, in the fit, and before anything is written
  StopSignals signals;
  bringup::IdentifyOptions io;
  io.fit = split_names(o.fit);
  // a real device's recording names no scene: the emulator's default one
  io.default_scene = sim::models_dir() + "/cases/case1.xml";
  const std::vector<bringup::Recording> recs = recordings_to_fit(o.dirs);
  const IdentifyTargets t = check_targets(o, recs);
  const bringup::IdentifyResult r = fit_recordings(recs, io);

  const std::string prov = provenance(t.serial, r);
  const std::string figure = o.out.empty() ? std::string() : fit_figure(r);
  runtime::throw_if_stopped("identify", "; nothing written");
  const std::filesystem::path model_dir = std::filesystem::path(t.model).parent_path();
  if (!model_dir.empty()) std::filesystem::create_directories(model_dir);
  bringup::write_calibrated_model(r.edit, sim::models_dir() + "/omni/omni.xml",
                                  t.model, prov);

  const Json out = identify_json(o, t, r, io, start);
  if (!o.out.empty()) {
    output::write_file_in(o.out, "identify_fit.svg", figure);
    output::write_file_in(o.out, "identify.json", dump_readable(out) + "\n");
  }
  // a signal while the files went out: they are whole, and the exit says so
  runtime::throw_if_stopped("identify", "; its files were already written (" +
                                            out["outputs"].dump() + ")");
  std::cout << dump_readable(out) << '\n';
  throw_if_poor_fit(r);
}

}  // namespace

void register_identify(CLI::App* app) {
  auto o = std::make_shared<IdentifyCliOptions>();
  CLI::App* c = app->add_subcommand(
      "identify",
      "fit the Omni model's mass, friction, damping (and motor gains) to "
      "motor-test recordings; write a calibrated model");
  c->add_option("dirs", o->dirs, "recording directories (meta.json, trace.csv)")
      ->required();
  c->add_option("--out", o->out, "write DIR/identify.json and DIR/identify_fit.svg");
  c->add_option("--model-out", o->model_out,
                "calibrated model path (default <models>/omni/calibrated/<serial>.xml)");
  c->add_option("--fit", o->fit,
                "scales to fit: mass,friction,damping,gains (default mass,friction,damping)");
  c->add_option("--serial", o->serial, "device serial (default: the recordings' meta.json)");
  c->callback([o]() { identify_verb(*o); });
}

}  // namespace vmh::cli
