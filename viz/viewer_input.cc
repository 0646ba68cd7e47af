// The viewer's input: keys, the mouse hand and the camera. GLFW's callbacks
// (viewer_window.cc) and tests both come in through Viewer::inject.
#include <GLFW/glfw3.h>

#include <cmath>
#include <cstdio>
#include <exception>

#include "viz/mouse_hand.h"
#include "viz/viewer.h"
#include "sim/served_emulator.h"
#include "viz/viewer_physics.h"

namespace vmh::viz {
namespace {

// the viewer's free camera as the mouse-hand geometry takes it
ViewCamera view_camera_of(const mjvCamera& c, const mjModel* m) {
  ViewCamera cam;
  cam.lookat_m = Vec3(c.lookat[0], c.lookat[1], c.lookat[2]);
  cam.azimuth_deg = c.azimuth;
  cam.elevation_deg = c.elevation;
  cam.distance_m = c.distance;
  cam.fovy_deg = m->vis.global.fovy;
  return cam;
}

}  // namespace

InputEvent InputEvent::key_press(int key, bool shift) {
  InputEvent e;
  e.type = Type::kKey;
  e.key = key;
  e.press = true;
  e.shift = shift;
  return e;
}

InputEvent InputEvent::click(int button, bool press, double x_px,
                              double y_px, bool shift, bool ctrl) {
  InputEvent e;
  e.type = Type::kButton;
  e.button = button;
  e.press = press;
  e.x_px = x_px;
  e.y_px = y_px;
  e.shift = shift;
  e.ctrl = ctrl;
  return e;
}

InputEvent InputEvent::move(double x_px, double y_px) {
  InputEvent e;
  e.type = Type::kMove;
  e.x_px = x_px;
  e.y_px = y_px;
  return e;
}

void Viewer::inject(const InputEvent& e) {
  switch (e.type) {
    case InputEvent::Type::kKey:
      if (e.press) handle_key(e);
      break;
    case InputEvent::Type::kButton:
      handle_button(e);
      break;
    case InputEvent::Type::kMove:
      handle_move(e);
      break;
    case InputEvent::Type::kScroll:
      // MuJoCo's zoom: a wheel step is 5 % of the distance
      mjv_moveCamera(model(), mjMOUSE_ZOOM, 0.0, -0.05 * e.scroll, &scn_,
                     &cam_);
      break;
  }
}

void Viewer::handle_key(const InputEvent& e) {
  // a device runs on its own, and so does a served emulator
  const bool sim_only = !opt_.live && opt_.served == nullptr;
  switch (e.key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
      want_close_ = true;
      break;
    case GLFW_KEY_SPACE:
      if (sim_only) sim_->set_paused(!sim_->paused());
      break;
    case GLFW_KEY_RIGHT:
      if (sim_only) sim_->step_once();
      break;
    case GLFW_KEY_S:
      slow_ = !slow_;
      if (sim_only) sim_->set_speed(slow_ ? 0.25 : 1.0);
      break;
    case GLFW_KEY_R:
      if (sim_only) sim_->reset();
      break;
    case GLFW_KEY_RIGHT_BRACKET:
    case GLFW_KEY_LEFT_BRACKET:
      if (sim_only && opt_.cases.size() > 1) {
        const int n = static_cast<int>(opt_.cases.size());
        const int step = e.key == GLFW_KEY_RIGHT_BRACKET ? 1 : n - 1;
        rebuild_or_keep((case_index_ + step) % n, gain_scale_);
      }
      break;
    case GLFW_KEY_EQUAL:  // '+' is shift+'=' on most layouts
    case GLFW_KEY_KP_ADD:
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      if (sim_only) {
        const bool up = e.key == GLFW_KEY_EQUAL || e.key == GLFW_KEY_KP_ADD;
        rebuild_or_keep(case_index_, gain_scale_ * (up ? 2.0 : 0.5));
      }
      break;
    case GLFW_KEY_M:
      if (sim_only) {
        mouse_hand_ = !mouse_hand_;
        sim_->set_manual_hand(mouse_hand_);
      }
      break;
    case GLFW_KEY_O:
      overlay_on_ = !overlay_on_;
      break;
    case GLFW_KEY_C:
      // the model's named cameras in turn (shift: backwards), as free
      // cameras, so that the mouse still turns the view and moves the hand
      set_named_camera(e.shift ? -1 : 1);
      break;
    case GLFW_KEY_P:
      want_shot_ = true;
      break;
    case GLFW_KEY_H:
      help_on_ = !help_on_;
      break;
    default:
      break;
  }
}

void Viewer::rebuild_or_keep(int case_index, double gain_scale) {
  const int old_index = case_index_;
  const double old_scale = gain_scale_;
  case_index_ = case_index;
  gain_scale_ = gain_scale;
  try {
    build_case();
  } catch (const std::exception& e) {
    // e.g. a --set that suits one case and not the next: stay where we were
    std::fprintf(stderr, "vmhaptics view: %s; kept %s\n", e.what(),
                 opt_.cases[static_cast<std::size_t>(old_index)].name.c_str());
    case_index_ = old_index;
    gain_scale_ = old_scale;
    build_case();
  }
}

void Viewer::handle_button(const InputEvent& e) {
  if (e.button == GLFW_MOUSE_BUTTON_LEFT) left_down_ = e.press;
  if (e.button == GLFW_MOUSE_BUTTON_RIGHT) right_down_ = e.press;
  if (e.button == GLFW_MOUSE_BUTTON_MIDDLE) middle_down_ = e.press;
  // the modifier is read when the drag starts: a drag is a move or a turn
  if (e.press && e.button == GLFW_MOUSE_BUTTON_LEFT) drag_rotate_ = e.shift;
  if (opt_.served != nullptr && e.button == GLFW_MOUSE_BUTTON_LEFT) {
    // the hand takes the stylus where it is (the grip site of the last
    // frame's copy), so nothing jumps; releasing the button lets go
    if (e.press && d_render_ != nullptr) {
      const int g = opt_.served->loop().hand().grip_site();
      sim::HandTargetState t;
      t.p_m = Vec3(d_render_->site_xpos + 3 * g);
      t.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
          d_render_->site_xmat + 9 * g);
      opt_.served->grab(t);
    } else if (!e.press) {
      opt_.served->release();
    }
  }
  last_x_px_ = e.x_px;
  last_y_px_ = e.y_px;
}

void Viewer::handle_move(const InputEvent& e) {
  const double dx = e.x_px - last_x_px_;
  const double dy = e.y_px - last_y_px_;
  last_x_px_ = e.x_px;
  last_y_px_ = e.y_px;
  if (dx == 0.0 && dy == 0.0) return;
  // drags are in window coordinates, which a HiDPI framebuffer scales
  const int h = win_height_px_ > 0 ? win_height_px_ : opt_.height_px;
  if (left_down_ && opt_.served != nullptr) {
    sim::HandTargetState t = opt_.served->target();
    apply_drag(view_camera_of(cam_, model()), h, dx, dy, drag_rotate_, &t);
    opt_.served->set_target(t);
    return;
  }
  if (left_down_ && mouse_hand_ && !opt_.live) {
    sim::HandTargetState t = sim_->manual_target();
    apply_drag(view_camera_of(cam_, model()), h, dx, dy, drag_rotate_, &t);
    sim_->set_manual_target(t);
    return;
  }
  // the camera, as MuJoCo's own simulate does it: relative to the height
  int action = mjMOUSE_NONE;
  if (right_down_ || left_down_) {
    action = e.shift ? mjMOUSE_ROTATE_H : mjMOUSE_ROTATE_V;
  } else if (middle_down_) {
    action = e.shift ? mjMOUSE_MOVE_H : mjMOUSE_MOVE_V;
  }
  if (action != mjMOUSE_NONE) {
    mjv_moveCamera(model(), action, dx / h, dy / h, &scn_, &cam_);
  }
}

}  // namespace vmh::viz
