#pragma once
// Path-traced subsurface scattering as a volumetric random walk inside a closed surface (Chiang, Kutz
// and Burley 2016, "Practical and Controllable Subsurface Scattering for Production Path Tracing"),
// with the limbal-arc teleportation cylinder of Chiang and Burley 2018 as an option.
//
// Parameters, units and defaults:
//  - surface albedo A (RGB, [0, 1]): the artist's colour, the multiple-scattering albedo the surface
//    should show under uniform diffuse light;
//  - mean free path d (RGB, mm, > 0): the artist's scattering distance, Chiang et al.'s d (Cycles calls
//    it "radius", RenderMan PxrSurface "mfp");
//  - ior (medium over outside, default 1.376: cornea and sclera tissue), phase g (Henyey-Greenstein,
//    default 0: isotropic), maxSteps (default 1024), teleportation on/off (default off).
//
// Albedo inversion (Chiang, Kutz and Burley 2016, the polynomial fit of their talk; the same constants
// are in Blender Cycles' subsurface_random_walk_remap up to 2.9x, kernel/kernel_subsurface.h):
//   single-scattering albedo  alpha   = 1 - exp(A (-5.09406 + A (2.61188 - 4.31805 A)))
//   extinction                sigma_t = 1 / (s d),  s = 1.9 - A + 3.5 (A - 0.8)^2
// The fit is for isotropic scattering (g = 0) and diffuse light entering an index-matched boundary;
// a dielectric boundary (ior > 1) traps light by internal reflection and changes the measured albedo
// (tests/eyelib/test_random_walk_sss.cpp and docs/limbal_arc.md give the numbers).
//
// Chromatic media: one-sample spectral MIS over the three channels (as Cycles' random walk does):
// each free flight samples its distance from one channel, chosen with probability proportional to the
// current throughput, and every channel's weight is its own transmittance over the balance-heuristic
// mixture pdf. Unbiased for every channel; a grey medium reduces to the classic walk.
//
// The boundary is abstract, so the delegate can use an Embree mesh and tests analytic shapes. All in
// the canonical eye frame (mm) when the cylinder is on: the cylinder's axis is the z axis there.
#include "eyelib/function_ref.h"
#include "eyelib/teleportation_cylinder.h"
#include "eyelib/vec.h"

#include <cstdint>
#include <functional>
#include <string>

namespace eyelib {

/// The closest crossing of the medium's boundary along origin + t * dir, 0 < t <= tMax (mm, dir unit).
/// On a hit, *t (mm) and *normal (the geometric normal, unit, either orientation: the walk orients it)
/// are written and true is returned. A walker that has just reflected off the boundary starts on it:
/// the callback must not report that surface again at t ~ 0 (Embree: a tnear from an error bound;
/// analytic shapes: the far root, or only crossings that move outward).
using SssBoundary = std::function<bool(const Vec3<double>& origin, const Vec3<double>& dir, double tMax, double* t,
                                       Vec3<double>* normal)>;
/// Uniform random numbers in [0, 1), caller-supplied (called once per number: a reference, not a copy).
using SssRandom = FunctionRef<double()>;

/// Single-scattering albedo from the artist's surface albedo A, both in [0, 1] (A clamped; NaN -> 0).
double SingleScatteringAlbedo(double surfaceAlbedo);
/// Extinction coefficient sigma_t (1/mm) from surface albedo A and mean free path d (mm); d is clamped
/// to at least 1e-9 mm so that sigma_t stays finite.
double ExtinctionCoefficient(double surfaceAlbedo, double meanFreePath);

/// Volume coefficients of a homogeneous medium, per RGB channel.
struct SssMedium {
  Vec3<double> sigmaT{1.0};  ///< extinction, 1/mm, finite and > 0
  Vec3<double> albedo{0.0};  ///< single-scattering albedo sigma_s / sigma_t, in [0, 1]
};

/// The albedo inversion above, channel by channel.
SssMedium SssMediumFromArtist(const Vec3<double>& surfaceAlbedo, const Vec3<double>& meanFreePath);
/// Mean free paths beyond this (mm) are rejected: the medium is transparent at any eye's scale, and the walk's
/// steps (of that order) would leave the scene's float range.
constexpr double kMaxMeanFreePathMm = 1000.0;
/// Empty if the artist's values are usable (finite, albedo in [0, 1], mean free path in (0, kMaxMeanFreePathMm]
/// mm), else a one-line message naming the first offending value. SssMediumFromArtist clamps regardless.
std::string ValidateSssArtistParams(const Vec3<double>& surfaceAlbedo, const Vec3<double>& meanFreePath);

struct RandomWalkSettings {
  double ior = 1.376;   ///< medium index over outside index, >= 1 (1: index-matched, no Fresnel)
  double g = 0;         ///< Henyey-Greenstein asymmetry, (-1, 1); the albedo inversion assumes 0
  int maxSteps = 1024;  ///< every event counts: scattering, internal reflection, teleportation
  /// Russian roulette once the largest channel weight falls below this (0: never). Unbiased, but it
  /// makes the per-path energy balance (escaped + absorbed = 1) hold only on average.
  double rouletteWeight = 0.05;
  bool teleport = false;             ///< the limbal-arc teleportation cylinder (canonical frame only)
  TeleportationCylinder cylinder{};  ///< default: the outer limbus, 12.89 mm, infinite along z
};

enum class WalkStatus : std::uint8_t {
  Exited,    ///< left the medium: exitPoint, exitDir and weight are set
  Absorbed,  ///< ended by Russian roulette or zero throughput
  Capped,    ///< maxSteps reached: the path is dropped; weight holds the dropped throughput
  Invalid,   ///< NaN/Inf input, invalid coefficients, or a boundary callback answer that is not finite
};

const char* ToString(WalkStatus status);

struct WalkResult {
  WalkStatus status = WalkStatus::Invalid;
  Vec3<double> exitPoint{0.0};  ///< mm, on the boundary (Exited only)
  Vec3<double> exitDir{0.0};    ///< unit, refracted out of the medium (Exited only)
  Vec3<double> weight{0.0};     ///< throughput (RGB, finite, >= 0): leaving (Exited) or dropped (Capped)
  /// An unbiased estimate of the energy deposited in the medium (RGB, per unit entering energy); for a
  /// grey medium without roulette, escaped + absorbed + dropped = 1 exactly on every path: the audit.
  Vec3<double> absorbed{0.0};
  int steps = 0;  ///< events taken (scattering + internal reflection + teleportation)
  int internalReflections = 0;
  int teleports = 0;  ///< > 0: the path lit the limbal arc (a later `limbalArc` AOV)
  bool Teleported() const { return teleports > 0; }
};

/// One walk from a point on the boundary (mm) with a unit direction pointing into the medium (the
/// caller has already refracted it: entry Fresnel belongs to the surface BSDF, as in Cycles and
/// Hyperion). At the boundary the walk reflects with the dielectric Fresnel probability (total internal
/// reflection included) and continues, or refracts out and exits. Every loop is bounded by maxSteps;
/// no NaN or Inf leaves this function.
WalkResult RandomWalkSss(const SssMedium& medium, const RandomWalkSettings& settings, const Vec3<double>& entryPoint,
                         const Vec3<double>& inwardDir, const SssBoundary& boundary, SssRandom random);

}  // namespace eyelib
