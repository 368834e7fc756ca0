#pragma once
// Manifold next event estimation through the analytic cornea (Hanika, Droske and Fascione 2015, as
// Chiang and Burley 2018 use it): given a point x on the iris, inside the anterior chamber, and a
// point y on a light (or a direction, for distant lights), find the cornea points p where the path
// x -> p -> y obeys Snell's law, and the irradiance that path carries to x.
//
// Formulation (derived in docs/mnee.md). p = (u, v, h(u, v)) on the height field. The optical path
// length L(u, v) = n |p - x| + |y - p| (or n |p - x| - w.p for a direction w) is stationary exactly
// where Snell's law holds, so the constraint is its gradient C = J^T (n a - b), with J = dp/d(u, v),
// a = (p - x)/|p - x| and b = (y - p)/|y - p|. Its Jacobian is the Hessian of L, known in closed form
// from the surface's second derivatives: Newton's method needs no finite differences, and the angle
// form stays well conditioned where the half-vector form of Cycles degenerates (eta near 1).
//
// All in double precision, in the canonical eye frame (mm).
#include "eyelib/anterior_chamber.h"
#include "eyelib/inline_vector.h"
#include "eyelib/vec.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace eyelib {

using Vec3d = Vec3<double>;

enum class MneeStatus : std::uint8_t {
  Converged,      ///< |C| below tolerance, the path is a valid refraction within the rim
  InvalidInput,   ///< NaN/Inf input, or x not below the surface
  NoConvergence,  ///< the iteration bound was reached
  Stalled,        ///< the line search could not reduce |C| (no solution near this seed)
  BeyondRim,      ///< converged to a point of the extended surface outside the 15.08 mm rim
  WrongSide,      ///< converged, but the light is not in front of the surface there (a light behind the eye)
  Occluded,       ///< the light is behind the sclera: below the rim plane
  OffPiece,       ///< converged on a piece's analytic extension, outside the radii that piece owns
  /// a distant light further below the rim plane than the cap's steepest normal tilts (AnteriorSurface::MaxSlope):
  /// it faces away from the whole cap, so no path exists and no solve is made
  BehindCap,
};

const char* ToString(MneeStatus status);

/// The end of the path at the light: a point, or a direction towards a distant light.
struct LightEnd {
  bool distant = false;
  Vec3d position;   ///< mm, for a point on a light
  Vec3d direction;  ///< unit, from the eye towards a distant light
};

struct MneeOptions {
  int maxIterations = 30;
  /// Converged when max |C_i| is below this (dimensionless: a difference of direction components,
  /// so roughly the angular error of Snell's law in radians).
  double tolerance = 1e-11;
  /// Largest Newton step on the height field, mm (a trust region).
  double maxStep = 1.0;
  /// Treat lights below the rim plane as hidden by the sclera (the analytic eye on its own, as the
  /// light-tracing reference models it). A renderer with its own shadow rays turns this off.
  bool scleraOccludes = true;
  /// Solve on this piece's own analytic extension (smooth across the junction circle) and accept the
  /// solution only if it lies in the piece's domain (else OffPiece). Unset: the piecewise surface, whose
  /// slope kink at the junction Newton cannot cross reliably (FindRefractionPaths always sets it).
  std::optional<SurfacePiece> piece;
};

struct MneeSolution {
  MneeStatus status = MneeStatus::InvalidInput;
  Vec3d p;                                       ///< cornea point, mm
  Vec3d normal;                                  ///< outward unit normal at p
  SurfacePiece piece = SurfacePiece::Ellipsoid;  ///< the piece that owns p
  int iterations = 0;
  double residual = 0;  ///< max |C_i| at the end
  /// Irradiance transfer at x: for a point light, E = I * transfer (I in W/sr, E in W/mm^2), i.e.
  /// transfer = T * |N.b| * |det d(u,v)/dx| / |y - p|^2 (1/mm^2); for a distant light, E = E_perp * transfer
  /// (dimensionless). T is the Fresnel transmittance. Zero unless Converged.
  double transfer = 0;
  double fresnelT = 0;  ///< Fresnel transmittance at p
};

/// Newton solve from one seed (u0, v0) on the height field (mm).
MneeSolution SolveRefractionPath(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                                 double u0, double v0, const MneeOptions& options = {});

/// The seed where the straight line from x to the light crosses the surface (what Cycles uses).
/// Falls back to the apex if that line misses the cap.
Vec2<double> StraightLineSeed(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light);

/// Approximately where light from `light` refracts into the chamber on its way to iris point x (mm): from the
/// apex (for light from below the rim plane, from the cone's middle on the light's side), `iterations` fixed-point
/// steps (refract the direction towards the light at the current point, then go back from x against that direction
/// to the cornea). Where it got to if a step misses the cap or cannot refract; the apex for a distant light behind the
/// cap (MneeStatus::BehindCap). Newton's start for MNEE, and a light's
/// sampling origin: MNEE's weight for a light point is cos(emission towards the path's cornea point) over the cosine
/// the sampling origin sees there, which diverges at the light's rim (as seen from the origin) when the origin is the
/// apex and the path crosses the cornea millimetres away; from this point the two cosines nearly agree.
Vec3d ApproximateEntryPoint(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                            int iterations = 3);

/// ApproximateEntryPoint's fixed-point steps from cap point p (mm) with outward unit normal n there.
Vec3d RefineEntryPoint(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light, Vec3d p, Vec3d n,
                       int iterations);

/// How to look for solutions.
struct SeedStrategy {
  /// false: one solution: the straight-line seed, then (if it fails and `fallback` is on) the
  /// meridian seeds until one converges; true: every seed below, keeping all distinct solutions.
  bool allSolutions = false;
  /// With allSolutions off: retry a failed straight-line seed from the meridian seeds. Off gives what
  /// Cycles' MNEE does, kept for comparison: one Newton solve from the straight-line seed on the piecewise
  /// surface (which stalls at the junction's kink where the path crosses it).
  bool fallback = true;
  /// Seeds along the light's azimuth through x (where a fold's second solution lies), spread
  /// across the cap. 0 turns them off.
  int meridianSeeds = 6;
  int rings = 0;  ///< optional polar grid over the cap: rings x segments seeds
  int segments = 8;
  double uniqueDistance = 1e-6;  ///< mm; solutions closer than this (on the same piece) are the same
  /// Where the first solve starts, a cornea point's (x, y) in mm, instead of the straight line from x to the light
  /// (which ignores refraction, so Newton starts millimetres off for a light off the axis). ApproximateEntryPoint
  /// towards a small light's centre lies within a fraction of a millimetre of the path to any point of it: about
  /// half the iterations, and fewer failed first solves left to the meridian seeds. Unset: the straight line. Not
  /// used by the one-solve mode (fallback and allSolutions off), which stays Cycles' seed.
  std::optional<Vec2<double>> start;
  /// With `start` and allSolutions off: whether a failed start is retried from the meridian seeds (`fallback`).
  /// Off is for a light small as seen from x (under sin 0.05, about 3 degrees, of angular radius): started at the
  /// entry point, the retry never found a path the start missed for such lights, 15 mm to 1 m away at 0-88 degrees,
  /// while it cost 4-10 times the iterations at grazing angles, on iris points the light does not reach (test
  /// "a small light's failed start ..."). For larger lights at 80-88 degrees it finds 0.2-2 % of the light.
  bool retryStart = true;
  /// Ellipsoid-cone model: a solution whose cornea point lies within this distance (mm, in radius) of the
  /// junction circle is paired with a solve on the other piece: near the 0.3 degree slope kink an iris
  /// point can have one path through each piece (where the two pieces' caustics overlap) or none (a gap).
  /// Both paths of such a pair lie within 0.02 mm of the junction for point lights 12 mm to 1 km away at
  /// 0-88 degrees (test "both paths of a junction pair ..."): the default has a margin of 5.
  double junctionPairRadius = 0.1;
};

struct MneeResult {
  InlineVector<MneeSolution, 4> solutions;  ///< distinct converged solutions
  int solves = 0;                           ///< Newton solves run
  int failures = 0;                         ///< solves that did not converge to a valid path
  int iterations = 0;                       ///< Newton iterations over all solves
  int maxIterations = 0;                    ///< the most any one solve took
  /// Sum of the solutions' transfers (see MneeSolution::transfer).
  double transfer = 0;
};

/// All distinct refraction paths from x to the light that the seeds find.
MneeResult FindRefractionPaths(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                               const SeedStrategy& seeds = {}, const MneeOptions& options = {});

}  // namespace eyelib
