// The chamber-light cache on the iris: its transport against a Monte Carlo walk of the same chamber, its
// resolution bias, determinism, and zero light in, zero light out.
#include "eyelib/iris_chamber_cache.h"
#include "eyelib/optics.h"
#include "eyelib/random.h"
#include "eyelib/sampling.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <limits>

using namespace eyelib;

namespace {

/// A first-order irradiance with a sharp shadow edge, as a grazing key casts: lit (1) where x > 1 mm, dark beyond.
double HalfLit(double x, double /*y*/) { return x > 1.0 ? 1.0 : 0.0; }

/// Chamber irradiance at iris point x by Monte Carlo over the same walk eyeShading's chamber takes (cosine bounce,
/// Fresnel reflection chosen with its probability), first-order light HalfLit, uniform albedo: the mean of
/// sum over later iris vertices v of albedo^(v - 1) HalfLit(x_v); also its standard error.
struct WalkResult {
  double mean, sigma;
  double predicted;  ///< the mean of the cache's prediction at each walk's second vertex (the control variate's)
  double predictedSigma;
};

/// The control variate's first-vertex term at x: the mean over `shifts` random shifts of the 2 x 2 lattice of what
/// the cache predicts where its chamber paths land (eyeShading's PredictedChamberLight), with its standard error.
std::pair<double, double> PredictAtFirstVertex(const AnteriorChamber<double>& chamber, const IrisChamberCache& cache,
                                               const Vec3d& x, double albedo, int shifts, std::uint64_t seed) {
  double sum = 0, sumSq = 0;
  for (int n = 0; n < shifts; ++n) {
    const double u1 = UniformAt(seed, n, 0), u2 = UniformAt(seed, n, 1);
    double e = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        double share;
        const ChamberReturn back = TraceChamberReturn(chamber, x, ChamberDirection(a, b, 2, u1, u2, &share));
        e += share * back.weight * albedo * cache.Irradiance(back.point).x;
      }
    sum += e, sumSq += e * e;
  }
  const double mean = sum / shifts;
  return {mean, std::sqrt(std::max(0.0, sumSq / shifts - mean * mean) / shifts)};
}

WalkResult WalkChamberLight(const AnteriorChamber<double>& chamber, const Vec3d& x, double albedo, int walks,
                            std::uint64_t seed, const IrisChamberCache& cache) {
  const auto& surface = chamber.Surface();
  const double inf = std::numeric_limits<double>::infinity();
  double sum = 0, sumSq = 0, predicted = 0, predictedSq = 0;
  for (int w = 0; w < walks; ++w) {
    std::uint64_t dim = 0;
    auto u = [&] { return UniformAt(seed, std::uint64_t(w), dim++); };
    Vec3d p = x, d = SampleCosineHemisphere(Vec3d(0, 0, 1), u(), u());
    double beta = albedo, value = 0;
    for (int k = 0; k < 64; ++k) {
      const double tPlane = d.z < 0 ? (chamber.IrisZ() - p.z) / d.z : inf;
      auto cap = surface.Intersect({p, d});
      if (cap && cap->fromOutside) cap.reset();
      if (tPlane < (cap ? cap->t : inf)) {
        p = p + tPlane * d;
        p.z = chamber.IrisZ();
        if (std::hypot(p.x, p.y) < chamber.PupilRadius()) break;
        if (beta == albedo) {
          const double h = albedo * cache.Irradiance(p).x;
          predicted += h, predictedSq += h * h;
        }
        value += beta * HalfLit(p.x, p.y);
        beta *= albedo;
        d = SampleCosineHemisphere(Vec3d(0, 0, 1), u(), u());
        continue;
      }
      if (!cap) break;
      if (u() >= FresnelDielectric(glm::dot(-d, cap->normal), chamber.CorneaIor())) break;  // out of the eye
      p = cap->point;
      d = d - 2 * glm::dot(d, cap->normal) * cap->normal;
    }
    sum += value, sumSq += value * value;
  }
  const double mean = sum / walks;
  const double h = predicted / walks;
  return {mean, std::sqrt(std::max(0.0, sumSq / walks - mean * mean) / walks), h,
          std::sqrt(std::max(0.0, predictedSq / walks - h * h) / walks)};
}

IrisChamberCache HalfLitCache(const IrisChamberTransport& t, double albedo) {
  std::vector<Vec3d> direct(t.Nodes()), nodeAlbedo(t.Nodes(), Vec3d(albedo));
  for (int i = 0; i < t.Nodes(); ++i) direct[i] = Vec3d(HalfLit(t.Node(i).x, t.Node(i).y));
  return IrisChamberCache(t, direct, nodeAlbedo);
}

}  // namespace

TEST_CASE(
    "the cached chamber light is the chamber walk's mean within its resolution bias, the control variate's "
    "exactly") {
  const AnteriorChamber<double> chamber;
  const double albedo = 0.5;
  // The default grid, and a coarse one (16 x 48 nodes, 24 x 24 directions) to show what resolution buys.
  const IrisChamberTransport transport(chamber, IrisPolarGrid{}), coarse(chamber, IrisPolarGrid{16, 48, 24});
  const IrisChamberCache cache = HalfLitCache(transport, albedo), rough = HalfLitCache(coarse, albedo);
  std::printf("chamber return (cosine-weighted, mean over nodes): %.4f; bounces %d\n", transport.MeanReturn(),
              cache.Bounces());
  CHECK(transport.MeanReturn() > 0.05);
  CHECK(transport.MeanReturn() < 0.6);
  // Points in the shadow (x < 1 mm, where chamber light is all there is), on the edge and in the light.
  const Vec3d points[] = {{-5, 0.3, 0}, {-3, -4, 0}, {-2.2, 0, 0}, {0, 4, 0}, {1.2, -2, 0}, {4, 3, 0}, {6.5, -1, 0}};
  double worstZ = 0, worstBias = 0, worstRough = 0, worstCv = 0;
  for (int k = 0; k < 7; ++k) {
    const Vec3d x(points[k].x, points[k].y, chamber.IrisZ());
    const WalkResult walk = WalkChamberLight(chamber, x, albedo, 400000, 7 + k, cache);
    const double c = cache.Chamber(x).x, r = rough.Chamber(x).x;
    const double z = (c - walk.mean) / walk.sigma, bias = (c - walk.mean) / walk.mean,
                 roughBias = (r - walk.mean) / walk.mean;
    // The control variate adds PredictAtFirstVertex at the first vertex and subtracts the cache's prediction at the
    // second: the two means must agree whatever the cache's own error.
    const auto [added, addedSigma] = PredictAtFirstVertex(chamber, cache, x, albedo, 200000, 70 + k);
    const double cvZ = (added - walk.predicted) / std::hypot(addedSigma, walk.predictedSigma);
    std::printf(
        "x (%5.2f, %5.2f): walk %.5f +- %.5f, cache %.5f (%+.2f %%, z %+.2f), coarse cache %.5f (%+.2f %%); "
        "control variate adds %.5f, subtracts %.5f (z %+.2f)\n",
        x.x, x.y, walk.mean, walk.sigma, c, 100 * bias, z, r, 100 * roughBias, added, walk.predicted, cvZ);
    worstCv = std::max(worstCv, std::abs(cvZ));
    CHECK(std::abs(cvZ) < 4);
    worstZ = std::max(worstZ, std::abs(z));
    worstBias = std::max(worstBias, std::abs(bias));
    worstRough = std::max(worstRough, std::abs(roughBias));
    CHECK(std::abs(z) < 4);  // within the walk's own noise
  }
  std::printf(
      "worst error of the cache %.2f %% (|z| %.2f), of the coarse cache %.2f %% (of the chamber light); "
      "worst |z| of the control variate's two terms %.2f\n",
      100 * worstBias, worstZ, 100 * worstRough, worstCv);
  CHECK(worstBias < 0.025);
  CHECK(worstRough > 2 * worstBias);  // the resolution is what keeps it small
}

TEST_CASE("sweep chamber-cache: the cache's worst bias at a sharp shadow edge by grid rings (the render plan's)") {
  // The render plan gives small eyes fewer rings (3 sectors per ring, the default directions); this is the bias it
  // accepts for them, against the walk's mean at the seven points of the test above.
  const AnteriorChamber<double> chamber;
  const double albedo = 0.5;
  const Vec3d points[] = {{-5, 0.3, 0}, {-3, -4, 0}, {-2.2, 0, 0}, {0, 4, 0}, {1.2, -2, 0}, {4, 3, 0}, {6.5, -1, 0}};
  const IrisChamberCache reference = HalfLitCache(IrisChamberTransport(chamber, IrisPolarGrid{}), albedo);
  double walk[7];
  for (int k = 0; k < 7; ++k)
    walk[k] =
        WalkChamberLight(chamber, Vec3d(points[k].x, points[k].y, chamber.IrisZ()), albedo, 200000, 7 + k, reference)
            .mean;
  double worstAt[49] = {};
  for (int rings : {12, 24, 32, 48}) {
    IrisPolarGrid grid;
    grid.rings = rings, grid.sectors = 3 * rings;
    const IrisChamberTransport t(chamber, grid);
    const IrisChamberCache cache = HalfLitCache(t, albedo);
    double worst = 0, sumSq = 0;
    for (int k = 0; k < 7; ++k) {
      const double bias = cache.Chamber(Vec3d(points[k].x, points[k].y, chamber.IrisZ())).x / walk[k] - 1;
      worst = std::max(worst, std::abs(bias)), sumSq += bias * bias;
    }
    std::printf("%2d rings x %3d sectors (%4d nodes): worst bias %.2f %%, rms %.2f %% of the chamber light\n", rings,
                3 * rings, t.Nodes(), 100 * worst, 100 * std::sqrt(sumSq / 7));
    worstAt[rings] = worst;
  }
  CHECK(worstAt[48] < 0.025);
  CHECK(worstAt[32] < 0.025);
  CHECK(worstAt[24] < 0.04);
  CHECK(worstAt[12] < 0.1);
  CHECK(worstAt[12] > worstAt[48]);
}

TEST_CASE("the cache solves its fixed point: each node's chamber light is what its ring's turned landings bring") {
  // E_chamber(node) = sum over the landings of the node's ring, turned to the node, of weight x albedo x (E_direct +
  // E_chamber) where the landing falls (uniform albedo: the cache's own Irradiance there). Checked node by node
  // against the landings themselves, on grids whose sector counts take KissFFT's radix-2, -3 and generic (7) paths.
  const AnteriorChamber<double> chamber;
  const double albedo = 0.6;
  for (const IrisPolarGrid grid : {IrisPolarGrid{8, 24, 8}, IrisPolarGrid{5, 21, 6}, IrisPolarGrid{3, 16, 10}}) {
    const IrisChamberTransport t(chamber, grid);
    std::vector<Vec3d> direct(t.Nodes());
    for (int i = 0; i < t.Nodes(); ++i)  // lopsided, so that no symmetry hides a wrong turn
      direct[i] = Vec3d(HalfLit(t.Node(i).x, t.Node(i).y), UniformAt(5, i, 0), t.Node(i).y > 0 ? 2.0 : 0.1);
    const IrisChamberCache cache(t, direct, std::vector<Vec3d>(t.Nodes(), Vec3d(albedo)), {}, 200, 1e-15);
    double worst = 0, largest = 0;
    for (int n = 0; n < t.Nodes(); ++n) {
      const int ring = n / grid.sectors, sector = n % grid.sectors;
      const double turn = sector * t.SectorAngle(), c = std::cos(turn), s = std::sin(turn);
      Vec3d expected(0);
      for (const auto* l = t.RingLandingsBegin(ring); l != t.RingLandingsEnd(ring); ++l)
        expected += l->weight * albedo * cache.Irradiance(Vec3d(c * l->x - s * l->y, s * l->x + c * l->y, 0));
      const Vec3d got = cache.ChamberAtNodes()[n];
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(got[k] - expected[k])), largest = std::max(largest, got[k]);
    }
    INFO(grid.rings << " x " << grid.sectors << ": worst difference " << worst << " of the largest " << largest);
    CHECK(largest > 0.01);
    CHECK(worst < 1e-12 * largest);
  }
}

TEST_CASE("a chamber without first-order light has no chamber light, and the cache is deterministic") {
  const AnteriorChamber<double> chamber;
  const IrisChamberTransport t(chamber, IrisPolarGrid{8, 24, 8});
  const IrisChamberCache dark(t, std::vector<Vec3d>(t.Nodes(), Vec3d(0)), std::vector<Vec3d>(t.Nodes(), Vec3d(0.5)));
  for (const Vec3d& e : dark.ChamberAtNodes()) CHECK(e == Vec3d(0));
  CHECK(dark.Chamber(Vec3d(3, 1, chamber.IrisZ())) == Vec3d(0));
  // Bad input counts as no light: NaN, Inf and negative irradiance, a NaN albedo.
  std::vector<Vec3d> bad(t.Nodes(), Vec3d(std::numeric_limits<double>::quiet_NaN()));
  bad[1] = Vec3d(std::numeric_limits<double>::infinity()), bad[2] = Vec3d(-1);
  const IrisChamberCache guarded(t, bad, std::vector<Vec3d>(t.Nodes(), Vec3d(NAN)));
  for (const Vec3d& e : guarded.ChamberAtNodes()) CHECK(e == Vec3d(0));
  const IrisChamberTransport again(chamber, IrisPolarGrid{8, 24, 8});
  REQUIRE(again.Landings().size() == t.Landings().size());
  for (std::size_t k = 0; k < t.Landings().size(); ++k) {
    CHECK(again.Landings()[k].x == t.Landings()[k].x);
    CHECK(again.Landings()[k].weight == t.Landings()[k].weight);
  }
}

TEST_CASE("chamber light is finite everywhere on the iris and in the pupil, and zero-albedo irises return nothing") {
  const AnteriorChamber<double> chamber;
  const IrisChamberTransport t(chamber, IrisPolarGrid{8, 24, 8});
  const IrisChamberCache lit(t, std::vector<Vec3d>(t.Nodes(), Vec3d(1)), std::vector<Vec3d>(t.Nodes(), Vec3d(1)));
  for (double r = 0; r <= 7.6; r += 0.1)
    for (double phi = 0; phi < 6.3; phi += 0.05) {
      const Vec3d e = lit.Chamber(Vec3d(r * std::cos(phi), r * std::sin(phi), chamber.IrisZ()));
      REQUIRE(std::isfinite(e.x));
      REQUIRE(e.x >= 0);
      REQUIRE(e.x < 10);  // albedo 1: at most R / (1 - R) for the largest return R (about 0.5)
    }
  const IrisChamberCache black(t, std::vector<Vec3d>(t.Nodes(), Vec3d(1)), std::vector<Vec3d>(t.Nodes(), Vec3d(0)));
  for (const Vec3d& e : black.ChamberAtNodes()) CHECK(e == Vec3d(0));
}
