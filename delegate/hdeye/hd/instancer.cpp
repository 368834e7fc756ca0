#include "hdeye/hd/instancer.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

void Instancer::Sync(SceneDelegate* sceneDelegate, RenderParam* /*renderParam*/, DirtyBits* dirtyBits) {
  std::vector<Matrix4d> transforms = sceneDelegate->GetInstanceTransforms(Id());
  std::vector<Vec3f> colors = sceneDelegate->GetInstanceColors(Id());
  for (std::size_t i = 0; i < transforms.size(); ++i)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(transforms[i][c][r]))
          throw std::runtime_error("instancer " + Id() + ": instance " + std::to_string(i) +
                                   " has a non-finite transform");
  if (!colors.empty() && colors.size() != transforms.size())
    throw std::runtime_error("instancer " + Id() + ": " + std::to_string(colors.size()) + " colours for " +
                             std::to_string(transforms.size()) + " instances");
  SyncMotions(sceneDelegate, transforms.size());
  transforms_ = std::move(transforms);
  colors_ = std::move(colors);
  ++syncs_;
  *dirtyBits = dirty::Clean;
}

void Instancer::SyncMotions(SceneDelegate* sceneDelegate, std::size_t count) {
  motions_.clear();
  motionWarnings_.clear();
  const TimeSampled<std::vector<Matrix4d>> samples = sceneDelegate->SampleInstanceTransforms(Id());
  if (samples.values.size() <= 1) return;
  if (samples.times.size() != samples.values.size())
    throw std::runtime_error("instancer " + Id() + ": instance transform sample times and values differ in count");
  for (const std::vector<Matrix4d>& perTime : samples.values)
    if (perTime.size() != count)
      throw std::runtime_error("instancer " + Id() + ": an instance transform sample has " +
                               std::to_string(perTime.size()) + " instances, not " + std::to_string(count));
  std::vector<std::shared_ptr<const TransformMotion>> motions(count);
  bool any = false;
  for (std::size_t i = 0; i < count; ++i) {
    TimeSampled<Matrix4d> one{samples.times, {}};
    for (const std::vector<Matrix4d>& perTime : samples.values) one.values.push_back(perTime[i]);
    if (SamplesAllEqual(one)) continue;
    std::optional<TransformMotion> motion =
        MakeTransformMotion(one, "instancer " + Id() + " instance " + std::to_string(i), &motionWarnings_);
    if (!motion || motion->Static()) continue;
    motions[i] = std::make_shared<const TransformMotion>(std::move(*motion));
    any = true;
  }
  if (any) motions_ = std::move(motions);
}

}  // namespace hdeye
