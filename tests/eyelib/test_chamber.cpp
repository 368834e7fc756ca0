// The anterior chamber: iris plane, pupil, limbus blend and parameter validation.
#include "eyelib/anterior_chamber.h"
#include "eyelib/random.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

using namespace eyelib;
using V = Vec3<double>;

TEST_CASE("the iris disk ends where the iris plane meets the cornea, capped at the rim") {
  const AnteriorChamber<double> anatomical;
  CHECK(anatomical.IrisRadius() == Approx(7.54));
  ChamberParams shallow;
  shallow.irisDepth = -AnteriorSurface<double>().Sag(11.64 / 2);  // figure 4(a): iris at the inner limbus
  const AnteriorChamber<double> a(shallow);
  CHECK(a.IrisRadius() == Approx(11.64 / 2).epsilon(1e-12));
  ChamberParams parab;
  parab.model = CorneaModel::Paraboloid;
  CHECK(AnteriorChamber<double>(parab).IrisRadius() == Approx(std::sqrt(14.5 * 3.735)).epsilon(1e-12));
}

TEST_CASE("rays meet the iris between the pupil and the iris edge, from either side") {
  const AnteriorChamber<double> c;
  CHECK(c.IntersectIris({V(3, 0, 0), V(0, 0, -1)})->point.z == -3.735);
  CHECK_FALSE(c.IntersectIris({V(1, 0, 0), V(0, 0, -1)}));       // through the 2 mm pupil radius
  CHECK_FALSE(c.IntersectIris({V(7.6, 0, 0), V(0, 0, -1)}));     // beyond the iris edge
  CHECK(c.IntersectIris({V(3, 0, -5), V(0, 0, 1)}));             // from behind
  CHECK_FALSE(c.IntersectIris({V(3, 0, 0), V(1, 0, 0)}));        // parallel to the plane
  CHECK_FALSE(c.IntersectIris({V(3, 0, 0), V(0, 0, -1)}, 3.0));  // beyond tMax
}

TEST_CASE("the limbus weight rises smoothly from cornea (0) to sclera (1) between its edges") {
  const AnteriorChamber<double> c;
  CHECK(c.LimbusWeight(0) == 0);
  CHECK(c.LimbusWeight(11.64 / 2) == 0);
  CHECK(c.LimbusWeight(12.89 / 2) == 1);
  CHECK(c.LimbusWeight(7.54) == 1);
  CHECK(c.LimbusWeight((11.64 + 12.89) / 4) == Approx(0.5));
  double prev = 0;
  for (double r = 5.8; r < 6.5; r += 1e-3) {
    CHECK(c.LimbusWeight(r) >= prev);
    prev = c.LimbusWeight(r);
  }
}

TEST_CASE("out-of-range chamber parameters are reported by name") {
  auto message = [](auto edit) {
    ChamberParams p;
    edit(p);
    return ValidateChamberParams(p);
  };
  CHECK(ValidateChamberParams({}).empty());
  CHECK_THAT(message([](ChamberParams& p) { p.irisDepth = -1; }), Catch::Contains("irisDepth"));
  CHECK_THAT(message([](ChamberParams& p) { p.limbusInnerRatio = 0.9; }), Catch::Contains("limbusInnerRatio"));
  CHECK_THAT(message([](ChamberParams& p) { p.limbusOuterRatio = 1.5; }), Catch::Contains("limbusOuterRatio"));
  CHECK_THAT(message([](ChamberParams& p) { p.corneaIor = 0.9; }), Catch::Contains("corneaIor"));
  CHECK_THAT(message([](ChamberParams& p) { p.irisDepth = std::nan(""); }), Catch::Contains("irisDepth"));
  CHECK_THAT(message([](ChamberParams& p) { p.pupilDiameter = 20; }), Catch::Contains("pupilDiameter"));
}

namespace {

/// What NextSurfaceFromInside must return, from the general intersection alone: the nearer of the iris plane and
/// the cap's first crossing, counted only if it is an exit.
ChamberSurfaceHit<double> NextSurfaceByFullSearch(const AnteriorChamber<double>& chamber, const V& p, const V& d) {
  ChamberSurfaceHit<double> hit;
  const double tPlane = d.z < 0 ? (chamber.IrisZ() - p.z) / d.z : INFINITY;
  auto cap = chamber.Surface().Intersect({p, d});
  if (cap && cap->fromOutside) cap.reset();
  if (tPlane < (cap ? cap->t : INFINITY)) {
    hit.point = p + tPlane * d;
    hit.point.z = chamber.IrisZ();
    hit.kind = std::hypot(hit.point.x, hit.point.y) < chamber.PupilRadius() ? ChamberSurfaceHit<double>::Pupil
                                                                            : ChamberSurfaceHit<double>::Iris;
  } else if (cap) {
    hit.kind = ChamberSurfaceHit<double>::Cornea;
    hit.point = cap->point, hit.normal = cap->normal;
  }
  return hit;
}

/// A direction uniform on the sphere, from UniformAt(seed, i, 3) and (seed, i, 4).
V UniformDirection(std::uint64_t seed, int i) {
  const double z = 2 * UniformAt(seed, i, 3) - 1, a = 2 * paper::kPi * UniformAt(seed, i, 4),
               s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(a), s * std::sin(a), z};
}

AnteriorChamber<double> ChamberOf(CorneaModel model) {
  ChamberParams params;
  params.model = model;
  return AnteriorChamber<double>(params);
}

const char* NameOf(CorneaModel model) { return model == CorneaModel::EllipsoidCone ? "ellipsoid-cone" : "paraboloid"; }

}  // namespace

TEST_CASE("the next surface from inside the chamber is the full two-piece search's, without its extra intersections") {
  // NextSurfaceFromInside skips the cap for rays that land on the iris disk and the second piece once the first
  // gives the exit (the chamber is convex). Rays from points inside, from the iris plane up and from cap points
  // (reflections, heading in), in every direction, for both cornea models.
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    const AnteriorChamber<double> chamber = ChamberOf(model);
    const auto& surface = chamber.Surface();
    int counts[4] = {}, mismatches = 0;
    double worst = 0;
    for (int i = 0; i < 200000; ++i) {
      const double r = chamber.IrisRadius() * std::sqrt(UniformAt(3, i, 0)), phi = 2 * paper::kPi * UniformAt(3, i, 1);
      const double x = r * std::cos(phi), y = r * std::sin(phi), top = surface.Sag(r);
      V p;
      switch (i % 3) {
        case 0: p = {x, y, chamber.IrisZ() + UniformAt(3, i, 2) * (top - chamber.IrisZ())}; break;  // inside
        case 1: p = {x, y, chamber.IrisZ()}; break;                                                 // on the iris
        default: p = {x, y, top}; break;                                                            // on the cap
      }
      V d = UniformDirection(3, i);
      if (i % 3 == 1 && d.z < 0) d.z = -d.z;                                // off the iris plane, up
      if (i % 3 == 2 && glm::dot(d, surface.Normal(p.x, p.y)) > 0) d = -d;  // off the cap, in
      const ChamberSurfaceHit<double> fast = chamber.NextSurfaceFromInside(p, d),
                                      full = NextSurfaceByFullSearch(chamber, p, d);
      ++counts[full.kind];
      const double gap = glm::length(fast.point - full.point);
      if (fast.kind != full.kind || !(gap <= 1e-12)) ++mismatches;
      if (fast.kind == full.kind) worst = std::max(worst, gap);
    }
    std::printf("%s: iris %d, pupil %d, cornea %d, lost %d of 200000 rays; %d differ, worst point gap %.1e mm\n",
                NameOf(model), counts[0], counts[1], counts[2], counts[3], mismatches, worst);
    CHECK(mismatches == 0);
    CHECK(counts[0] > 10000);
    CHECK(counts[2] > 10000);
  }
}

TEST_CASE("a ray from inside aimed at the junction ring leaves through the piece the full search finds") {
  // The exit's piece is told by where the ray crosses the junction plane (AnteriorSurface::ExitPiece); near the ring,
  // within rounding, both pieces are tried. Rays from inside and from cap points towards points 1e-12 to 1e-2 mm off
  // the junction ring, above and below it.
  const AnteriorChamber<double> chamber = ChamberOf(CorneaModel::EllipsoidCone);
  const auto& surface = chamber.Surface();
  const double rj = surface.JunctionRadius(), zj = surface.Sag(rj);
  int mismatches = 0, cornea = 0;
  for (int i = 0; i < 100000; ++i) {
    const double phi = 2 * paper::kPi * UniformAt(5, i, 0), off = std::pow(10.0, -12 + 10 * UniformAt(5, i, 1));
    const double side = UniformAt(5, i, 2) < 0.5 ? -1 : 1;
    const V target((rj + side * off) * std::cos(phi), (rj + side * off) * std::sin(phi), zj + side * off * 0.3);
    const double r = chamber.IrisRadius() * std::sqrt(UniformAt(5, i, 3)), a = 2 * paper::kPi * UniformAt(5, i, 4);
    const double top = surface.Sag(r);
    const V p(r * std::cos(a), r * std::sin(a),
              i % 2 ? top : chamber.IrisZ() + UniformAt(5, i, 5) * (top - chamber.IrisZ()));
    const V d = glm::normalize(target - p);
    const ChamberSurfaceHit<double> fast = chamber.NextSurfaceFromInside(p, d),
                                    full = NextSurfaceByFullSearch(chamber, p, d);
    cornea += full.kind == ChamberSurfaceHit<double>::Cornea;
    if (fast.kind != full.kind || !(glm::length(fast.point - full.point) <= 1e-12)) ++mismatches;
  }
  std::printf("rays at the junction ring: %d of 100000 leave through the cornea; %d differ\n", cornea, mismatches);
  CHECK(mismatches == 0);
  CHECK(cornea > 30000);
}

TEST_CASE("a ray from outside enters the cap where both pieces' search finds, whichever piece is tried first") {
  // AnteriorSurface tries the cone first for rays that come down through the junction plane outside the junction
  // disk, and stops at the first piece that gives an entry. The reference intersects both pieces' quadrics and takes
  // the nearest root on its own piece (an exit, for rays from below that reach the cap from inside). Rays from 20 to 60
  // mm away (above the cap, beside it, below the rim plane) towards cap points and past the rim; points within 1e-6 mm
  // of the junction ring are left to the ring's own test.
  const AnteriorChamber<double> chamber = ChamberOf(CorneaModel::EllipsoidCone);
  const auto& surface = chamber.Surface();
  const double rj = surface.JunctionRadius(), rim = surface.RimRadius();
  const auto reference = [&](const V& o, const V& d) {
    double best = INFINITY;
    for (SurfacePiece piece : {SurfacePiece::Ellipsoid, SurfacePiece::Cone})
      IntersectQuadric(surface.Quadric(piece), o, d, V(0, 0, -2), 9.0, [&](double t, const V& p) {
        const double r = std::hypot(p.x, p.y);
        // On the cap: the piece's radii, and its sheet through the apex (not the ellipsoid's far side).
        if (r > rim || surface.PieceAt(r) != piece || !(std::abs(p.z - surface.Sag(r)) < 1e-6)) return false;
        best = std::min(best, t);
        return true;
      });
    return best;
  };
  int entries[2] = {}, entering = 0, misses = 0, mismatches = 0;
  for (int i = 0; i < 200000; ++i) {
    const V from = (20 + 40 * UniformAt(7, i, 0)) * UniformDirection(7, i);
    const double r = 1.1 * rim * std::sqrt(UniformAt(7, i, 1)), a = 2 * paper::kPi * UniformAt(7, i, 2);
    const V target(r * std::cos(a), r * std::sin(a), surface.Sag(std::min(r, rim)));
    const V d = glm::normalize(target - from);
    const auto hit = surface.Intersect({from, d});
    const double expected = reference(from, d);
    if (!hit) {
      ++misses;
      if (std::isfinite(expected)) ++mismatches;
      continue;
    }
    const double radius = std::hypot(hit->point.x, hit->point.y);
    if (std::abs(radius - rj) < 1e-6) continue;
    ++entries[surface.PieceAt(radius) == SurfacePiece::Cone];
    entering += hit->fromOutside;
    if (!(std::abs(hit->t - expected) <= 1e-9)) ++mismatches;
  }
  std::printf("rays from outside: %d meet the ellipsoid first, %d the cone (%d of them entering), %d miss; %d differ\n",
              entries[0], entries[1], entering, misses, mismatches);
  CHECK(mismatches == 0);
  CHECK(entering > 100000);
  CHECK(entries[0] > 20000);
  CHECK(entries[1] > 20000);
}

TEST_CASE("a ray that heads away from the cap's tangent plane above it meets neither the cap nor the iris disk") {
  // AnteriorSurface::HeadsAway: exact for a convex region; checked against the intersections themselves for rays
  // from points above the cap (on it, as offset shadow rays start, and up to 2 mm above) in every direction.
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    const AnteriorChamber<double> chamber = ChamberOf(model);
    const auto& surface = chamber.Surface();
    int away = 0, wrong = 0;
    for (int i = 0; i < 200000; ++i) {
      const double r = surface.RimRadius() * std::sqrt(UniformAt(9, i, 0)), phi = 2 * paper::kPi * UniformAt(9, i, 1);
      const double lift = i % 2 ? 1e-9 : 2 * UniformAt(9, i, 2);
      const V o(r * std::cos(phi), r * std::sin(phi), surface.Sag(r) + lift);
      const V d = UniformDirection(9, i);
      if (!surface.HeadsAway(o, d)) continue;
      ++away;
      const auto cap = surface.Intersect({o, d});
      if ((cap && cap->fromOutside) || chamber.IntersectIris({o, d})) ++wrong;
    }
    std::printf("%s: %d of 200000 rays head away; %d of them meet the cap from outside or the iris disk\n",
                NameOf(model), away, wrong);
    CHECK(away > 50000);
    CHECK(wrong == 0);
  }
}
