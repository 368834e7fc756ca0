#include "hdeye/render/movingLights.h"

namespace hdeye {

bool AnyLightMoves(const std::vector<RenderLight>& lights) {
  for (const RenderLight& l : lights)
    if (l.motion) return true;
  return false;
}

void MoveLightTo(const RenderLight& source, double time, RenderLight* out) {
  if (!source.motion) return;
  const LightMotion& m = *source.motion;
  RenderLight moved = RenderLight::FromParams(m.params, m.transform->At(time), m.dome, m.rectImage);
  moved.unlit.swap(out->unlit);
  moved.unshadowed.swap(out->unshadowed);
  moved.motion = source.motion;
  *out = std::move(moved);
}

}  // namespace hdeye
