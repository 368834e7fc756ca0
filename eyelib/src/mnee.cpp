// Manifold next event estimation through the analytic cornea: Newton on the gradient of the optical
// path length over the height field, and the generalized geometry term from the implicit function
// theorem. See mnee.h and docs/mnee.md.
#include "eyelib/mnee.h"

#include "eyelib/optics.h"

#include <algorithm>
#include <cmath>

namespace eyelib {

const char* ToString(MneeStatus status) {
  switch (status) {
    case MneeStatus::Converged: return "converged";
    case MneeStatus::InvalidInput: return "invalid input";
    case MneeStatus::NoConvergence: return "no convergence";
    case MneeStatus::Stalled: return "stalled";
    case MneeStatus::BeyondRim: return "beyond rim";
    case MneeStatus::WrongSide: return "wrong side";
    case MneeStatus::Occluded: return "occluded";
    case MneeStatus::OffPiece: return "off piece";
    case MneeStatus::BehindCap: return "behind the cap";
  }
  return "?";
}

namespace {

// Backtracking halvings before a solve counts as stalled. A step cut 2^12 times moves the seed by less
// than a quarter of a micrometre: no root is near, and every further halving is a full evaluation.
constexpr int kMaxHalvings = 12;

struct Mat2 {
  double a, b, c, d;  // [[a, b], [c, d]]
  double Det() const { return a * d - b * c; }
};

/// The constraint C = grad_(u,v) L and its Jacobian H (the Hessian of L) at (u, v).
struct PathState {
  Vec3d p, J1, J2;
  Vec3d a;        // unit, x -> p (inside)
  Vec3d b;        // unit, p -> light (outside)
  double lx, ly;  // |p - x|, |y - p| (inf for a distant light)
  double C[2];
  Mat2 H;
  double Residual() const { return std::max(std::abs(C[0]), std::abs(C[1])); }
};

/// On `piece`'s analytic extension if set, else on the piecewise surface.
PathState Evaluate(const AnteriorSurface<double>& surface, const std::optional<SurfacePiece>& piece, double eta,
                   const Vec3d& x, const LightEnd& light, double u, double v) {
  PathState s;
  const HeightDerivatives<double> h = piece ? surface.HeightOnPiece(*piece, u, v) : surface.Height(u, v);
  s.p = {u, v, h.h};
  s.J1 = {1, 0, h.hx};
  s.J2 = {0, 1, h.hy};
  const Vec3d dx = s.p - x;
  s.lx = glm::length(dx);
  s.a = dx / s.lx;
  if (light.distant) {
    s.b = light.direction;
    s.ly = INFINITY;
  } else {
    const Vec3d dy = light.position - s.p;
    s.ly = glm::length(dy);
    s.b = dy / s.ly;
  }
  const Vec3d g = eta * s.a - s.b;
  s.C[0] = glm::dot(g, s.J1);
  s.C[1] = glm::dot(g, s.J2);
  // Hessian: J^T [eta (I - aa^T)/lx + (I - bb^T)/ly] J + g_z * h_ij.
  auto quad = [&](const Vec3d& Ji, const Vec3d& Jj) {
    double q = eta * (glm::dot(Ji, Jj) - glm::dot(Ji, s.a) * glm::dot(Jj, s.a)) / s.lx;
    if (!light.distant) q += (glm::dot(Ji, Jj) - glm::dot(Ji, s.b) * glm::dot(Jj, s.b)) / s.ly;
    return q;
  };
  s.H.a = quad(s.J1, s.J1) + g.z * h.hxx;
  s.H.b = quad(s.J1, s.J2) + g.z * h.hxy;
  s.H.c = s.H.b;
  s.H.d = quad(s.J2, s.J2) + g.z * h.hyy;
  return s;
}

/// |det d(u,v)/dx| for x moving on the iris plane: d(u,v)/dx = -H^-1 C_x, with
/// C_x[i][k] = -eta/lx (J_i.e_k - (J_i.a)(a.e_k)).
double ParamJacobianDet(const PathState& s, double eta) {
  const double k = -eta / s.lx;
  const Mat2 Cx{k * (s.J1.x - glm::dot(s.J1, s.a) * s.a.x), k * (s.J1.y - glm::dot(s.J1, s.a) * s.a.y),
                k * (s.J2.x - glm::dot(s.J2, s.a) * s.a.x), k * (s.J2.y - glm::dot(s.J2, s.a) * s.a.y)};
  // det(-H^-1 Cx) = det(Cx) / det(H).
  return std::abs(Cx.Det() / s.H.Det());
}

bool AllFinite(const Vec3d& v) { return IsFinite(v); }

/// Whether a distant light faces away from every outward normal of the cap. The normals tilt at most
/// atan(MaxSlope) off the axis, and a direction at elevation e has a positive cosine to a normal tilted by t towards
/// it only if t > -e: so no path leaves towards z <= -sin(atan(MaxSlope)).
bool BehindCap(const AnteriorSurface<double>& surface, const LightEnd& light) {
  const double k = surface.MaxSlope(), z = light.direction.z;  // z <= -k / sqrt(1 + k^2), without the root
  return light.distant && z < 0 && z * z * (1 + k * k) >= k * k;
}

/// A first solve's outcome that no other seed can change.
bool Final(MneeStatus s) {
  return s == MneeStatus::Occluded || s == MneeStatus::InvalidInput || s == MneeStatus::BehindCap;
}

}  // namespace

MneeSolution SolveRefractionPath(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                                 double u0, double v0, const MneeOptions& options) {
  MneeSolution out;
  const AnteriorSurface<double>& surface = chamber.Surface();
  const double eta = chamber.CorneaIor();
  const bool lightOk = light.distant ? AllFinite(light.direction) && std::abs(glm::length(light.direction) - 1) < 1e-9
                                     : AllFinite(light.position);
  if (!AllFinite(x) || !lightOk || !std::isfinite(u0) || !std::isfinite(v0) ||
      !(x.z < surface.Sag(std::sqrt(x.x * x.x + x.y * x.y))))
    return out;
  if (BehindCap(surface, light)) {
    out.status = MneeStatus::BehindCap;
    return out;
  }
  // The sclera hides everything below the rim plane from the cornea (lights behind the eye).
  const double zRim = surface.Sag(surface.RimRadius());
  if (options.scleraOccludes && (light.distant ? light.direction.z <= 0 : light.position.z <= zRim)) {
    out.status = MneeStatus::Occluded;
    return out;
  }

  double u = u0, v = v0;
  PathState s = Evaluate(surface, options.piece, eta, x, light, u, v);
  double merit = s.C[0] * s.C[0] + s.C[1] * s.C[1];
  out.status = MneeStatus::NoConvergence;
  int it = 0;
  for (; it < options.maxIterations && s.Residual() > options.tolerance; ++it) {
    // Newton direction; fall back to steepest descent on |C|^2 where H is singular (a caustic fold).
    double du, dv;
    const double det = s.H.Det();
    const double scale = std::abs(s.H.a) + std::abs(s.H.b) + std::abs(s.H.d);
    if (std::abs(det) > 1e-12 * scale * scale) {
      du = -(s.H.d * s.C[0] - s.H.b * s.C[1]) / det;
      dv = -(-s.H.c * s.C[0] + s.H.a * s.C[1]) / det;
    } else {
      du = -(s.H.a * s.C[0] + s.H.c * s.C[1]);
      dv = -(s.H.b * s.C[0] + s.H.d * s.C[1]);
    }
    const double len = std::sqrt(du * du + dv * dv);
    if (!(len > 0) || !std::isfinite(len)) break;
    if (len > options.maxStep) du *= options.maxStep / len, dv *= options.maxStep / len;
    // Backtracking line search on |C|^2.
    double alpha = 1;
    bool accepted = false;
    for (int k = 0; k < kMaxHalvings; ++k, alpha /= 2) {
      const PathState trial = Evaluate(surface, options.piece, eta, x, light, u + alpha * du, v + alpha * dv);
      const double m = trial.C[0] * trial.C[0] + trial.C[1] * trial.C[1];
      if (std::isfinite(m) && m < merit * (1 - 1e-4 * alpha)) {
        u += alpha * du, v += alpha * dv;
        s = trial;
        merit = m;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      out.status = MneeStatus::Stalled;
      break;
    }
  }
  out.iterations = it;
  out.residual = s.Residual();
  out.p = s.p;
  // The normal of the surface the solve used (the piece's own where it is set).
  out.normal = glm::normalize(glm::cross(s.J1, s.J2));
  out.piece = surface.PieceAt(std::sqrt(RadiusSquared(s.p)));
  if (!(out.residual <= options.tolerance)) {
    if (out.status != MneeStatus::Stalled) out.status = MneeStatus::NoConvergence;
    return out;
  }
  if (RadiusSquared(s.p) > surface.RimRadius() * surface.RimRadius()) {
    out.status = MneeStatus::BeyondRim;
    return out;
  }
  if (options.piece && out.piece != *options.piece) {
    out.status = MneeStatus::OffPiece;
    return out;
  }
  // A stationary point of L is a refraction only if the light is in front of the surface and x behind
  // it (otherwise it is a reflection-like or inverted configuration).
  const double cosOut = glm::dot(out.normal, s.b), cosIn = glm::dot(out.normal, s.a);
  if (!(cosOut > 0) || !(cosIn > 0)) {
    out.status = MneeStatus::WrongSide;
    return out;
  }
  out.status = MneeStatus::Converged;
  out.fresnelT = 1 - FresnelDielectric(cosOut, eta);
  const Vec3d N = glm::cross(s.J1, s.J2);  // (-hx, -hy, 1)
  double transfer = out.fresnelT * std::abs(glm::dot(N, s.b)) * ParamJacobianDet(s, eta);
  if (!light.distant) transfer /= s.ly * s.ly;
  out.transfer = std::isfinite(transfer) ? transfer : 0;
  return out;
}

Vec2<double> StraightLineSeed(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light) {
  const Vec3d dir = light.distant ? light.direction : light.position - x;
  if (const auto hit = chamber.Surface().Intersect({x, dir})) return {hit->point.x, hit->point.y};
  return {0, 0};
}

Vec3d ApproximateEntryPoint(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                            int iterations) {
  if (BehindCap(chamber.Surface(), light)) return Vec3d(0);  // no path to start
  // Light from below the rim plane enters near the rim on its own side, where the cap tilts most: three steps from
  // the apex do not get there, so start there, at 0.83 of the rim radius (mid-cone).
  const Vec3d fromApex = light.distant ? light.direction : light.position;
  if (const double across = fromApex.z < 0 ? std::hypot(fromApex.x, fromApex.y) : 0; across > 0) {
    const AnteriorSurface<double>& surface = chamber.Surface();
    const double r = 0.83 * surface.RimRadius();
    const Vec3d p(r * fromApex.x / across, r * fromApex.y / across, surface.Sag(r));
    return RefineEntryPoint(chamber, x, light, p, surface.Normal(p.x, p.y), iterations);
  }
  return RefineEntryPoint(chamber, x, light, Vec3d(0), Vec3d(0, 0, 1), iterations);
}

Vec3d RefineEntryPoint(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light, Vec3d p, Vec3d n,
                       int iterations) {
  for (int k = 0; k < iterations; ++k) {
    const Vec3d toLight = light.distant ? light.direction : light.position - p;
    const double length = glm::length(toLight);
    Vec3d inside;
    if (!(length > 0 && std::isfinite(length)) || !Refract(toLight / length, n, chamber.CorneaIor(), &inside)) break;
    const ChamberSurfaceHit<double> hit = chamber.NextSurfaceFromInside(x, -inside);
    if (hit.kind != ChamberSurfaceHit<double>::Cornea) break;
    p = hit.point, n = hit.normal;
  }
  return p;
}

MneeResult FindRefractionPaths(const AnteriorChamber<double>& chamber, const Vec3d& x, const LightEnd& light,
                               const SeedStrategy& seeds, const MneeOptions& options) {
  MneeResult result;
  const AnteriorSurface<double>& surface = chamber.Surface();
  auto solveOn = [&](SurfacePiece piece, double u, double v) {
    ++result.solves;
    MneeOptions pieceOptions = options;
    pieceOptions.piece = piece;
    const MneeSolution sol = SolveRefractionPath(chamber, x, light, u, v, pieceOptions);
    result.iterations += sol.iterations;
    result.maxIterations = std::max(result.maxIterations, sol.iterations);
    if (sol.status != MneeStatus::Converged) {
      ++result.failures;
      return sol;
    }
    for (const MneeSolution& known : result.solutions)
      if (known.piece == sol.piece && glm::length(known.p - sol.p) < seeds.uniqueDistance) return sol;
    result.solutions.push_back(sol);
    result.transfer += sol.transfer;
    return sol;
  };
  // One seed: a Newton solve on the smooth extension of the piece that owns the seed, kept only inside that
  // piece; then one on the other piece where a path through it is near: the first converged near the
  // junction (the two pieces' caustics overlap there) or beyond its own piece. (A failed first solve is not
  // retried there: on the light-tracing tests that finds no more light.)
  auto trySeed = [&](double u, double v) {
    const SurfacePiece own = surface.PieceAt(Radius(u, v)), other = surface.OtherPiece(own);
    const MneeSolution first = solveOn(own, u, v);
    if (other == own || Final(first.status)) return first.status;
    const bool converged = first.status == MneeStatus::Converged;
    const double fromJunction = std::abs(Radius(first.p.x, first.p.y) - surface.JunctionRadius());
    if (converged && fromJunction >= seeds.junctionPairRadius) return first.status;
    if (!converged && first.status != MneeStatus::OffPiece) return first.status;
    // From where the first solve ended on its extension: the other piece's path is near it.
    const MneeSolution second = solveOn(other, first.p.x, first.p.y);
    return converged ? first.status : second.status;
  };
  if (!seeds.allSolutions && !seeds.fallback) {  // Cycles' way: one solve on the piecewise surface
    const Vec2<double> seed = StraightLineSeed(chamber, x, light);
    const MneeSolution sol = SolveRefractionPath(chamber, x, light, seed.x, seed.y, options);
    result.solves = 1;
    result.failures = sol.status != MneeStatus::Converged;
    result.iterations = result.maxIterations = sol.iterations;
    if (sol.status == MneeStatus::Converged) result.solutions.push_back(sol), result.transfer = sol.transfer;
    return result;
  }
  // The straight line only when no start is given (it costs a cap intersection).
  const Vec2<double> start = seeds.start ? *seeds.start : StraightLineSeed(chamber, x, light);
  const MneeStatus first = trySeed(start.x, start.y);
  if (Final(first)) return result;
  // One solution wanted: stop at the first, but if the straight line failed (it often misses the
  // cap for light from below the rim plane), walk the meridian seeds until one converges.
  const bool stopAtFirst = !seeds.allSolutions;
  const bool retry = seeds.fallback && (!seeds.start || seeds.retryStart);
  if (stopAtFirst && (first == MneeStatus::Converged || !retry)) return result;
  const double rim = chamber.Surface().RimRadius();
  // The light's azimuth as seen from x: the refraction plane of the paths to find.
  const Vec3d toLight = light.distant ? light.direction : light.position - x;
  const double az = std::hypot(toLight.x, toLight.y);
  const Vec2<double> along = az > 1e-12 ? Vec2<double>(toLight.x / az, toLight.y / az) : Vec2<double>(1, 0);
  const Vec2<double> across(-along.y, along.x);
  const double offset = x.x * across.x + x.y * across.y;
  for (int k = 0; k < seeds.meridianSeeds; ++k) {
    const double s = rim * (-0.95 + 1.9 * (k + 0.5) / seeds.meridianSeeds);
    const MneeStatus status = trySeed(s * along.x + offset * across.x, s * along.y + offset * across.y);
    if (stopAtFirst && status == MneeStatus::Converged) return result;
  }
  if (stopAtFirst) return result;
  for (int ring = 1; ring <= seeds.rings; ++ring) {
    const double r = rim * ring / (seeds.rings + 0.5);
    for (int k = 0; k < seeds.segments; ++k) {
      const double phi = 2 * paper::kPi * (k + 0.5 * (ring % 2)) / seeds.segments;
      trySeed(r * std::cos(phi), r * std::sin(phi));
    }
  }
  return result;
}

}  // namespace eyelib
