#include "hdeye/prims/motionSync.h"

#include "hdeye/prims/renderParam.h"

#include <stdexcept>

namespace hdeye {

namespace {
/// The render's shutter; closed at frame 0 for a sync without a render param (tests syncing one prim).
Shutter ShutterOf(const RenderParam* renderParam) { return renderParam ? renderParam->GetShutter() : Shutter{}; }
}  // namespace

PrimMotion SyncTransformMotion(SceneDelegate* sceneDelegate, RenderParam* renderParam, const PrimId& id,
                               const std::string& what) {
  const TimeSampled<Matrix4d> samples = sceneDelegate->SampleTransform(id);
  if (samples.values.size() == 1 || (!samples.values.empty() && SamplesAllEqual(samples)))
    return {samples.values.front(), nullptr};
  std::vector<std::string> warnings;
  std::optional<TransformMotion> motion = MakeTransformMotion(samples, what, &warnings);
  for (const std::string& w : warnings)
    if (renderParam) renderParam->Warn(w);
  if (!motion) throw std::runtime_error(what + ": no usable transform sample");
  const Shutter shutter = ShutterOf(renderParam);
  if (!shutter.IsOpen() || motion->Static()) return {motion->At(shutter.open), nullptr};
  PrimMotion out;
  out.transform = motion->At(shutter.open);
  out.motion = std::make_shared<const TransformMotion>(std::move(*motion));
  return out;
}

PointSteps SyncPointSteps(SceneDelegate* sceneDelegate, RenderParam* renderParam, const PrimId& id,
                          const std::string& what) {
  TimeSampled<std::vector<Vec3f>> samples = sceneDelegate->SamplePoints(id);
  const Shutter shutter = ShutterOf(renderParam);
  if (samples.values.size() <= 1) return {std::move(samples.values), {shutter.open}};
  for (const std::vector<Vec3f>& p : samples.values)
    if (p.size() != samples.values[0].size()) throw std::runtime_error(what + ": point samples differ in count");
  if (samples.times.size() != samples.values.size()) throw std::runtime_error(what + ": point sample times mismatch");
  const std::vector<double> authored(samples.times.begin(), samples.times.end());
  PointSteps out;
  out.times = MotionStepTimes(authored, shutter.open, shutter.close);
  for (double t : out.times) out.points.push_back(PointsAt(samples, t));
  // Points that do not move over the shutter render as one step.
  bool moves = false;
  for (std::size_t k = 1; k < out.points.size() && !moves; ++k) moves = out.points[k] != out.points[0];
  if (!moves) out.points.resize(1), out.times.resize(1);
  return out;
}

void SetInstanceMotion(RTCGeometry instance, const Matrix4d& world, const TransformMotion* motion) {
  if (!motion || motion->Static()) {
    rtcSetGeometryTimeStepCount(instance, 1);
    const glm::mat4 m(world);
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &m[0][0]);
    return;
  }
  rtcSetGeometryTimeStepCount(instance, unsigned(motion->parts.size()));
  for (std::size_t k = 0; k < motion->parts.size(); ++k) {
    const TransformParts& p = motion->parts[k];
    RTCQuaternionDecomposition qd;
    rtcInitQuaternionDecomposition(&qd);
    rtcQuaternionDecompositionSetScale(&qd, float(p.stretch[0][0]), float(p.stretch[1][1]), float(p.stretch[2][2]));
    rtcQuaternionDecompositionSetSkew(&qd, float(p.stretch[1][0]), float(p.stretch[2][0]), float(p.stretch[2][1]));
    rtcQuaternionDecompositionSetQuaternion(&qd, float(p.rotation.w), float(p.rotation.x), float(p.rotation.y),
                                            float(p.rotation.z));
    rtcQuaternionDecompositionSetTranslation(&qd, float(p.translation.x), float(p.translation.y),
                                             float(p.translation.z));
    rtcSetGeometryTransformQuaternion(instance, unsigned(k), &qd);
  }
}

std::shared_ptr<const TransformMotion> SteppedMotion(const std::vector<double>& authoredTimes, const Shutter& shutter,
                                                     const std::function<Matrix4d(double)>& world) {
  if (!shutter.IsOpen()) return nullptr;
  std::optional<TransformMotion> stepped =
      ResampleMotion(MotionStepTimes(authoredTimes, shutter.open, shutter.close), world);
  if (!stepped || stepped->Static()) return nullptr;
  return std::make_shared<const TransformMotion>(std::move(*stepped));
}

}  // namespace hdeye
