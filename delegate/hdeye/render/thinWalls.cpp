#include "hdeye/render/thinWalls.h"

#include "hdeye/render/previewSurface.h"

#include <algorithm>
#include <cmath>

namespace hdeye {

namespace {

thread_local bool tlsThinWallMet = false;

}  // namespace

double ThinWallTransmittance(const GeometryContext& context, double cosTheta) {
  const double opacity = std::clamp(double(context.surface.params.opacity), 0.0, 1.0);
  return (1 - opacity) * (1 - ThinSheetReflectance(std::abs(cosTheta), context.surface.params.ior));
}

void ThinWallsMet::Reset() { tlsThinWallMet = false; }
bool ThinWallsMet::Any() { return tlsThinWallMet; }

void PassThinWallsFilter(const RTCFilterFunctionNArguments* args) {
  const auto* context = static_cast<const GeometryContext*>(args->geometryUserPtr);
  if (!context || !IsThinWall(*context)) return;
  bool rejected = false;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    args->valid[i] = 0;
    rejected = true;
  }
  if (rejected) tlsThinWallMet = true;
}

}  // namespace hdeye
