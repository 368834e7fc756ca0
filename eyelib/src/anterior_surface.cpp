#include "eyelib/anterior_surface.h"
#include "eyelib/anterior_chamber.h"

#include <cmath>
#include <sstream>

namespace eyelib {

const char* ToString(CorneaModel model) { return model == CorneaModel::Paraboloid ? "paraboloid" : "ellipsoidCone"; }

const char* ToString(SurfacePiece piece) {
  switch (piece) {
    case SurfacePiece::Ellipsoid: return "ellipsoid";
    case SurfacePiece::Cone: return "cone";
    case SurfacePiece::Paraboloid: return "paraboloid";
  }
  return "?";
}

std::string ValidateChamberParams(const ChamberParams& p) {
  std::ostringstream err;
  auto bad = [&](const char* name, double value, const char* rule) {
    err << name << " = " << value << " is out of range: " << rule;
  };
  if (!(p.irisDepth > 0) || !std::isfinite(p.irisDepth))
    bad("irisDepth", p.irisDepth, "must be > 0 mm");
  else if (!(p.limbusInnerRatio > 0 && p.limbusInnerRatio <= 1))
    bad("limbusInnerRatio", p.limbusInnerRatio, "must be in (0, 1]");
  else if (!(p.limbusOuterRatio > 0 && p.limbusOuterRatio <= 1))
    bad("limbusOuterRatio", p.limbusOuterRatio, "must be in (0, 1]");
  else if (!(p.limbusInnerRatio <= p.limbusOuterRatio))
    bad("limbusInnerRatio", p.limbusInnerRatio, "must not exceed limbusOuterRatio");
  else if (!(p.corneaIor >= 1) || !std::isfinite(p.corneaIor))
    bad("corneaIor", p.corneaIor, "must be >= 1");
  else if (!(p.pupilDiameter >= 0) || !(p.pupilDiameter < paper::kIrisDiameter))
    bad("pupilDiameter", p.pupilDiameter, "must be in [0, 15.08) mm");
  return err.str();
}

// Compile both precisions here so errors in rarely used paths show up in the library build.
template class AnteriorSurface<float>;
template class AnteriorSurface<double>;
template class AnteriorChamber<float>;
template class AnteriorChamber<double>;

}  // namespace eyelib
