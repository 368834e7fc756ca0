#pragma once
// A light-tracing reference for iris irradiance: rays shot from a light through the analytic cornea,
// refracted (weighted by Fresnel transmittance) and binned where they first meet the iris plane.
// It is the ground truth MNEE is checked against, and shares only the surface and optics code.
//
// Units as in eye_light.h; irradiance in W/mm^2. Only the direct, once-refracted light is binned:
// rays that would hit the cornea again from inside before the iris are dropped. Lights below the
// rim plane are hidden by the sclera, as in MNEE.
#include "eyelib/anterior_chamber.h"
#include "eyelib/eye_light.h"
#include "eyelib/mnee.h"

#include <cstdint>
#include <limits>
#include <vector>

namespace eyelib {

/// A square grid on the iris plane, centred on the axis.
struct IrisGrid {
  int cells = 32;           ///< per side
  double halfWidth = 7.54;  ///< mm

  double CellSize() const { return 2 * halfWidth / cells; }
  /// Centre of cell (i, j) in the iris plane (x, y), mm.
  Vec2<double> CellCenter(int i, int j) const {
    return {-halfWidth + (i + 0.5) * CellSize(), -halfWidth + (j + 0.5) * CellSize()};
  }
};

/// Binned irradiance with its per-cell standard error.
struct IrradianceMap {
  IrisGrid grid;
  std::vector<double> irradiance;  ///< W/mm^2
  std::vector<double> stdError;    ///< standard error of each cell's estimate
  std::int64_t rays = 0;

  double At(int i, int j) const { return irradiance[j * grid.cells + i]; }
  double ErrorAt(int i, int j) const { return stdError[j * grid.cells + i]; }
};

/// The radii (mm) of the anterior surface whose light is binned: the light one band of the cornea brings,
/// for example the neighbourhood of the ellipsoid-cone junction. The default is the whole cap.
struct CorneaBand {
  double minRadius = 0;
  double maxRadius = std::numeric_limits<double>::infinity();
  bool Contains(double r) const { return r >= minRadius && r < maxRadius; }
};

/// Light-traces `rays` rays from the light into the chamber, binning those that enter the cornea inside
/// `band`. Deterministic for a given seed.
IrradianceMap LightTraceIris(const AnteriorChamber<double>& chamber, const EyeLight& light, const IrisGrid& grid,
                             std::int64_t rays, std::uint64_t seed = 1, const CorneaBand& band = {});

/// Whether cell (i, j) lies wholly on the iris (between the pupil and the iris edge).
bool CellOnIris(const AnteriorChamber<double>& chamber, const IrisGrid& grid, int i, int j);

}  // namespace eyelib
