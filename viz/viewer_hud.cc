#include "viz/viewer_hud.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace vmh::viz {
namespace {

void setup_figure(mjvFigure* f, const char* title, const float rgb[3]) {
  mjv_defaultFigure(f);
  std::snprintf(f->title, sizeof f->title, "%s", title);
  std::snprintf(f->xlabel, sizeof f->xlabel, "sim time (s)");
  std::snprintf(f->xformat, sizeof f->xformat, "%%.0f");
  std::snprintf(f->yformat, sizeof f->yformat, "%%.3g");
  // the ranges are set from the data with round ends (set_samples), so
  // that every grid line falls on a round number
  f->flg_extend = 0;
  f->flg_legend = 0;
  f->gridsize[0] = static_cast<int>(kPlotWindow_s) + 1;  // a line a second
  f->gridsize[1] = kPlotYIntervals + 1;
  f->figurergba[3] = 0.75f;  // see the scene through the figure
  for (int i = 0; i < 3; ++i) f->linergb[0][i] = rgb[i];
  f->linewidth = 2.5f;
  // the y axis from zero, grown with the data
  f->range[1][0] = 0.0f;
  f->range[1][1] = 1.0f;
}

}  // namespace

double round_axis_top(double max, int intervals) {
  if (!(max > 0.0) || !std::isfinite(max) || intervals < 1) return 1.0;
  const double raw = max / intervals;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * p * intervals >= max * (1.0 - 1e-12)) return m * p * intervals;
  }
  return 10.0 * p * intervals;
}

std::string status_text(ControlStatus s) {
  if (s == kStatusOk) return "ok";
  std::string out;
  for (int i = 0; i < kStatusFlagCount; ++i) {
    const ControlStatus f = 1u << i;
    if (s & f) {
      if (!out.empty()) out += "|";
      out += status_flag_name(f);
    }
  }
  return out;
}

const char* hud_help_text(bool served) {
  if (served) {
    return "left-drag grabs the stylus and moves it, shift+left-drag turns "
           "it, release lets go\n"
           "o overlay | c camera | p screenshot | h help | esc quit | "
           "right-drag camera, middle-drag pan, scroll zoom";
  }
  return "space pause | right arrow one tick | s slow x1/4 | r reset | "
         "[ ] case | + - gains x2 /2\n"
         "m mouse/script hand | o overlay | c camera | p screenshot | h help | "
         "esc quit\n"
         "mouse hand: left-drag moves it, shift+left-drag turns it | "
         "right-drag camera, middle-drag pan, scroll zoom";
}

Hud::Hud()
    : error_fig_(std::make_unique<mjvFigure>()),
      force_fig_(std::make_unique<mjvFigure>()) {
  // the colours of the overlay: path blue, force magenta (viz/overlay.cc)
  const float blue[3] = {0.45f, 0.65f, 0.95f};
  const float magenta[3] = {0.85f, 0.10f, 0.85f};
  setup_figure(error_fig_.get(), "path error (mm)", blue);
  setup_figure(force_fig_.get(), "|F| (N)", magenta);
}

Hud::~Hud() = default;

void Hud::set_served(bool served) {
  // the hand's force in the colour of its spring line (viz/overlay.cc)
  const float blue[3] = {0.45f, 0.65f, 0.95f};
  const float brown[3] = {0.60f, 0.40f, 0.20f};
  if (served) {
    setup_figure(error_fig_.get(), "hand force (N)", brown);
  } else {
    setup_figure(error_fig_.get(), "path error (mm)", blue);
  }
}

void Hud::set_samples(const PlotSample* samples, int n) {
  const float t_end = n > 0 ? samples[n - 1].t_s : 0.0f;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    const PlotSample& s = samples[i];
    if (t_end - s.t_s > static_cast<float>(kPlotWindow_s)) continue;
    error_fig_->linedata[0][2 * k] = s.t_s;
    error_fig_->linedata[0][2 * k + 1] = s.d_path_mm;
    force_fig_->linedata[0][2 * k] = s.t_s;
    force_fig_->linedata[0][2 * k + 1] = s.force_N;
    ++k;
  }
  error_fig_->linepnt[0] = k;
  force_fig_->linepnt[0] = k;
  // the x axis the last window, ending on the next whole second, so that
  // the plot scrolls a second at a time with a grid line on each second;
  // the y axis from zero to a round top above the data
  const float x_end = std::ceil(t_end);
  for (mjvFigure* f : {error_fig_.get(), force_fig_.get()}) {
    f->range[0][0] = x_end - static_cast<float>(kPlotWindow_s);
    f->range[0][1] = x_end;
    float y_max = 0.0f;
    for (int i = 0; i < k; ++i) y_max = std::max(y_max, f->linedata[0][2 * i + 1]);
    f->range[1][0] = 0.0f;
    f->range[1][1] = static_cast<float>(round_axis_top(y_max, kPlotYIntervals));
  }
}

void Hud::draw(const mjrRect& viewport, const HudText& t, bool help,
               const mjrContext* con) {
  char values[1024];
  if (t.served) {
    std::snprintf(values, sizeof values,
                  "%s\n%s\n%s\n%.3f\n%.3f\n%s\n%.3f\n%.2f\n%.1f",
                  t.case_name.c_str(), t.camera.c_str(), t.hand.c_str(),
                  t.force_N, t.hand_force_N, t.status.c_str(), t.t_sim_s,
                  t.realtime_factor, t.frames_per_s);
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport,
                "scene\ncamera\nhand\nclient |F| (N)\nhand |F| (N)\n"
                "device\nsim time (s)\nreal-time factor\nframes/s",
                values, con);
  } else {
    std::snprintf(values, sizeof values,
                  "%s\n%s\n%s\n%.3g N/mm, %.4g N mm/rad (x%g)\n%.3f\n%.3f\n%s\n"
                  "%.3f%s\n%.2f\n%.1f",
                  t.case_name.c_str(), t.camera.c_str(), t.hand.c_str(),
                  t.k_pos_N_per_mm,
                  t.k_ornt_Nmm_per_rad, t.gain_scale, t.force_N,
                  t.path_error_mm, t.status.c_str(), t.t_sim_s,
                  t.paused ? "  (paused)" : (t.slow ? "  (x1/4)" : ""),
                  t.realtime_factor, t.frames_per_s);
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport,
                "case\ncamera\nhand\nK_pos, K_ornt\n|F| (N)\npath error (mm)\n"
                "controller\nsim time (s)\nreal-time factor\nframes/s",
                values, con);
  }
  if (help) {
    mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMLEFT, viewport,
                hud_help_text(t.served), nullptr, con);
  }
  // each plot a third of the width and at least 240 px high: MuJoCo's
  // labels take about 100 px of it
  const int w = viewport.width / 3;
  const int h = std::max(viewport.height * 3 / 10, 240);
  const mjrRect top{viewport.left + viewport.width - w,
                    viewport.bottom + viewport.height - h, w, h};
  const mjrRect below{top.left, top.bottom - h, w, h};
  mjr_figure(top, error_fig_.get(), con);
  mjr_figure(below, force_fig_.get(), con);
}

}  // namespace vmh::viz
