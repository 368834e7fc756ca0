#pragma once
// ApproximateEntryPoint towards one light point, tabulated over the iris: a renderer asks for it at every iris sample
// of a light that does not move, and gets a bilinear lookup of converged nodes instead of three fixed-point steps
// from the apex (each a walk back to the cornea). Canonical frame, mm.
#include "eyelib/anterior_chamber.h"
#include "eyelib/mnee.h"

#include <vector>

namespace eyelib {

class EntryPointTable {
 public:
  /// Nodes per side of the table's grid over the square around the iris disk (0.47 mm apart on the paper's eye): on
  /// a light 100 mm away at 30 degrees the lookup is 0.004 mm from the converged entry on average (17 nodes: 0.012).
  static constexpr int kNodes = 33;
  /// ApproximateEntryPoint's fixed-point steps at each node: converged (four leave 0.0039 mm, six and eight 0.0036).
  static constexpr int kSteps = 6;

  EntryPointTable() = default;
  /// ApproximateEntryPoint(chamber, x, light) at the grid's nodes, each node's x moved into the iris disk.
  EntryPointTable(const AnteriorChamber<double>& chamber, const LightEnd& light);

  const LightEnd& Light() const { return light_; }
  bool Empty() const { return nodes_.empty(); }

  /// The entry point for iris point x (mm): the table's bilinear (x, y), put on the cap.
  Vec3d At(const AnteriorChamber<double>& chamber, const Vec3d& x) const;

 private:
  LightEnd light_;
  double half_ = 0;                  ///< the grid's half-width, mm: the iris radius
  std::vector<Vec2<double>> nodes_;  ///< row-major, kNodes x kNodes: the entries' (x, y)
};

}  // namespace eyelib
