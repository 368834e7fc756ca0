#include "eyelib/iris_chamber_cache.h"

#include "eyelib/optics.h"
#include "eyelib/sampling.h"

#include <kissfft/kissfft.hh>

#include <algorithm>
#include <cmath>
#include <complex>
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

using Complex = std::complex<double>;

/// The discrete Fourier transform over a ring's sectors (KissFFT, any sector count). Not to be shared between
/// threads: it has a buffer of its own, and KissFFT keeps scratch space for radices above 5.
class SectorTransform {
 public:
  explicit SectorTransform(int sectors)
      : forward_(std::size_t(sectors), false), inverse_(std::size_t(sectors), true), buffer_(std::size_t(sectors)) {}
  /// The spectrum of `sectors` real values.
  void Forward(const double* values, Complex* spectrum) {
    for (std::size_t q = 0; q < buffer_.size(); ++q) buffer_[q] = values[q];
    forward_.transform(buffer_.data(), spectrum);
  }
  /// The real part of the unnormalised inverse transform of a spectrum, clamped at 0: light is never negative, and
  /// the transforms' rounding (about 1e-16 of the largest value) can make a dark node's so.
  void InverseReal(const Complex* spectrum, double* values) {
    inverse_.transform(spectrum, buffer_.data());
    for (std::size_t q = 0; q < buffer_.size(); ++q) values[q] = std::max(0.0, buffer_[q].real());
  }

 private:
  kissfft<double> forward_, inverse_;
  std::vector<Complex> buffer_;
};

}  // namespace

IrisPolarGrid IrisChamberTransport::Valid(IrisPolarGrid grid) {
  grid.rings = std::max(1, grid.rings);
  grid.sectors = std::max(1, grid.sectors);
  grid.directionsPerSide = std::max(1, grid.directionsPerSide);
  return grid;
}

std::vector<IrisChamberTransport::Landing> IrisChamberTransport::RingLandings(const AnteriorChamber<double>& chamber,
                                                                              const IrisPolarGrid& grid, int ring,
                                                                              int maxEvents) {
  const IrisPolarGrid g = Valid(grid);
  const Vec3d x = NodeOf(g, chamber.PupilRadius(), chamber.IrisRadius(), chamber.IrisZ(), ring * g.sectors);
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
  offsets_.reserve(grid_.rings + 1);
  offsets_.push_back(0);
  for (int r = 0; r < grid_.rings; ++r) {
    const std::vector<Landing> ring = RingLandings(chamber, grid_, r, maxEvents);
    landings_.insert(landings_.end(), ring.begin(), ring.end());
    offsets_.push_back(landings_.size());
  }
}

IrisChamberTransport::IrisChamberTransport(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid,
                                           const std::vector<std::vector<Landing>>& ringLandings)
    : grid_(Valid(grid)), rMin_(chamber.PupilRadius()), rMax_(chamber.IrisRadius()), irisZ_(chamber.IrisZ()) {
  offsets_.reserve(grid_.rings + 1);
  offsets_.push_back(0);
  for (int r = 0; r < grid_.rings; ++r) {
    if (std::size_t(r) < ringLandings.size())
      landings_.insert(landings_.end(), ringLandings[r].begin(), ringLandings[r].end());
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
  return sum / grid_.rings;  // every node of a ring returns what its first node does
}

IrisChamberCache::IrisChamberCache(const IrisChamberTransport& transport, const std::vector<Vec3d>& direct,
                                   const std::vector<Vec3d>& albedo, ParallelFor parallelFor, int maxBounces,
                                   double tolerance)
    : grid_(transport.Grid()), rMin_(transport.InnerRadius()), rMax_(transport.OuterRadius()) {
  const int nodes = transport.Nodes();
  const auto valid = [](const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  direct_.assign(nodes, Vec3d(0));
  std::vector<Vec3d> nodeAlbedo(nodes, Vec3d(0));
  for (int i = 0; i < nodes; ++i) {
    if (i < int(direct.size()) && valid(direct[i])) direct_[i] = glm::max(direct[i], Vec3d(0));
    if (i < int(albedo.size()) && valid(albedo[i])) nodeAlbedo[i] = glm::clamp(albedo[i], Vec3d(0), Vec3d(1));
  }
  chamber_.assign(nodes, Vec3d(0));
  const int rings = grid_.rings, sectors = grid_.sectors;
  const auto forEachRing = [&](FunctionRef<void(int)> body) {
    if (parallelFor) {
      parallelFor(rings, body);
    } else {
      for (int i = 0; i < rings; ++i) body(i);
    }
  };
  // Node (ring, s) reads its ring's landings turned by s sectors, so the transport is one kernel per ring, turned:
  // kernel[i][j][d] is what node (j, d + s) sends to node (i, s) per unit of light leaving it (each landing's
  // Fresnel weight spread over the four nodes it interpolates).
  std::vector<double> kernel(std::size_t(rings) * nodes, 0.0);
  forEachRing([&](int i) {
    double* k = &kernel[std::size_t(i) * nodes];
    for (const auto* l = transport.RingLandingsBegin(i); l != transport.RingLandingsEnd(i); ++l) {
      const Stencil st = StencilAt(Vec3d(l->x, l->y, 0));
      const int r1 = std::min(rings - 1, st.ring + 1), s1 = (st.sector + 1) % sectors;
      const double fr = st.fr, fs = st.fs;
      k[st.ring * sectors + st.sector] += l->weight * (1 - fr) * (1 - fs);
      k[st.ring * sectors + s1] += l->weight * (1 - fr) * fs;
      k[r1 * sectors + st.sector] += l->weight * fr * (1 - fs);
      k[r1 * sectors + s1] += l->weight * fr * fs;
    }
  });
  // A turned kernel is a circular correlation over sectors, so in the sectors' Fourier basis the transport is one
  // rings x rings matrix per frequency: a bounce costs rings^2 x sectors products (and a transform per ring) instead
  // of rings^2 x sectors^2. Correlating with K is multiplying by K's conjugate spectrum; the inverse transform's
  // factor 1 / sectors is folded into it.
  // A transform per ring (copies of one: its twiddles computed once), used only by that ring's body, on one thread.
  std::vector<SectorTransform> transforms(rings, SectorTransform(sectors));
  std::vector<Complex> kernelSpectrum(std::size_t(rings) * nodes);
  forEachRing([&](int i) {
    SectorTransform& transform = transforms[i];
    for (int j = 0; j < rings; ++j) {
      Complex* out = &kernelSpectrum[std::size_t(i) * nodes + std::size_t(j) * sectors];
      transform.Forward(&kernel[std::size_t(i) * nodes + std::size_t(j) * sectors], out);
      for (int f = 0; f < sectors; ++f) out[f] = std::conj(out[f]) / double(sectors);
    }
  });
  // Jacobi iteration of E_chamber = T[albedo (E_direct + E_chamber)]: the cosine-weighted quadrature already
  // carries the 1 / pi of the Lambertian lobe (E = pi x the mean radiance over cosine-distributed directions).
  // Each bounce scales by at most albedo x MeanReturn (about 0.1): it converges in a few bounces.
  // Per bounce: the spectrum of the light leaving each ring, channel by channel, then each ring's sum over rings of
  // kernel x leaving, frequency by frequency, transformed back. Each ring's sums run in a fixed order, on any thread.
  std::vector<Complex> leavingSpectrum(3 * std::size_t(nodes));
  std::vector<double> next(3 * std::size_t(nodes));
  for (bounces_ = 0; bounces_ < std::max(1, maxBounces);) {
    forEachRing([&](int j) {
      SectorTransform& transform = transforms[j];
      std::vector<double> leaving(sectors);
      for (int c = 0; c < 3; ++c) {
        for (int q = 0; q < sectors; ++q) {
          const int n = j * sectors + q;
          leaving[q] = nodeAlbedo[n][c] * (direct_[n][c] + chamber_[n][c]);
        }
        transform.Forward(leaving.data(), &leavingSpectrum[c * std::size_t(nodes) + std::size_t(j) * sectors]);
      }
    });
    forEachRing([&](int i) {
      SectorTransform& transform = transforms[i];
      std::vector<Complex> sum(sectors);
      for (int c = 0; c < 3; ++c) {
        std::fill(sum.begin(), sum.end(), Complex(0));
        for (int j = 0; j < rings; ++j) {
          const Complex* k = &kernelSpectrum[std::size_t(i) * nodes + std::size_t(j) * sectors];
          const Complex* l = &leavingSpectrum[c * std::size_t(nodes) + std::size_t(j) * sectors];
          for (int f = 0; f < sectors; ++f)  // by parts: std::complex's product goes through a NaN check (__muldc3)
            sum[f] += Complex(k[f].real() * l[f].real() - k[f].imag() * l[f].imag(),
                              k[f].real() * l[f].imag() + k[f].imag() * l[f].real());
        }
        transform.InverseReal(sum.data(), &next[c * std::size_t(nodes) + std::size_t(i) * sectors]);
      }
    });
    double added = 0, total = 0;
    for (int i = 0; i < nodes; ++i) {
      const Vec3d e(next[i], next[std::size_t(nodes) + i], next[2 * std::size_t(nodes) + i]);
      added += glm::length(e - chamber_[i]);
      total += glm::length(e + direct_[i]);
      chamber_[i] = e;
    }
    ++bounces_;
    if (!(added > tolerance * total)) break;
  }
}

IrisChamberCache::Stencil IrisChamberCache::StencilAt(const Vec3d& x) const {
  const int rings = grid_.rings, sectors = grid_.sectors;
  const double rr = (Radius(x.x, x.y) - rMin_) / (rMax_ - rMin_) * rings - 0.5;
  const double ss = Azimuth(x.x, x.y) / (2 * paper::kPi) * sectors - 0.5;
  const double rc = std::clamp(rr, 0.0, double(rings - 1));
  const int r0 = std::min(rings - 1, int(std::floor(rc)));
  const double sf = std::floor(ss);
  return {r0, ((int(sf) % sectors) + sectors) % sectors, float(rc - r0), float(ss - sf)};
}

Vec3d IrisChamberCache::Interpolate(const std::vector<Vec3d>& values, const Vec3d& x) const {
  if (values.empty()) return Vec3d(0);
  const Stencil st = StencilAt(x);
  const int sectors = grid_.sectors, r1 = std::min(grid_.rings - 1, st.ring + 1), s1 = (st.sector + 1) % sectors;
  const auto at = [&](int r, int q) { return values[std::size_t(r) * sectors + q]; };
  const double fr = st.fr, fs = st.fs;
  return (1 - fr) * ((1 - fs) * at(st.ring, st.sector) + fs * at(st.ring, s1)) +
         fr * ((1 - fs) * at(r1, st.sector) + fs * at(r1, s1));
}

}  // namespace eyelib
