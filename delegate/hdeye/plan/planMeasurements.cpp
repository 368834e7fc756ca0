#include "hdeye/plan/renderPlan.h"

#include "hdeye/render/renderContext.h"

#include <eyelib/eye_constants.h>
#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>
#include <limits>

// The plan's facts: what the camera sees of an eye and what each light is to it. The decisions read only these.
namespace hdeye {

namespace {

using eyelib::paper::kPi;
constexpr double kDeg = 180 / kPi;
constexpr int kCirclePoints = 64;  // samples of the iris circle: the chord error is under 0.2% of its diameter
/// The iris centre (canonical (0, 0, irisZ)) in world space: where the lights are measured from.
glm::dvec3 IrisCentre(const EyeGeometry& eye) { return eye.ToWorld({0, 0, eye.chamber.IrisZ()}); }

/// Solid angle (sr) of a cone of half-angle alpha (radians).
double ConeSolidAngle(double cosAlpha) { return 2 * kPi * (1 - cosAlpha); }

/// A flat emitter of `area` (world units^2) facing `normal`, seen from `p`: its solid angle as the
/// small-light approximation area cos / d^2, capped at a hemisphere (sr).
double FlatSolidAngle(double area, const glm::dvec3& centre, const glm::dvec3& normal, const glm::dvec3& p,
                      bool* facing) {
  const glm::dvec3 to = p - centre;
  const double d = glm::length(to);
  const double cosAtLight = d > 0 ? glm::dot(to / d, normal) : 1;
  *facing = cosAtLight > 0;
  if (!(d > 0)) return 2 * kPi;
  return std::min(2 * kPi, area * std::max(0.0, cosAtLight) / (d * d));
}

/// A dome's luminance contrast E[L^2] / E[L]^2 over cosine-distributed directions about the gaze, from `p` (a
/// stratified kSide x kSide grid of them); 1 for a dome that sends nothing there.
double DomeContrast(const RenderLight& light, const glm::dvec3& p, const glm::dvec3& gaze) {
  constexpr int kSide = 32;
  double sum = 0, sumSquares = 0;
  for (int a = 0; a < kSide; ++a)
    for (int b = 0; b < kSide; ++b) {
      const glm::dvec3 d = eyelib::SampleCosineHemisphere(gaze, (a + 0.5) / kSide, (b + 0.5) / kSide);
      glm::dvec3 radiance(0);
      double pdf = 0, distance = 0;
      if (!IntersectLight(light, p, d, std::numeric_limits<double>::infinity(), &radiance, &pdf, &distance)) continue;
      const double L = std::max(0.0, 0.2126 * radiance.x + 0.7152 * radiance.y + 0.0722 * radiance.z);
      sum += L, sumSquares += L * L;
    }
  const double n = kSide * kSide;
  return sum > 0 && std::isfinite(sumSquares) ? sumSquares * n / (sum * sum) : 1;
}

}  // namespace

EyePlan MeasureEye(const PrimId& prim, const std::string& geometry, const EyeGeometry& eye, const CameraView& camera,
                   int width, int height) {
  EyePlan plan;
  plan.prim = prim;
  plan.geometry = geometry;
  const glm::dmat4 worldToCamera = glm::inverse(camera.transform);
  const CameraParams& cp = camera.params;
  const double halfW = cp.horizontalAperture / 2, halfH = halfW * height / width;  // film (mm or units)

  // The 15.08 mm circle at the iris plane, projected to pixels (x right, y down), as the camera's
  // GenerateRay maps them.
  std::vector<glm::dvec2> front;
  int behind = 0;
  const double R = eyelib::paper::kRimRadius;
  for (int k = 0; k < kCirclePoints; ++k) {
    const double a = 2 * kPi * k / kCirclePoints;
    const glm::dvec3 c(worldToCamera *
                       glm::dvec4(eye.ToWorld({R * std::cos(a), R * std::sin(a), eye.chamber.IrisZ()}), 1));
    if (!(c.z < 0)) {  // on or behind the camera plane (the camera looks down its -z)
      ++behind;
      continue;
    }
    const double fx = cp.orthographic ? c.x : cp.focalLength * c.x / -c.z;
    const double fy = cp.orthographic ? c.y : cp.focalLength * c.y / -c.z;
    front.push_back({(fx / halfW + 1) / 2 * width, (1 - fy / halfH) / 2 * height});
  }
  plan.behindCamera = behind == kCirclePoints;
  if (behind > 0 && !front.empty()) {
    // The circle crosses the camera plane: it surrounds the camera and fills the view.
    plan.pixels = std::hypot(double(width), double(height));
    plan.inView = true;
  } else if (!front.empty()) {
    double longest = 0;
    glm::dvec2 lo(1e300), hi(-1e300);
    for (std::size_t i = 0; i < front.size(); ++i) {
      lo = glm::min(lo, front[i]), hi = glm::max(hi, front[i]);
      for (std::size_t j = i + 1; j < front.size(); ++j) longest = std::max(longest, glm::length(front[i] - front[j]));
    }
    plan.pixels = longest;
    plan.inView = hi.x >= 0 && lo.x <= width && hi.y >= 0 && lo.y <= height;
  }
  // The circle of confusion at the iris centre's depth along the view axis (film units, then pixels).
  const double depth = -glm::dvec3(worldToCamera * glm::dvec4(IrisCentre(eye), 1)).z;
  const double aperture = LensApertureDiameter(cp), focus = cp.focusDistance;
  if (aperture > 0 && focus > 0 && depth > 0)
    plan.blurPixels =
        aperture * cp.focalLength * std::abs(depth - focus) / (depth * focus) / cp.horizontalAperture * width;
  plan.resolvedPixels = plan.pixels / std::max(1.0, plan.blurPixels);
  plan.limbusPixels = plan.resolvedPixels * (eye.chamber.LimbusOuterRadius() - eye.chamber.LimbusInnerRadius()) /
                      (2 * eyelib::paper::kRimRadius);

  const glm::dvec3 centre = IrisCentre(eye), gaze = eye.DirToWorld({0, 0, 1});
  const glm::dvec3 camPos(camera.transform * glm::dvec4(0, 0, 0, 1));
  const glm::dvec3 toCamera = cp.orthographic ? glm::normalize(glm::dvec3(camera.transform * glm::dvec4(0, 0, 1, 0)))
                                              : glm::normalize(camPos - centre);
  plan.viewAngleDeg = std::acos(std::clamp(glm::dot(gaze, toCamera), -1.0, 1.0)) * kDeg;
  return plan;
}

/// MeasureEye over the open shutter: at the shutter's ends and every motion sample of the eye and the camera inside
/// it, the measurement where the eye is largest on screen (a saccade's footprint is its widest pose's); in view if
/// it is in view at any of them.
EyePlan MeasureEyeOverShutter(const PrimId& prim, const std::string& geometry, const EyeGeometry& eye,
                              const CameraView& camera, int width, int height) {
  const Shutter shutter = camera.GetShutter();
  if (!shutter.IsOpen() || (!eye.motion && !camera.motion))
    return MeasureEye(prim, geometry, eye, camera, width, height);
  std::vector<double> times{shutter.open, shutter.close};
  for (const TransformMotion* m : {eye.motion ? eye.motion->prim.get() : nullptr, camera.motion.get()})
    if (m)
      for (double t : m->times)
        if (t > shutter.open && t < shutter.close) times.push_back(t);
  EyePlan widest;
  bool inView = false, first = true;
  for (double t : times) {
    EyePlan e = MeasureEye(prim, geometry, eye.AtTime(t), camera.AtTime(t), width, height);
    inView = inView || e.inView;
    if (first || e.pixels > widest.pixels) widest = std::move(e), first = false;
  }
  widest.inView = inView;
  return widest;
}

LightFacts MeasureLight(const PrimId& lightId, const RenderLight& light, const EyeGeometry& eye) {
  LightFacts f;
  f.light = lightId;
  f.kind = light.type;
  const glm::dvec3 p = IrisCentre(eye), gaze = eye.DirToWorld({0, 0, 1});
  glm::dvec3 dir(0);  // towards the light's centre
  bool facing = true;
  switch (light.type) {
    case LightType::Dome:
      f.solidAngleSr = 4 * kPi;
      f.angleOffGazeDeg = -1;
      f.angularRadiusDeg = 180;
      f.reachesIris = true;
      f.radianceContrast = DomeContrast(light, p, gaze);
      return f;
    case LightType::Distant:
      dir = glm::normalize(light.direction);
      f.angularRadiusDeg = std::acos(std::clamp(light.cosHalfAngle, -1.0, 1.0)) * kDeg;
      f.solidAngleSr = ConeSolidAngle(light.cosHalfAngle);
      break;
    case LightType::Sphere: {
      const glm::dvec3 to = light.position - p;
      const double d = glm::length(to);
      if (!(d > light.radius)) {  // the eye is inside the light
        f.solidAngleSr = 4 * kPi, f.angleOffGazeDeg = -1, f.angularRadiusDeg = 180;
        return f;
      }
      dir = to / d;
      const double sinA = light.radius / d;
      f.angularRadiusDeg = std::asin(sinA) * kDeg;
      f.solidAngleSr = ConeSolidAngle(std::sqrt(1 - sinA * sinA));
      break;
    }
    case LightType::Cylinder: {
      // Its silhouette from p, 2 r l sin(angle to the axis) over d^2 (a line: its radius is 0, nothing to
      // resolve), as the cone of the same solid angle.
      const glm::dvec3 to = light.position - p;
      const double d = glm::length(to);
      dir = d > 0 ? to / d : gaze;
      const double width = 2 * std::max(light.radius, 0.0) * 2 * light.halfLength;
      f.solidAngleSr = d > 0 ? std::min(2 * kPi, width * glm::length(glm::cross(dir, light.axisU)) / (d * d)) : 2 * kPi;
      f.angularRadiusDeg = std::acos(std::clamp(1 - f.solidAngleSr / (2 * kPi), -1.0, 1.0)) * kDeg;
      break;
    }
    case LightType::Rect:
    case LightType::Disk: {
      const double area = light.type == LightType::Rect ? 4 * glm::length(glm::cross(light.axisU, light.axisV))
                                                        : kPi * light.radius * light.radius;
      f.solidAngleSr = FlatSolidAngle(area, light.position, light.direction, p, &facing);
      const glm::dvec3 to = light.position - p;
      dir = glm::length(to) > 0 ? glm::normalize(to) : gaze;
      // The cone of the same solid angle: a light's reach above the rim plane, approximately.
      f.angularRadiusDeg = std::acos(std::clamp(1 - f.solidAngleSr / (2 * kPi), -1.0, 1.0)) * kDeg;
      break;
    }
  }
  f.angleOffGazeDeg = std::acos(std::clamp(glm::dot(dir, gaze), -1.0, 1.0)) * kDeg;
  // Light reaches the iris through the cornea only from above the rim plane: below it the sclera is in
  // the way (MNEE reports Occluded; docs/mnee.md). The planes of the rim and the iris differ by a micron.
  f.reachesIris = facing && f.angleOffGazeDeg - f.angularRadiusDeg < 90;
  return f;
}

}  // namespace hdeye
