#include "eyelib/entry_point_table.h"

#include <algorithm>
#include <cmath>

namespace eyelib {

EntryPointTable::EntryPointTable(const AnteriorChamber<double>& chamber, const LightEnd& light)
    : light_(light), half_(chamber.IrisRadius()), nodes_(kNodes * kNodes) {
  // Nodes at most this far out are solved where they are; the iris edge itself meets the cap, where the walk back to
  // the cornea has no room.
  const double step = 2 * half_ / (kNodes - 1), inside = half_ * (1 - 5e-3);
  for (int j = 0; j < kNodes; ++j)
    for (int i = 0; i < kNodes; ++i) {
      Vec3d x(-half_ + i * step, -half_ + j * step, chamber.IrisZ());
      // Past that, the map is continued as the identity plus the edge's offset: at the edge, where the iris meets the
      // cap, a point's entry is right above it. Cells at the edge then interpolate a map that goes on smoothly,
      // rather than a constant (or points outside the chamber, which have no entry).
      const double r = Radius(x.x, x.y);
      Vec2<double> beyond(0);
      if (r > inside) {
        const double s = inside / r;
        beyond = {x.x * (1 - s), x.y * (1 - s)};
        x.x *= s, x.y *= s;
      }
      const Vec3d p = ApproximateEntryPoint(chamber, x, light, kSteps);
      nodes_[j * kNodes + i] = Vec2<double>(p.x, p.y) + beyond;
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
  return Vec3d(q.x, q.y, chamber.Surface().Sag(Radius(q.x, q.y)));
}

}  // namespace eyelib
