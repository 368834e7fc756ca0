#pragma once
// A camera as the renderer sees it: its parameters and camera-to-world transform, and the rays it shoots
// (perspective or orthographic, looking down its local -z axis; a thin lens when CameraParams::fStop > 0).
#include "hdeye/params/motion.h"
#include "hdeye/params/primParams.h"

#include <memory>

namespace hdeye {

/// A world-space ray (direction unit length).
struct WorldRay {
  glm::dvec3 origin, dir;
  double tNear, tFar;
};

/// What the renderer needs of a camera: its parameters and its camera-to-world transform.
struct CameraView {
  CameraParams params;
  Matrix4d transform{1.0};
  /// The camera's motion over the open shutter (frames), or null: `transform` holds for every path.
  std::shared_ptr<const TransformMotion> motion;

  Shutter GetShutter() const { return {params.shutterOpen, params.shutterClose}; }
  /// The camera as a path at frame time `time` sees it (itself when it does not move).
  CameraView AtTime(double time) const {
    if (!motion) return *this;
    CameraView view = *this;
    view.transform = motion->At(time);
    return view;
  }

  /// Whether rays start on a lens of non-zero aperture (a perspective camera with fStop > 0): GenerateRay then
  /// reads its lens sample.
  bool HasLens() const { return LensApertureDiameter(params) > 0; }

  /// The ray through film position (u, v) in [0, 1]^2 (u right, v down) of an image of the given
  /// aspect (width / height), fitting the film's width. With a lens (HasLens), (lensU, lensV) in [0, 1)^2 pick
  /// a point on the aperture disk (concentric map) and the ray goes from it through the point the pinhole ray
  /// meets on the plane in focus (pbrt's thin lens: the field of view stays the pinhole's, as USD's projection
  /// has it); without one they are ignored and the ray is the pinhole's.
  WorldRay GenerateRay(double u, double v, double imageAspect, double lensU = 0.5, double lensV = 0.5) const;
};

/// Shirley and Chiu's concentric map of [0, 1)^2 onto the unit disk (area preserving, continuous).
glm::dvec2 ConcentricDisk(double u1, double u2);

}  // namespace hdeye
