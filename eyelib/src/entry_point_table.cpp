#include "eyelib/entry_point_table.h"

#include <algorithm>
#include <cmath>

namespace eyelib {

EntryPointTable::EntryPointTable(const AnteriorChamber<double>& chamber, const LightEnd& light)
    : light_(light), half_(chamber.IrisRadius()), nodes_(kNodes * kNodes) {
  const double step = 2 * half_ / (kNodes - 1), inside = half_ * (1 - 1e-9);
  for (int j = 0; j < kNodes; ++j)
    for (int i = 0; i < kNodes; ++i) {
      Vec3d x(-half_ + i * step, -half_ + j * step, chamber.IrisZ());
      // Nodes past the disk's edge take its nearest point's entry: the map continued, so cells at the edge blend
      // neighbours rather than points outside the chamber.
      const double r = Radius(x.x, x.y);
      if (r > inside) x.x *= inside / r, x.y *= inside / r;
      const Vec3d p = ApproximateEntryPoint(chamber, x, light);
      nodes_[j * kNodes + i] = {p.x, p.y};
    }
}

Vec3d EntryPointTable::At(const AnteriorChamber<double>& chamber, const Vec3d& x) const {
  const double scale = (kNodes - 1) / (2 * half_);
  const double gx = std::clamp((x.x + half_) * scale, 0.0, kNodes - 1.0);
  const double gy = std::clamp((x.y + half_) * scale, 0.0, kNodes - 1.0);
  const int i = std::min(kNodes - 2, int(gx)), j = std::min(kNodes - 2, int(gy));
  const double fx = gx - i, fy = gy - j;
  const Vec2<double>* row = &nodes_[j * kNodes + i];
  const Vec2<double> q =
      (1 - fy) * ((1 - fx) * row[0] + fx * row[1]) + fy * ((1 - fx) * row[kNodes] + fx * row[kNodes + 1]);
  const AnteriorSurface<double>& surface = chamber.Surface();
  const Vec3d p(q.x, q.y, surface.Sag(Radius(q.x, q.y)));
  return RefineEntryPoint(chamber, x, light_, p, surface.Normal(p.x, p.y), 1);
}

}  // namespace eyelib
