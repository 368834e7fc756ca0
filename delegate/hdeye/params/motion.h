#pragma once
// Interpolating transforms over the shutter. A transform splits into world = T * R * U: a translation T, a rotation
// R (a unit quaternion) and an upper-triangular U (scales on its diagonal, shears above it), the decomposition
// Embree's quaternion motion blur takes (RTCQuaternionDecomposition). Between two samples the translation and U
// interpolate linearly and the rotation by spherical linear interpolation, so a turning eye keeps its shape where
// a linear blend of matrices would shrink it. For the usual translate-rotate-scale transforms U is the diagonal
// scale and R the rotation of the polar decomposition; with shear the two decompositions differ, and this one is
// Embree's, so analytic eyes, lights and cameras move exactly as the instances Embree intersects.
#include "hdeye/params/primParams.h"
#include "hdeye/params/timeSampled.h"

#include <glm/gtc/quaternion.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace hdeye {

/// A render's shutter interval, frames relative to the frame (CameraParams::shutterOpen, shutterClose). Embree's
/// ray time runs over [0, 1]; time 0 is the shutter's opening.
struct Shutter {
  double open = 0, close = 0;
  bool IsOpen() const { return close > open; }
  /// The Embree ray time of frame time `time` (0 when the shutter is closed: one sharp instant).
  float RayTime(double time) const { return IsOpen() ? float((time - open) / (close - open)) : 0.0f; }
  /// The frame time of an Embree ray time.
  double FrameTime(float rayTime) const { return open + double(rayTime) * (close - open); }
  bool operator==(const Shutter& o) const { return open == o.open && close == o.close; }
  bool operator!=(const Shutter& o) const { return !(*this == o); }
};

/// A transform as world = translate(translation) * mat3(rotation) * stretch.
struct TransformParts {
  glm::dquat rotation{1, 0, 0, 0};
  glm::dmat3 stretch{1.0};  ///< upper triangular (column-major: stretch[col][row] == 0 for row > col)
  glm::dvec3 translation{0.0};
};

/// The parts of an affine transform, or nothing when it has non-finite entries or a singular linear part. A
/// reflection (negative determinant) keeps a proper rotation and puts the mirror into stretch's last scale.
std::optional<TransformParts> DecomposeTransform(const Matrix4d& m);
Matrix4d ComposeTransform(const TransformParts& parts);
/// `a` at u = 0 to `b` at u = 1: translation and stretch linearly, rotation by slerp along the shorter arc (a
/// half turn, where both arcs are equal, turns the way b's stored sign says; identical rotations stay put).
TransformParts InterpolateParts(const TransformParts& a, const TransformParts& b, double u);

/// A transform's motion over the shutter, ready to evaluate at any time: decomposed samples.
struct TransformMotion {
  std::vector<double> times;          ///< ascending, frames relative to the frame
  std::vector<TransformParts> parts;  ///< per time; consecutive quaternions on the same hemisphere
  bool Static() const { return parts.size() <= 1; }
  /// The transform at `time` (frames): clamped to the first and last samples outside them.
  Matrix4d At(double time) const;
  TransformParts PartsAt(double time) const;
};

/// Builds a TransformMotion from authored samples. Samples with non-finite or singular matrices are skipped, and so
/// are samples whose determinant's sign differs from the first kept one (a motion through a mirror passes through a
/// singular transform, which no rigid interpolation can follow); each skip appends one line to `warnings` (naming
/// `what`). Unsorted or duplicate times keep the first sample of each time. Nothing usable: std::nullopt.
std::optional<TransformMotion> MakeTransformMotion(const TimeSampled<Matrix4d>& samples, const std::string& what,
                                                   std::vector<std::string>* warnings);

/// The times Embree's motion blur steps through for a motion over [open, close] (frames): Embree needs steps
/// uniformly spaced over the geometry's time range, so authored times in the shutter are used as they are when they
/// are uniform (to 1e-4 of the shutter), and otherwise resampled onto the uniform grid of spacing no larger than the
/// smallest gap between them (at most kMaxMotionSteps steps). Samples outside the shutter only shape the ends (the
/// motion is interpolated at open and close). One time (a sharp shutter, or one sample) when nothing moves.
std::vector<double> MotionStepTimes(const std::vector<double>& authoredTimes, double open, double close);
/// Embree 3 allows 129 time steps per geometry; more than this many steps buys nothing a film shutter shows.
constexpr int kMaxMotionSteps = 33;

/// The motion resampled at `stepTimes` (MotionStepTimes): what Embree interpolates between, so the renderer's own
/// evaluations (normals, eyes, lights) follow exactly the motion Embree intersects. `world` gives the transform at a
/// time; quaternions are kept on one hemisphere step to step. Nothing when a step's transform cannot be decomposed.
std::optional<TransformMotion> ResampleMotion(const std::vector<double>& stepTimes,
                                              const std::function<Matrix4d(double)>& world);

/// Whether every sample equals the first (a prim authored with samples that do not move).
bool SamplesAllEqual(const TimeSampled<Matrix4d>& samples);

/// Piecewise-linear interpolation of points between samples at `time` (frames), clamped at the ends; every sample
/// must have the same count.
std::vector<Vec3f> PointsAt(const TimeSampled<std::vector<Vec3f>>& samples, double time);

}  // namespace hdeye
