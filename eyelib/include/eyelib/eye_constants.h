#pragma once
// The paper's numbers (Chiang and Burley 2018, after Kojima et al. 2013 and Iskander 2006), in mm.
// Kept in double; models convert once to their working precision.
#include <cmath>

namespace eyelib::paper {

inline constexpr double kPi = 3.14159265358979323846;

/// Ellipsoid 0.75 z^2 + 15.6 z + r^2 = 0 (apex radius of curvature 7.8 mm).
inline constexpr double kEllipsoidZ2 = 0.75;
inline constexpr double kEllipsoidZ1 = 15.6;
/// Junction of ellipsoid and cone: the 10.02 mm chord.
inline constexpr double kJunctionRadius = 10.02 / 2;
/// Rim of the anterior surface: the 15.08 mm chord, which is also the iris diameter.
inline constexpr double kIrisDiameter = 15.08;
inline constexpr double kRimRadius = kIrisDiameter / 2;
/// Cone half-angle measured from the xy-plane, degrees.
inline constexpr double kConeAngleDeg = 38.0;
/// Paraboloid approximation 14.5 z + r^2 = 0.
inline constexpr double kParaboloidZ1 = 14.5;
/// Iris depth below the apex at the 15.08 mm chord.
inline constexpr double kIrisDepth = 3.735;
/// Limbus edges (diameters) and their ratios over the iris diameter.
inline constexpr double kLimbusInnerDiameter = 11.64;
inline constexpr double kLimbusOuterDiameter = 12.89;
inline constexpr double kLimbusInnerRatio = kLimbusInnerDiameter / kIrisDiameter;
inline constexpr double kLimbusOuterRatio = kLimbusOuterDiameter / kIrisDiameter;
/// Refractive index of the cornea.
inline constexpr double kCorneaIor = 1.376;
/// Default pupil diameter, mm (not from the paper: a typical photopic value).
inline constexpr double kPupilDiameter = 4.0;

inline double TanConeAngle() { return std::tan(kConeAngleDeg * kPi / 180.0); }

}  // namespace eyelib::paper
