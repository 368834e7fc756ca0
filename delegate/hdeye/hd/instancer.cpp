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
  transforms_ = std::move(transforms);
  colors_ = std::move(colors);
  ++syncs_;
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
