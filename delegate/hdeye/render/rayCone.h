#pragma once
// The footprint of a path's rays on the surfaces it meets, for filtered texture lookups: a ray cone
// (Akenine-Moller et al., "Texture Level of Detail Strategies for Real-Time Ray Tracing", 2019).
//
// A cone has a width (scene units, the footprint's diameter where the ray starts) and a spread angle
// (radians, how fast the width grows per unit of distance). The camera starts it at a fraction of a
// pixel (RenderSettings::textureFootprintScale): width the pixel's size at the camera (orthographic),
// spread the angle between neighbouring pixels' rays (perspective), both times that fraction. At a hit
// the width is width + spread * t; the footprint on the surface is an ellipse whose axes are that width
// across the ray and width / |cos| along it, and mapped through the triangle's (s, t) parameterisation
// it gives the lookup's derivatives.
//
// What it approximates, and why that is enough here: surface curvature is ignored (a mirror or glass
// event keeps the spread; a curved mirror would change it), and a rough or diffuse bounce widens the
// spread by kRoughSpreadWidening rather than by the lobe's true angular extent. Secondary lookups then
// blur more than a ray differential would, which only removes texture noise from indirect light;
// what the camera sees directly is filtered from the exact pixel footprint.
#include <glm/glm.hpp>

#include "hdeye/render/texture.h"

namespace hdeye {

/// Radians added to the spread at each non-delta (diffuse or rough) bounce.
constexpr double kRoughSpreadWidening = 0.25;

struct RayCone {
  double width = 0;   ///< scene units at the ray's origin
  double spread = 0;  ///< radians; the width grows by spread per scene unit travelled

  double WidthAt(double t) const { return width + spread * t; }
  /// The cone leaving a hit at distance t: delta events keep the spread, rough ones widen it.
  RayCone AfterBounce(double t, bool delta) const {
    return {WidthAt(t), delta ? spread : std::min(3.14159265358979, spread + kRoughSpreadWidening)};
  }
};

/// How st varies over a triangle: the surface tangents dp/ds and dp/dt (world units per st unit).
struct StFrame {
  glm::dvec3 dpds{0}, dpdt{0};
  bool valid = false;  ///< false for a degenerate st mapping (collapsed or zero area in st)
};

/// dp/ds and dp/dt of the triangle with world corners p0..p2 and texture coordinates st0..st2.
StFrame TriangleStFrame(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec2& st0,
                        const glm::dvec2& st1, const glm::dvec2& st2);

/// The lookup footprint of a cone of `width` (scene units, at the hit) arriving along unit `dir` at a
/// surface of unit normal `n` with st frame `frame`. Zero (the finest level) when the frame is invalid.
TextureFootprint FootprintOnSurface(double width, const glm::dvec3& dir, const glm::dvec3& n, const StFrame& frame);

}  // namespace hdeye
