#pragma once
// A camera as the renderer sees it: its parameters and camera-to-world transform, and the rays it shoots
// (perspective or orthographic, looking down its local -z axis).
#include "hdeye/render/params.h"

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

  /// The ray through film position (u, v) in [0, 1]^2 (u right, v down) of an image of the given
  /// aspect (width / height), fitting the film's width.
  WorldRay GenerateRay(double u, double v, double imageAspect) const;
};

}  // namespace hdeye
