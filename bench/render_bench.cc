// The wall time of one headless render (viz/scene_renderer.h): MuJoCo's
// scene update with the overlay, mjr_render into the offscreen buffer, the
// read-back, and the PNG encoding, at 640x480 and 1280x720. Needs an
// OpenGL context; run it by hand under Xvfb:
//   xvfb-run -a -s "-screen 0 1280x1024x24" build/bench/render_bench
// The figures are reported (viz/README.md), never asserted.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "sim/closed_loop.h"
#include "thesis/run_case.h"
#include "viz/gl_context.h"
#include "viz/overlay.h"
#include "viz/png.h"
#include "viz/scene_renderer.h"

namespace vmh::viz {
namespace {

// case1 at 2.5 s (the hand pulled off the circle, the force arrow drawn);
// arguments: width, height in px; encode: 1 also encodes the PNG
void BM_Render(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0));
  const int h = static_cast<int>(state.range(1));
  const bool encode = state.range(2) != 0;
  std::string name;
  sim::ClosedLoop loop(sim::resolve_scene("case1", &name), {});
  TickRecord row;
  while (loop.time_s() < 2.5 - 1e-9) loop.tick(&row);
  std::vector<OverlayPrimitive> prims;
  overlay_primitives(loop.controller().mechanism(), loop.controller_params(),
                     row.out, OverlayOptions(), &prims);
  GlContext gl;
  SceneRenderer r(loop.model(), loop.controller_params().omni, w, h);
  const RenderLabel label{"case1\nt", "\n2.500 s"};
  for (auto _ : state) {
    std::vector<std::uint8_t> rgb =
        r.render_rgb(loop.model(), loop.data(), prims, w, h, "", label);
    if (encode) {
      benchmark::DoNotOptimize(encode_png(w, h, rgb));
    } else {
      benchmark::DoNotOptimize(rgb.data());
    }
  }
}
BENCHMARK(BM_Render)
    ->Args({640, 480, 0})
    ->Args({640, 480, 1})
    ->Args({1280, 720, 0})
    ->Args({1280, 720, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace vmh::viz

BENCHMARK_MAIN();
