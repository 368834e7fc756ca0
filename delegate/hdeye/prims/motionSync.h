#pragma once
// How prims read their motion samples (SceneDelegate::SampleTransform, SamplePoints) against the render's shutter,
// and how they hand a transform motion to an Embree instance. A prim whose samples do not move over an open shutter,
// or any prim under a closed one, stays a single-step (static) geometry: motion costs nothing where there is none.
#include "hdeye/hd/sceneDelegate.h"
#include "hdeye/params/motion.h"

#include <embree3/rtcore.h>

#include <memory>
#include <string>

namespace hdeye {

class RenderParam;

/// A prim's transform as the render uses it.
struct PrimMotion {
  /// Shutter closed, or nothing moves: the transform (at the shutter's time). Open: the transform at its opening.
  Matrix4d transform{1.0};
  /// The authored motion (frames), when the shutter is open and the samples move; null otherwise.
  std::shared_ptr<const TransformMotion> motion;
};

/// The prim's transform samples read through SampleTransform against renderParam's shutter. Bad samples (NaN,
/// singular, a mirror flip) are skipped with one warning each naming `what` (e.g. "mesh /World/Lid"); when none is
/// usable std::runtime_error names the prim.
PrimMotion SyncTransformMotion(SceneDelegate* sceneDelegate, RenderParam* renderParam, const PrimId& id,
                               const std::string& what);

/// The points of a point-based prim per Embree time step: one set (static, or the points at a closed shutter's
/// time) or one per step of MotionStepTimes over the open shutter.
struct PointSteps {
  std::vector<std::vector<Vec3f>> points;  ///< one entry per time step
  std::vector<double> times;               ///< frames, the steps' times
};
/// From SamplePoints; std::runtime_error naming `what` when the samples differ in count.
PointSteps SyncPointSteps(SceneDelegate* sceneDelegate, RenderParam* renderParam, const PrimId& id,
                          const std::string& what);

/// Sets an Embree instance's transform for the render: `world` at one step (rtcSetGeometryTransform, as a static
/// instance always was), or, when `motion` is set (times uniform over the open shutter, ResampleMotion's), one
/// quaternion decomposition per step so Embree slerps the rotation as TransformMotion does.
void SetInstanceMotion(RTCGeometry instance, const Matrix4d& world, const TransformMotion* motion);

/// The motion of `world(t)` over the open shutter, resampled on the uniform steps Embree takes (MotionStepTimes over
/// `authoredTimes`); null when the shutter is closed or the resampling fails (then the caller keeps a static world).
std::shared_ptr<const TransformMotion> SteppedMotion(const std::vector<double>& authoredTimes, const Shutter& shutter,
                                                     const std::function<Matrix4d(double)>& world);

}  // namespace hdeye
