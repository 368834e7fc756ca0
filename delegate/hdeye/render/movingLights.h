#pragma once
// Lights that move over the shutter: each path sees every light where it is at the path's time (position, axes and
// the radiance a `normalize`d light's world-space size sets), rebuilt from its parameters and its transform then.
#include "hdeye/params/motion.h"
#include "hdeye/render/renderLight.h"

#include <memory>
#include <vector>

namespace hdeye {

/// What a moving light is rebuilt from (RenderLight::FromParams' arguments, the transform as a motion).
struct LightMotion {
  std::shared_ptr<const TransformMotion> transform;  ///< frames; never null
  LightParams params;
  std::shared_ptr<const DomeTexture> dome;
  std::shared_ptr<const Texture> rectImage;
};

/// Whether any light moves.
bool AnyLightMoves(const std::vector<RenderLight>& lights);

/// `*out` becomes `source` at frame time `time`: rebuilt from source.motion (its light and shadow links kept; out
/// must already hold a copy of source, so the links move instead of being copied per path). A static source is left
/// as it is.
void MoveLightTo(const RenderLight& source, double time, RenderLight* out);

}  // namespace hdeye
