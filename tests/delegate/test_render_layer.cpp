// The renderer as a layer of its own: this executable links hdeye_render (and what it needs below: hdeye_image,
// eyelib, Embree, TBB) and nothing of the Hydra framework or the prims, so it only builds while that wall holds.
#include "hdeye/render/renderer.h"

#include <catch2/catch.hpp>

#include <embree3/rtcore.h>

TEST_CASE("the renderer renders without the Hydra framework or the prims: an empty scene is black and transparent",
          "[render]") {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(device);
  rtcCommitScene(scene);
  hdeye::AccumulationBuffer color("color", 3, 2, 4);
  hdeye::AovBuffers aovs;
  aovs.color = &color;
  hdeye::RenderSettings settings;
  settings.samplesPerPixel = 2;
  const hdeye::RenderStats stats = hdeye::Renderer().Render(scene, hdeye::CameraView{}, {}, settings, aovs);
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  CHECK(stats.samples == 2 * 3 * 2);
  CHECK(stats.passes == 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 4; ++c) CHECK(color.Resolved(x, y, c) == 0.0f);
}
