// Offscreen renders of the MuJoCo scene with the overlay (viz/overlay.h)
// drawn over it: the pixels of one frame, rows from the top, ready for
// write_png (viz/png.h).
//
// A SceneRenderer owns MuJoCo's visual state for one model (mjvScene,
// mjvOption, mjvCamera) and its GPU resources (mjrContext), so it needs a
// current OpenGL context (viz/gl_context.h) for its whole life, on the
// thread that uses it. Not for the servo tick: it allocates and draws.
#ifndef VMHAPTICS_VIZ_SCENE_RENDERER_H_
#define VMHAPTICS_VIZ_SCENE_RENDERER_H_

#include <mujoco/mujoco.h>

#include <cstdint>
#include <string>
#include <vector>

#include "controller/omni_params.h"
#include "viz/overlay.h"

namespace vmh::viz {

// The free camera framing the Omni's workspace: it looks at a point between
// the shoulder (the DH base origin) and the device-frame origin (the wrist
// centre of the zero pose, where the thesis's circle is centred), from the
// user's side (+x of the DH base frame = +z of the device frame), a little
// to the side and above, so that the device x-y plane, the thesis's circle,
// is seen nearly face on and the arm beside it.
mjvCamera workspace_camera(const OmniParams& omni);

// The view a frame starts from when no camera is named: the model's camera
// "three_quarter" (models/omni/stage.xml) when it has one, looking the same
// as `--camera three_quarter`, else workspace_camera() as a free camera.
mjvCamera default_camera(const mjModel* m, const OmniParams& omni);

// A free camera showing what the model's camera `cam_id` (a world-fixed
// camera) shows: looking the same way at the point of its line of sight
// nearest the model's centre (statistic center), from a distance scaled so
// that, at the free camera's field of view (visual/global fovy), the frame
// holds the same. The viewer starts from it and its camera key steps
// through them, keeping the free camera the mouse turns and the mouse hand
// reads (viz/mouse_hand.h).
mjvCamera free_camera_like(const mjModel* m, int cam_id);

// the model's cameras' names, in the model's order (unnamed ones as "#i")
std::vector<std::string> camera_names(const mjModel* m);

// What `vmhaptics render` and `vmhaptics view` draw, made in one place so
// that the two show the same scene: MuJoCo's scene of `d` seen from `cam`,
// a brighter headlight for a scene without lights of its own, the overlay
// (viz/overlay.h; the moving bodies at kOverlayModelAlpha while there is
// one) and the simulated hand (its target's pads and its spring to the
// grip site, hand_primitives(), whenever the model has the mocap body
// "hand_target" and the site "grip"). Fills *scn.
void prepare_scene(const mjModel* m, mjData* d, const mjvOption* opt,
                   mjvCamera* cam, const std::vector<OverlayPrimitive>& overlay,
                   mjvScene* scn);

// The id of the model's camera called `name`. Throws std::invalid_argument
// naming the camera and listing the model's cameras when there is none by
// that name.
int camera_id(const mjModel* m, const std::string& name);

// A few lines of text drawn in the image's top-left corner: titles in the
// left column, values in the right, lines separated by '\n'.
struct RenderLabel {
  std::string titles;
  std::string values;
};

class SceneRenderer {
 public:
  // `m` must outlive the renderer. The offscreen buffer is made at least
  // max_width_px x max_height_px (MuJoCo sizes it from m->vis.global
  // .offwidth/offheight when the context is made; those of a copy of the
  // model's header are raised, the model itself is left alone). Throws
  // std::invalid_argument for a size outside [16, 4096] px,
  // std::runtime_error if MuJoCo cannot make the buffer that large.
  SceneRenderer(const mjModel* m, const OmniParams& omni, int max_width_px,
                int max_height_px);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Renders `d`'s state of the renderer's model with `overlay` added,
  // width_px x height_px (within the buffer's size), seen from the model's
  // camera `camera` or, when empty, from default_camera(). Returns
  // 3 * width * height bytes of RGB, rows from the top. Throws
  // std::invalid_argument on a size larger than the buffer or an unknown
  // camera.
  std::vector<std::uint8_t> render_rgb(
      const mjModel* m, mjData* d, const std::vector<OverlayPrimitive>& overlay,
      int width_px, int height_px, const std::string& camera,
      const RenderLabel& label = {});

  // Which of the model's geoms each pixel shows, as render_rgb would draw
  // the state without overlay (MuJoCo's segmentation rendering): the geom
  // id, or -1 for the background, a decoration or the hand. Rows from the
  // top, width_px * height_px entries. For measuring what a camera frames
  // (tests/viz/render_test.cc, the device's share of each camera's frame).
  std::vector<int> render_geom_ids(const mjModel* m, mjData* d, int width_px,
                                   int height_px, const std::string& camera);

  // The last frame's scene: its camera (scene().camera[0]) says how world
  // points project to pixels.
  const mjvScene& scene() const { return scn_; }
  int buffer_width_px() const { return con_.offWidth; }
  int buffer_height_px() const { return con_.offHeight; }

 private:
  const mjModel* m_;
  mjvScene scn_;
  mjvOption opt_;
  mjvCamera free_cam_;
  mjrContext con_;
};

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_SCENE_RENDERER_H_
