#include "hdeye/render/cameraView.h"

#include "hdeye/render/fastTrig.h"

#include <glm/glm.hpp>

#include <cmath>

namespace hdeye {

glm::dvec2 ConcentricDisk(double u1, double u2) {
  constexpr double kQuarterPi = 0.78539816339744830962;
  const double a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  // Shirley and Chiu's angle phi = pi/4 (b/a), or pi/2 - pi/4 (a/b): its reduced part x lies in [-pi/4, pi/4], and
  // the second case's cos and sin are sin x and cos x.
  const bool wide = std::abs(a) > std::abs(b);
  const double r = wide ? a : b, x = kQuarterPi * (wide ? b / a : a / b);
  double s, c;
  SinCosReduced(x, &s, &c);
  return wide ? glm::dvec2(r * c, r * s) : glm::dvec2(r * s, r * c);
}

WorldRay CameraView::GenerateRay(double u, double v, double imageAspect, double lensU, double lensV) const {
  const double halfW = params.horizontalAperture / 2, halfH = halfW / imageAspect;
  const double fx = (2 * u - 1) * halfW, fy = (1 - 2 * v) * halfH;
  // Normalisations as a reciprocal square root times the vector; the pinhole's camera direction is not normalised
  // before the transform (the world one is), only its axis cosine taken.
  glm::dvec3 o(0), d;
  double invCosAxis = 1;  // clipping distances are along the view axis: the ray parameter of a unit direction
  if (params.orthographic) {
    o = {fx, fy, 0};
    d = {0, 0, -1};
  } else {
    d = glm::dvec3(fx, fy, -params.focalLength);
    const double len = std::sqrt(glm::dot(d, d));
    invCosAxis = len / params.focalLength;
    if (HasLens() && params.focusDistance > 0) {
      const glm::dvec3 focus = d * (params.focusDistance / params.focalLength);  // on the plane z = -focusDistance
      const glm::dvec2 lens = ConcentricDisk(lensU, lensV) * (LensApertureDiameter(params) / 2);
      o = {lens.x, lens.y, 0};
      d = focus - o;
      invCosAxis = std::sqrt(glm::dot(d, d)) / -d.z;
    }
  }
  const glm::dvec3 wo = o.x == 0 && o.y == 0 ? glm::dvec3(transform[3]) : glm::dvec3(transform * glm::dvec4(o, 1));
  const glm::dvec3 wd = glm::dmat3(transform) * d;
  return {wo, wd * (1 / std::sqrt(glm::dot(wd, wd))), params.nearClip * invCosAxis, params.farClip * invCosAxis};
}

}  // namespace hdeye
