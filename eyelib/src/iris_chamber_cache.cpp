#include "eyelib/iris_chamber_cache.h"

#include "eyelib/optics.h"
#include "eyelib/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace eyelib {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// A chamber path whose Fresnel weight falls below this (of one direction's share) carries nothing measurable.
constexpr double kNegligibleWeight = 1e-9;

double Azimuth(double x, double y) {
  const double phi = std::atan2(y, x);
  return phi < 0 ? phi + 2 * paper::kPi : phi;
}

}  // namespace

IrisPolarGrid IrisChamberTransport::Valid(IrisPolarGrid grid) {
  grid.rings = std::max(1, grid.rings);
  grid.sectors = std::max(1, grid.sectors);
  grid.directionsPerSide = std::max(1, grid.directionsPerSide);
  return grid;
}

std::vector<IrisChamberTransport::Landing> IrisChamberTransport::NodeLandings(const AnteriorChamber<double>& chamber,
                                                                              const IrisPolarGrid& grid, int i,
                                                                              int maxEvents) {
  const IrisPolarGrid g = Valid(grid);
  const Vec3d x = NodeOf(g, chamber.PupilRadius(), chamber.IrisRadius(), chamber.IrisZ(), i);
  const int side = g.directionsPerSide;
  std::vector<Landing> landings;
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b) {
      double share;
      const Vec3d d = ChamberDirection(a, b, side, 0.5, 0.5, &share);
      const ChamberReturn back = TraceChamberReturn(chamber, x, d, maxEvents);
      if (back.weight > 0) landings.push_back({back.point.x, back.point.y, share * back.weight});
    }
  return landings;
}

IrisChamberTransport::IrisChamberTransport(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid,
                                           int maxEvents)
    : grid_(Valid(grid)), rMin_(chamber.PupilRadius()), rMax_(chamber.IrisRadius()), irisZ_(chamber.IrisZ()) {
  offsets_.reserve(Nodes() + 1);
  offsets_.push_back(0);
  for (int i = 0; i < Nodes(); ++i) {
    const std::vector<Landing> node = NodeLandings(chamber, grid_, i, maxEvents);
    landings_.insert(landings_.end(), node.begin(), node.end());
    offsets_.push_back(landings_.size());
  }
}

IrisChamberTransport::IrisChamberTransport(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid,
                                           const std::vector<std::vector<Landing>>& nodeLandings)
    : grid_(Valid(grid)), rMin_(chamber.PupilRadius()), rMax_(chamber.IrisRadius()), irisZ_(chamber.IrisZ()) {
  offsets_.reserve(Nodes() + 1);
  offsets_.push_back(0);
  for (int i = 0; i < Nodes(); ++i) {
    if (std::size_t(i) < nodeLandings.size())
      landings_.insert(landings_.end(), nodeLandings[i].begin(), nodeLandings[i].end());
    offsets_.push_back(landings_.size());
  }
}

ChamberReturn TraceChamberReturn(const AnteriorChamber<double>& chamber, const Vec3d& x, const Vec3d& d0,
                                 int maxEvents) {
  Vec3d p = x, d = d0;
  double weight = 1;
  for (int k = 0; k < maxEvents && weight > kNegligibleWeight; ++k) {
    const ChamberSurfaceHit<double> hit = chamber.NextSurfaceFromInside(p, d);
    if (hit.kind == ChamberSurfaceHit<double>::Iris) return {hit.point, weight};
    if (hit.kind != ChamberSurfaceHit<double>::Cornea) return {};  // into the lens, or through the gap at the rim
    p = hit.point;
    weight *= FresnelDielectric(glm::dot(-d, hit.normal), chamber.CorneaIor());
    d = d - 2 * glm::dot(d, hit.normal) * hit.normal;
  }
  return {};
}

Vec3d ChamberDirection(int a, int b, int side, double u1, double u2, double* weight) {
  const double t = (a + u1) / side;
  *weight = 2 * (1 - t) / double(side * side);
  return SampleCosineHemisphere(Vec3d(0, 0, 1), 1 - (1 - t) * (1 - t), (b + u2) / side);
}

Vec3d IrisChamberTransport::NodeOf(const IrisPolarGrid& grid, double rMin, double rMax, double irisZ, int i) {
  const int ring = i / grid.sectors, sector = i % grid.sectors;
  const double r = rMin + (ring + 0.5) * (rMax - rMin) / grid.rings;
  const double phi = (sector + 0.5) * 2 * paper::kPi / grid.sectors;
  return {r * std::cos(phi), r * std::sin(phi), irisZ};
}

double IrisChamberTransport::MeanReturn() const {
  double sum = 0;
  for (const Landing& l : landings_) sum += l.weight;
  return Nodes() > 0 ? sum / Nodes() : 0;
}

IrisChamberCache::IrisChamberCache(const IrisChamberTransport& transport, const std::vector<Vec3d>& direct,
                                   const std::vector<Vec3d>& landingAlbedo, int maxBounces, double tolerance)
    : grid_(transport.Grid()), rMin_(transport.InnerRadius()), rMax_(transport.OuterRadius()) {
  const int nodes = transport.Nodes();
  direct_.assign(nodes, Vec3d(0));
  for (int i = 0; i < nodes && i < int(direct.size()); ++i) {
    const Vec3d& e = direct[i];
    const bool valid = std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z);
    direct_[i] = valid ? glm::max(e, Vec3d(0)) : Vec3d(0);
  }
  chamber_.assign(nodes, Vec3d(0));
  const std::vector<IrisChamberTransport::Landing>& landings = transport.Landings();
  std::vector<Vec3d> albedo(landings.size(), Vec3d(0));
  for (std::size_t k = 0; k < landings.size() && k < landingAlbedo.size(); ++k) {
    const Vec3d& a = landingAlbedo[k];
    const bool valid = std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
    albedo[k] = valid ? glm::clamp(a, Vec3d(0), Vec3d(1)) : Vec3d(0);
  }
  // Jacobi iteration of E_chamber = T[albedo (E_direct + E_chamber)]: the cosine-weighted quadrature already
  // carries the 1 / pi of the Lambertian lobe (E = pi x the mean radiance over cosine-distributed directions).
  // Each bounce scales by at most albedo x MeanReturn (about 0.1): it converges in a few bounces.
  std::vector<Vec3d> next(nodes);
  for (bounces_ = 0; bounces_ < std::max(1, maxBounces);) {
    double added = 0, total = 0;
    for (int i = 0; i < nodes; ++i) {
      Vec3d e(0);
      const auto* first = transport.LandingsBegin(i);
      for (const auto* l = first; l != transport.LandingsEnd(i); ++l) {
        const Vec3d land(l->x, l->y, 0);
        e += l->weight * albedo[l - landings.data()] * (Interpolate(direct_, land) + Interpolate(chamber_, land));
      }
      next[i] = e;
      added += glm::length(e - chamber_[i]);
      total += glm::length(e + direct_[i]);
    }
    chamber_.swap(next);
    ++bounces_;
    if (!(added > tolerance * total)) break;
  }
}

Vec3d IrisChamberCache::Interpolate(const std::vector<Vec3d>& values, const Vec3d& x) const {
  if (values.empty()) return Vec3d(0);
  const int rings = grid_.rings, sectors = grid_.sectors;
  const double rr = (std::hypot(x.x, x.y) - rMin_) / (rMax_ - rMin_) * rings - 0.5;
  const double ss = Azimuth(x.x, x.y) / (2 * paper::kPi) * sectors - 0.5;
  const double rc = std::clamp(rr, 0.0, double(rings - 1));
  const int r0 = std::min(rings - 1, int(std::floor(rc))), r1 = std::min(rings - 1, r0 + 1);
  const double fr = rc - r0;
  const double sf = std::floor(ss);
  const double fs = ss - sf;
  const int s0 = ((int(sf) % sectors) + sectors) % sectors, s1 = (s0 + 1) % sectors;
  const auto at = [&](int r, int s) { return values[std::size_t(r) * sectors + s]; };
  return (1 - fr) * ((1 - fs) * at(r0, s0) + fs * at(r0, s1)) + fr * ((1 - fs) * at(r1, s0) + fs * at(r1, s1));
}

}  // namespace eyelib
