#pragma once
// Chamber light on a polar grid over the iris: the light that reaches an iris point after leaving another iris
// point and reflecting off the cornea's inside (partial reflection and total internal reflection), every bounce
// included. The chamber's geometry alone decides where a direction leaving an iris point lands again and with what
// Fresnel weight (IrisChamberTransport); given the first-order irradiance at the grid's nodes and the albedo where
// each chamber path lands, the fixed point E_chamber = T[albedo / pi (E_direct + E_chamber)] is solved on the grid
// (IrisChamberCache). Units: mm, canonical eye frame; irradiance in whatever unit the caller's first-order
// irradiance has (the cache is linear in it).
#include "eyelib/anterior_chamber.h"
#include "eyelib/function_ref.h"

#include <cstdint>
#include <vector>

namespace eyelib {

using Vec3d = Vec3<double>;

/// Nodes at the centres of a polar lattice over the iris annulus (pupil radius to iris radius), and the
/// directions integrated per node.
struct IrisPolarGrid {
  int rings = 48;              ///< radial nodes, >= 1
  int sectors = 144;           ///< azimuthal nodes, >= 1
  int directionsPerSide = 96;  ///< the hemisphere per node: directionsPerSide^2 cosine-weighted strata, >= 1
};

/// A chamber path that left the iris and came back onto it after reflecting off the cornea's inside.
struct ChamberReturn {
  Vec3d point{0};     ///< mm, on the iris plane
  double weight = 0;  ///< the product of the Fresnel reflectances on the way; 0: the path left the eye or met the pupil
};

/// The chamber path leaving iris point x (mm, on the iris plane) along unit d (d.z > 0): eyeShading's chamber walk
/// with each Fresnel choice replaced by its expectation (the reflected part goes on, the refracted part leaves).
/// At most maxEvents cornea reflections (> 0); a path whose weight falls below 1e-9 ends there.
ChamberReturn TraceChamberReturn(const AnteriorChamber<double>& chamber, const Vec3d& x, const Vec3d& d,
                                 int maxEvents = 64);

/// Direction (a, b) of a side x side lattice of cosine-weighted strata about +z, shifted by (u1, u2) in [0, 1)^2
/// (0.5, 0.5: the strata's centres; uniform random shifts make every direction cosine-distributed). The strata are
/// uniform in t with sin^2(theta) = 1 - (1 - t)^2, denser towards grazing directions, the only ones that meet the
/// cornea beyond the critical angle from the middle of the iris; *weight is the stratum's share (the weights of a
/// lattice sum to 1 for any shift in expectation, and exactly for the centres).
Vec3d ChamberDirection(int a, int b, int side, double u1, double u2, double* weight);

/// Where the chamber paths leaving each node of a grid land on the iris again, with their Fresnel weights.
/// Deterministic: each stratum's centre direction, no random numbers. The chamber is a surface of revolution, so a
/// node's paths are those of the first node of its ring turned by the angle between them (a whole number of sectors):
/// only the first node of each ring is traced, and its landings stand for the ring.
class IrisChamberTransport {
 public:
  /// One chamber path from the first node of a ring: it reflects off the cornea's inside (weight: the product of the
  /// Fresnel reflectances, over the number of directions) and lands at (x, y) on the iris (mm, outside the pupil).
  struct Landing {
    double x, y, weight;
  };

  /// maxEvents: cornea reflections followed per path (> 0); paths whose weight falls below 1e-9 end early.
  IrisChamberTransport(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid, int maxEvents = 64);
  /// The same from each ring's RingLandings, computed by the caller (in parallel, say): ringLandings[r] for ring r.
  IrisChamberTransport(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid,
                       const std::vector<std::vector<Landing>>& ringLandings);
  /// The landings of the paths from the first node of `ring` (what the constructor stores for it).
  static std::vector<Landing> RingLandings(const AnteriorChamber<double>& chamber, const IrisPolarGrid& grid, int ring,
                                           int maxEvents = 64);

  const IrisPolarGrid& Grid() const { return grid_; }
  int Nodes() const { return grid_.rings * grid_.sectors; }
  /// Node i = ring * sectors + sector, on the iris plane (mm).
  Vec3d Node(int i) const { return NodeOf(grid_, rMin_, rMax_, irisZ_, i); }
  /// The landings of the paths from the first node of `ring`; node (ring, s)'s are these turned by s sectors.
  const Landing* RingLandingsBegin(int ring) const { return landings_.data() + offsets_[ring]; }
  const Landing* RingLandingsEnd(int ring) const { return landings_.data() + offsets_[ring + 1]; }
  const std::vector<Landing>& Landings() const { return landings_; }
  /// The angle between neighbouring sectors, radians.
  double SectorAngle() const { return 2 * paper::kPi / grid_.sectors; }
  /// The fraction of a node's cosine-weighted light that the cornea sends back onto the iris, averaged over nodes.
  double MeanReturn() const;

  double InnerRadius() const { return rMin_; }
  double OuterRadius() const { return rMax_; }
  double IrisZ() const { return irisZ_; }

 private:
  static IrisPolarGrid Valid(IrisPolarGrid grid);
  static Vec3d NodeOf(const IrisPolarGrid& grid, double rMin, double rMax, double irisZ, int i);

  IrisPolarGrid grid_;
  double rMin_, rMax_, irisZ_;
  std::vector<Landing> landings_;
  std::vector<std::size_t> offsets_;  ///< rings + 1
};

/// Runs body(i) for every i in [0, count), in any order and possibly on several threads at once: the caller's thread
/// pool (eyelib has none). Empty: one after another on this thread.
using ParallelFor = FunctionRef<void(int count, FunctionRef<void(int)> body)>;

/// RGB chamber irradiance on an IrisChamberTransport's grid, with the first-order irradiance it came from.
class IrisChamberCache {
 public:
  IrisChamberCache() = default;
  /// direct: first-order irradiance at each node (Nodes() values, >= 0, finite; others count as 0);
  /// albedo: the iris albedo of each node's cell, its mean over the cell (Nodes() values, in [0, 1]): a chamber path
  /// landing between nodes sees the albedo and irradiance interpolated together. The fixed point is iterated at most
  /// maxBounces times (>= 1), stopping once a bounce adds less than `tolerance` of the total (each bounce scales by
  /// albedo x MeanReturn, about 0.1-0.3, so what is left is a fraction of that). Its rings are computed through
  /// `parallelFor`, each ring's sum in a fixed order: the result does not depend on the threads.
  IrisChamberCache(const IrisChamberTransport& transport, const std::vector<Vec3d>& direct,
                   const std::vector<Vec3d>& albedo, ParallelFor parallelFor = {}, int maxBounces = 16,
                   double tolerance = 1e-5);

  /// What the cache predicts a Lambertian iris point at x sends into the chamber, over albedo / pi: the first-order
  /// plus the chamber irradiance there.
  Vec3d Irradiance(const Vec3d& x) const { return Direct(x) + Chamber(x); }
  /// Chamber irradiance at iris point x (mm; bilinear in radius and azimuth, clamped at the first and last ring).
  Vec3d Chamber(const Vec3d& x) const { return Interpolate(chamber_, x); }
  /// The first-order irradiance the cache was built from, interpolated the same way.
  Vec3d Direct(const Vec3d& x) const { return Interpolate(direct_, x); }
  const std::vector<Vec3d>& ChamberAtNodes() const { return chamber_; }

  int Bounces() const { return bounces_; }
  bool Empty() const { return chamber_.empty(); }

 private:
  /// Bilinear interpolation at a point: its lower ring and sector, and its fractions towards the next ones.
  struct Stencil {
    int ring, sector;
    float fr, fs;
  };
  Stencil StencilAt(const Vec3d& x) const;
  Vec3d Interpolate(const std::vector<Vec3d>& values, const Vec3d& x) const;

  IrisPolarGrid grid_;
  double rMin_ = 0, rMax_ = 0;
  std::vector<Vec3d> direct_, chamber_;

  int bounces_ = 0;
};

}  // namespace eyelib
