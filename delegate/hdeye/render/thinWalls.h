#pragma once
// Thin walls: open meshes (surfaces with a boundary: a tear-line strip, an occlusion shell round an eye, a
// leaf) whose material has opacity < 1. An open surface encloses no volume, so the glass part of its
// UsdPreviewSurface cannot refract into one; it is a thin dielectric sheet instead (pbrt's ThinDielectric):
// it reflects with the sheet's two-interface reflectance and transmits straight through (PreviewSurface::
// thinWalled). Because that transmission does not bend, a shadow ray may cross the sheet, attenuated by
// (1 - opacity) (1 - R): an occlusion shell darkens what lies behind it by its opacity, and MNEE's shadow rays
// from the iris pass it instead of being blocked (which would turn the iris black under the shell).
#include "hdeye/render/renderContext.h"

#include <embree3/rtcore.h>

namespace hdeye {

/// Whether a geometry is a thin wall that shadow rays cross (open surface, opacity < 1, not an eye).
inline bool IsThinWall(const GeometryContext& context) {
  return context.thinWalled && context.surface.params.opacity < 1 && !context.eye && !context.meshEye;
}

/// The fraction of light a thin wall passes straight through at cosine `cosTheta` (to its normal, either side):
/// (1 - opacity) (1 - R_sheet).
double ThinWallTransmittance(const GeometryContext& context, double cosTheta);

/// Shadow rays' record of the thin walls they met: rtcOccluded1 skips thin walls (their occluded filter) and notes
/// it here, per thread (a filter runs on the thread that traces), so the caller attenuates through the walls in
/// order (closest-hit queries) only when there were any.
class ThinWallsMet {
 public:
  /// Clears the record of this thread before a shadow query.
  static void Reset();
  /// Whether a thin wall was skipped on this thread since Reset.
  static bool Any();
};

/// The occluded filter Mesh installs on open meshes: a hit on a thin wall (IsThinWall, read at render time, so a
/// material edit needs no new geometry) does not occlude, and is noted in ThinWallsMet. Plain rtcOccluded1
/// callers see thin walls as absent.
void PassThinWallsFilter(const RTCFilterFunctionNArguments* args);

}  // namespace hdeye
