// The viewer's window, its cases and its frame: copy, draw, swap.
// Input handling is viewer_input.cc; the physics thread viewer_physics.cc;
// the text and plots viewer_hud.cc.
#include "viz/viewer.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/closed_loop.h"
#include "sim/served_emulator.h"
#include "viz/png.h"
#include "viz/scene_renderer.h"
#include "viz/viewer_hud.h"
#include "viz/viewer_physics.h"
#include "viz/viewer_window.h"

namespace vmh::viz {
namespace {

double wall_now_s() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

Viewer::Viewer(const ViewerOptions& options)
    : opt_(options), case_index_(options.case_index),
      mouse_hand_((options.start_with_mouse_hand && !options.live) ||
                  options.served != nullptr) {
  if (opt_.cases.empty()) throw ViewerError("view: no case to show");
  if (case_index_ < 0 || case_index_ >= static_cast<int>(opt_.cases.size())) {
    throw ViewerError("view: case index " + std::to_string(case_index_) +
                      " out of range");
  }
  win_ = std::make_unique<Window>(opt_.width_px, opt_.height_px,
                                  "vmhaptics view", this);
  mjv_defaultCamera(&cam_);
  mjv_defaultOption(&vopt_);
  mjv_defaultScene(&scn_);
  mjr_defaultContext(&con_);
  hud_ = std::make_unique<Hud>();
  static_assert(kPlotSamples == 1000, "Viewer::plots_ is sized for it");
  plots_ = std::make_unique<std::array<PlotSample, kPlotSamples>>();
  build_case();
  // the model's three-quarter view (models/omni/stage.xml) as a free
  // camera, as `render` shows it; a scene without named cameras: the VM's
  // path, from far enough to see the arm that holds the stylus on it
  const std::vector<std::string> names = camera_names(model());
  const auto it = std::find(names.begin(), names.end(), "three_quarter");
  if (it != names.end()) {
    set_named_camera(static_cast<int>(it - names.begin()) + 1);
  } else {
    mjv_defaultFreeCamera(model(), &cam_);
    const ControllerParams& p = overlay_controller_->params();
    const Vec3 pivot_m = device_mm_to_base(p.omni, p.vm.pivot_mm);
    for (int i = 0; i < 3; ++i) cam_.lookat[i] = pivot_m[i];
    cam_.distance = 0.45;
    cam_.azimuth = 150.0;
    cam_.elevation = -25.0;
  }
}

void Viewer::set_named_camera(int step) {
  const mjModel* m = model();
  if (m->ncam == 0) return;
  const std::vector<std::string> names = camera_names(m);
  const auto it = std::find(names.begin(), names.end(), camera_name_);
  const int now = it == names.end() ? -1 : static_cast<int>(it - names.begin());
  const int next = ((now + step) % m->ncam + m->ncam) % m->ncam;
  cam_ = free_camera_like(m, next);
  camera_name_ = names[static_cast<std::size_t>(next)];
}

Viewer::~Viewer() {
  if (opt_.served != nullptr) opt_.served->release();
  sim_.reset();  // joins the physics thread
  if (d_render_ != nullptr) mj_deleteData(d_render_);
  if (scene_made_) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scn_);
  }
}

const std::string& Viewer::case_name() const {
  return opt_.cases[static_cast<std::size_t>(case_index_)].name;
}

bool Viewer::paused() const { return sim_ && sim_->paused(); }

const mjModel* Viewer::model() const {
  return opt_.served != nullptr ? opt_.served->model() : sim_->model();
}

void Viewer::build_case() {
  const bool was_paused = paused();
  sim_.reset();
  if (d_render_ != nullptr) {
    mj_deleteData(d_render_);
    d_render_ = nullptr;
  }
  if (opt_.served != nullptr) {
    // the served emulator's own physics: nothing to build but the copy
    overlay_controller_ =
        std::make_unique<Controller>(opt_.served->loop().controller_params());
    hud_->set_served(true);
    const mjModel* m = model();
    d_render_ = mj_makeData(m);
    if (!scene_made_) {
      mjv_makeScene(m, &scn_, 5000);
      mjr_makeContext(m, &con_, mjFONTSCALE_150);
      scene_made_ = true;
    }
    out_ = ControlOutput{};
    prims_.clear();
    return;
  }
  const ViewerCase& c = opt_.cases[static_cast<std::size_t>(case_index_)];
  std::vector<std::string> sets = opt_.overrides;
  auto loop = std::make_unique<sim::ClosedLoop>(c.scene, sets);
  if (gain_scale_ != 1.0) {
    // the gains as --set would give them: the case's own, scaled
    const sim::ControllerSettings& k = loop->config().controller;
    sets.push_back("k_pos_N_per_mm=" + number(k.k_pos_N_per_mm * gain_scale_));
    sets.push_back("k_ornt_multiple=" + number(k.k_ornt_multiple * gain_scale_));
    loop.reset();
    loop = std::make_unique<sim::ClosedLoop>(c.scene, sets);
  }
  overlay_controller_ = std::make_unique<Controller>(loop->controller_params());
  loop->set_manual_hand(mouse_hand_);
  sim_ = std::make_unique<SimThread>(std::move(loop));
  sim_->set_speed(slow_ ? 0.25 : 1.0);
  sim_->set_paused(was_paused);
  const mjModel* m = sim_->model();
  d_render_ = mj_makeData(m);
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    qpos_adr_[static_cast<std::size_t>(i)] = j >= 0 ? m->jnt_qposadr[j] : -1;
  }
  if (scene_made_) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scn_);
  }
  mjv_makeScene(m, &scn_, 5000);
  mjr_makeContext(m, &con_, mjFONTSCALE_150);
  scene_made_ = true;
  out_ = ControlOutput{};
  prims_.clear();
  t_sim_s_ = 0.0;
  rate_wall0_s_ = -1.0;
  if (!opt_.live) sim_->start();
}

void Viewer::record_live_plot(double t_s) {
  // the plots from the readings the frames saw (no physics thread here)
  auto& buf = *plots_;
  if (live_plot_n_ == kPlotSamples) {
    std::copy(buf.begin() + 1, buf.end(), buf.begin());
    --live_plot_n_;
  }
  buf[static_cast<std::size_t>(live_plot_n_++)] = PlotSample{
      static_cast<float>(t_s), static_cast<float>(d_path_mm_),
      static_cast<float>(out_.force_device_N.norm())};
  hud_->set_samples(buf.data(), live_plot_n_);
}

void Viewer::copy_from_served() {
  sim::ServedEmulator& se = *opt_.served;
  if (!se.copy(d_render_)) {
    status_ = "starting";
    return;
  }
  const sim::EmulatorTruth truth = se.truth();
  const hw::served::ServedState pub = se.published();
  t_sim_s_ = truth.t_sim_s;
  // what the overlay draws: the stylus at the wrist centre and the force
  // the client's motor torques make there, F = (J^T)^-1 tau, with J the
  // device's own Jacobian of the reading (device frame, mm/rad, columns
  // t1..t3), tau in N m -> F in N
  out_ = ControlOutput{};
  out_.p_rm_mm = truth.p_end_mm;
  out_.axis_rm = truth.stylus_axis;
  if (pub.state.has(kStateJacobian)) {
    const Mat3 Jt = pub.state.jacobian.block<3, 3>(0, 0).transpose();
    const Eigen::FullPivLU<Mat3> lu(Jt);
    if (lu.isInvertible()) out_.force_device_N = lu.solve(pub.tau_applied_Nm) * 1e3;
  }
  have_output_ = true;
  const hw::served::ServerStats st = se.server();
  char buf[200];
  const Vec3 tau_mNm = pub.tau_applied_Nm * 1e3;
  std::snprintf(buf, sizeof buf,
                "client %s, command %s, tau (%.0f, %.0f, %.0f) mN m",
                st.client_pid != 0 ? ("pid " + std::to_string(st.client_pid)).c_str()
                                   : "none",
                hw::served::command_state_name(st.command_state), tau_mNm[0],
                tau_mNm[1], tau_mNm[2]);
  status_ = buf;
  // the upper plot: the hand's force (N), who pushes the stylus
  hand_force_N_ = truth.hand_force_N.norm();
  d_path_mm_ = hand_force_N_;
  record_live_plot(t_sim_s_);
}

void Viewer::copy_from_physics() {
  const mjModel* m = model();
  if (opt_.served != nullptr) {
    copy_from_served();
    return;
  }
  if (opt_.live) {
    // the device's reading poses the model; nothing is simulated here
    const LiveSample s = opt_.live();
    if (!s.valid) return;
    const Joints q_dh = device_to_dh_joints(s.q_device_rad);
    for (int i = 0; i < 6; ++i) {
      const int adr = qpos_adr_[static_cast<std::size_t>(i)];
      if (adr >= 0) d_render_->qpos[adr] = q_dh[i];
    }
    mj_forward(m, d_render_);
    out_ = s.out;
    t_sim_s_ = s.t_s;
    status_ = s.status.empty() ? status_text(out_.status)
                               : status_text(out_.status) + ", " + s.status;
    d_path_mm_ = overlay_controller_->mechanism().distance_to_path(
                     out_.p_rm_mm / overlay_controller_->params().length_unit_mm) *
                 overlay_controller_->params().length_unit_mm;
    have_output_ = true;
    record_live_plot(s.t_s);
    return;
  }
  TickRecord row;
  bool ticked = false;
  int n = 0;
  sim_->copy(d_render_, &row, &ticked, plots_.get(), &n);
  hud_->set_samples(plots_->data(), n);
  t_sim_s_ = d_render_->time;
  have_output_ = ticked;
  if (ticked) {
    out_ = row.out;
    d_path_mm_ = row.d_path_mm;
    status_ = status_text(out_.status);
  } else {
    status_ = "not started";
  }
}

void Viewer::render() {
  const mjModel* m = model();
  win_->framebuffer_size(&width_px_, &height_px_);
  win_height_px_ = win_->window_height_px();
  const mjrRect viewport{0, 0, width_px_, height_px_};
  prims_.clear();
  if (overlay_on_ && have_output_) {
    // a served device's program is not this case's controller: its stylus
    // and force only, not the case's mechanism
    OverlayOptions oo;
    oo.path = oo.mechanism = opt_.served == nullptr;
    overlay_primitives(overlay_controller_->mechanism(),
                       overlay_controller_->params(), out_, oo, &prims_);
  }
  // the scene as `render` makes it (viz/scene_renderer.h)
  prepare_scene(m, d_render_, &vopt_, &cam_, prims_, &scn_);
  mjr_render(viewport, &scn_, &con_);

  HudText t;
  t.case_name = case_name();
  if (opt_.served != nullptr) t.case_name += " as " + opt_.served->spec();
  t.camera = camera_name_.empty() ? "free" : camera_name_;
  if (opt_.served != nullptr) {
    t.hand = opt_.served->held() ? "mouse, holding the stylus"
                                 : "mouse, let go (left-drag grabs)";
  } else {
    t.hand = opt_.live ? opt_.live_name : (mouse_hand_ ? "mouse" : "script");
  }
  t.k_pos_N_per_mm = overlay_controller_->params().gains.k_pos_N_per_mm;
  t.k_ornt_Nmm_per_rad = overlay_controller_->params().gains.k_ornt_Nmm_per_rad;
  t.gain_scale = gain_scale_;
  t.force_N = out_.force_device_N.norm();
  t.path_error_mm = d_path_mm_;
  t.status = status_;
  t.t_sim_s = t_sim_s_;
  t.realtime_factor = rtf_;
  t.frames_per_s = fps_;
  t.paused = paused();
  t.slow = slow_;
  t.served = opt_.served != nullptr;
  t.hand_force_N = hand_force_N_;
  hud_->draw(viewport, t, help_on_, &con_);
  if (want_shot_) {
    want_shot_ = false;
    screenshot();
  }
}

void Viewer::screenshot() {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width_px_) *
                                static_cast<std::size_t>(height_px_) * 3);
  mjr_readPixels(rgb.data(), nullptr, mjrRect{0, 0, width_px_, height_px_},
                 &con_);
  flip_rows(width_px_, height_px_, &rgb);
  // named by the local time, so successive shots do not overwrite
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  std::string base = "vmhaptics-view-" + case_name() + "-" + stamp;
  std::filesystem::path path = std::filesystem::path(opt_.out_dir) / (base + ".png");
  for (int k = 2; std::filesystem::exists(path); ++k) {
    path = std::filesystem::path(opt_.out_dir) /
           (base + "-" + std::to_string(k) + ".png");
  }
  try {
    write_png(path.string(), width_px_, height_px_, rgb);
    last_shot_ = path.string();
    std::fprintf(stderr, "vmhaptics view: screenshot %s\n", last_shot_.c_str());
  } catch (const std::exception& e) {
    // a failed screenshot should not end the session
    std::fprintf(stderr, "vmhaptics view: screenshot failed: %s\n", e.what());
  }
}

void Viewer::update_rates() {
  const double now = wall_now_s();
  if (rate_wall0_s_ < 0.0) {
    rate_wall0_s_ = now;
    rate_sim0_s_ = t_sim_s_;
    rate_frames0_ = frames_;
    return;
  }
  const double dt = now - rate_wall0_s_;
  if (dt < 1.0) return;
  fps_ = static_cast<double>(frames_ - rate_frames0_) / dt;
  rtf_ = (t_sim_s_ - rate_sim0_s_) / dt;
  rate_wall0_s_ = now;
  rate_sim0_s_ = t_sim_s_;
  rate_frames0_ = frames_;
}

bool Viewer::frame() {
  Window::poll();
  if (want_close_ || win_->should_close()) return false;
  if (opt_.stop_requested && opt_.stop_requested()) return false;
  copy_from_physics();
  render();
  win_->swap();
  ++frames_;
  update_rates();
  return true;
}

long Viewer::run() {
  while (opt_.max_frames <= 0 || frames_ < opt_.max_frames) {
    if (opt_.screenshot_last_frame && frames_ + 1 == opt_.max_frames) {
      want_shot_ = true;
    }
    if (!frame()) break;
  }
  return frames_;
}

}  // namespace vmh::viz
