// bench_mnee: what manifold next event estimation (MNEE) through the analytic cornea costs, and what
// it buys over plain path tracing, for the irradiance that a small light brings to the iris.
//
// Three measurements, each printed as markdown (and optionally written as CSV):
//  1. Solve cost. Median ns per FindRefractionPaths call, and the mean and max Newton iterations per
//     solve, for the single straight-line seed and for all solutions (straight seed + polar grid).
//     Both cornea models; a point light 100 mm away, 30 and 75 degrees off the gaze axis; iris points
//     on a grid.
//  2. Speed versus error. The iris irradiance map (IrisGrid 16 x 16 over half-width 7.54 mm, cells
//     wholly on the iris) from a sphere light (radius 5 mm, centre 100 mm away, 30 or 75 degrees off
//     axis in the xz-plane). Reference: LightTraceIris with many rays. Estimators, each at 1, 2, 4, ...
//     samples per cell (jittered positions within the cell): MNEE single-seed, MNEE all-solutions, and
//     plain path tracing (cosine-sample a direction at the iris point, refract out of the cornea, see
//     whether the ray hits the light). Per estimator and sample count: single-thread wall time, the
//     relative RMSE against the reference over cells with E_ref > 10 % of the maximum, and the mean
//     relative bias. Then the time each method needs to reach 1, 2 and 5 % relative RMSE, and the
//     path-tracing / MNEE time ratio at equal error.
//  3. Energy a single-solution solver misses. Point light 100 mm away at 0 ... 85 degrees: total flux
//     onto the iris annulus from MNEE (single seed, all solutions; midpoint rule in polar coordinates)
//     and from the light-tracing reference.
//
// Units: mm, W; the canonical eye frame (apex at the origin, gaze +z, iris plane z = -3.735). Lights
// have unit power (intensity 1 W/sr, radiance 1 W/(mm^2 sr)): only relative numbers are reported.
// All randomness is eyelib::UniformAt (counter-based), so every run is bit-reproducible; timings are
// single-threaded, std::chrono::steady_clock.
//
// Usage: bench_mnee [--quick] [--csv PREFIX] [--ref-rays N] [--reps K]
#include "bench_util.h"
#include "eyelib/anterior_chamber.h"
#include "eyelib/eye_light.h"
#include "eyelib/iris_light_tracer.h"
#include "eyelib/mnee.h"
#include "eyelib/optics.h"
#include "eyelib/random.h"
#include "eyelib/vec.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

using bench::Median;

using eyelib::AnteriorChamber;
using eyelib::ChamberParams;
using eyelib::CorneaModel;
using eyelib::EyeLight;
using eyelib::IrisGrid;
using eyelib::IrradianceMap;
using eyelib::LightEnd;
using eyelib::LightShape;
using eyelib::MneeOptions;
using eyelib::SeedStrategy;
using eyelib::UniformAt;
using Vec3d = eyelib::Vec3<double>;
using Chamber = AnteriorChamber<double>;
using Clock = std::chrono::steady_clock;

constexpr double kPi = eyelib::paper::kPi;
constexpr double kLightDistance = 100;       // mm, from the apex to the light (centre)
constexpr double kSphereRadius = 5;          // mm
constexpr std::uint64_t kSeed = 0x6d6e6565;  // "mnee"

// ------------------------------------------------------------------------------------- options

struct Options {
  bool quick = false;
  std::string csvPrefix;
  std::int64_t refRays = 40'000'000;       ///< light-tracing rays for the section-2 reference
  std::int64_t fluxRefRays = 10'000'000;   ///< light-tracing rays per angle in section 3
  int reps = 5;                            ///< timed passes in section 1 (median reported)
  int solveGrid = 24;                      ///< section 1: iris points on a solveGrid^2 grid
  int maxLog2SppSingle = 14;               ///< section 2: MNEE single-seed at 1 ... 2^this samples per cell
  int maxLog2SppAll = 12;                  ///< section 2: MNEE all-solutions at 1 ... 2^this samples per cell
  int maxLog2SppPt = 18;                   ///< section 2: path tracing at 1 ... 2^this samples per cell
  int fluxRadial = 96, fluxAngular = 192;  ///< section 3: polar midpoint grid over the iris annulus
};

[[noreturn]] void Usage(const char* argv0, int exitCode) {
  std::fprintf(exitCode ? stderr : stdout,
               "usage: %s [--quick] [--csv PREFIX] [--ref-rays N] [--reps K]\n"
               "  --quick       small sizes, a smoke run of a few seconds\n"
               "  --csv PREFIX  also write PREFIX_solve.csv, PREFIX_convergence.csv, PREFIX_time_to_error.csv\n"
               "                and PREFIX_flux.csv\n"
               "  --ref-rays N  light-tracing rays for the speed-versus-error reference (default 4e7)\n"
               "  --reps K      timed passes per solve-cost row, the median is reported (default 5)\n",
               argv0);
  std::exit(exitCode);
}

Options ParseOptions(int argc, char** argv) {
  Options opt;
  std::optional<long long> refRays;
  std::optional<int> reps;
  bench::ParseArgs(argc, argv, Usage, [&](const std::string& arg, const auto& value) {
    if (arg == "--quick")
      opt.quick = true;
    else if (arg == "--csv")
      opt.csvPrefix = value();
    else if (arg == "--ref-rays")
      refRays = std::llround(std::stod(value()));
    else if (arg == "--reps")
      reps = std::stoi(value());
    else
      return false;
    return true;
  });
  if (opt.quick) {
    opt.refRays = 2'000'000;
    opt.fluxRefRays = 1'000'000;
    opt.reps = 2;
    opt.solveGrid = 12;
    opt.maxLog2SppSingle = 8;
    opt.maxLog2SppAll = 5;
    opt.maxLog2SppPt = 12;
    opt.fluxRadial = 16;
    opt.fluxAngular = 32;
  }
  if (refRays) opt.refRays = *refRays;
  if (reps) opt.reps = *reps;
  if (opt.refRays < 1 || opt.reps < 1) Usage(argv[0], 2);
  return opt;
}

// ---------------------------------------------------------------------------------- utilities

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string Join(const std::vector<std::string>& cells, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < cells.size(); ++i) out += (i ? separator : "") + cells[i];
  return out;
}

/// A markdown table; `numeric` columns are right-aligned.
struct Table {
  std::vector<std::string> header;
  std::vector<bool> numeric;
  std::vector<std::vector<std::string>> rows;

  void Print() const {
    std::printf("| %s |\n|", Join(header, " | ").c_str());
    for (std::size_t i = 0; i < header.size(); ++i) std::printf("%s", numeric[i] ? "--:|" : "---|");
    std::printf("\n");
    for (const auto& r : rows) std::printf("| %s |\n", Join(r, " | ").c_str());
    std::printf("\n");
  }
};

/// Writes a CSV; an empty path writes nothing. Exits on an I/O error.
void WriteCsv(const std::string& path, const std::vector<std::string>& header,
              const std::vector<std::vector<std::string>>& rows) {
  if (path.empty()) return;
  std::ofstream out(path);
  out << Join(header, ",") << '\n';
  for (const auto& r : rows) out << Join(r, ",") << '\n';
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::fprintf(stderr, "wrote %s\n", path.c_str());
}

std::string CsvPath(const Options& opt, const char* name) {
  return opt.csvPrefix.empty() ? std::string() : opt.csvPrefix + "_" + name + ".csv";
}

const char* ModelName(CorneaModel model) { return eyelib::ToString(model); }

/// A point (or sphere centre) `distance` mm from the apex, `degrees` off the gaze axis in the xz-plane.
Vec3d OffAxis(double degrees, double distance) {
  const double a = degrees * kPi / 180;
  return {distance * std::sin(a), 0, distance * std::cos(a)};
}

EyeLight PointLight(double degrees) {
  EyeLight light;
  light.shape = LightShape::Point;
  light.position = OffAxis(degrees, kLightDistance);
  light.power = 1;  // W/sr
  return light;
}

EyeLight SphereLight(double degrees) {
  EyeLight light;
  light.shape = LightShape::Sphere;
  light.position = OffAxis(degrees, kLightDistance);
  light.radius = kSphereRadius;
  light.power = 1;  // W/(mm^2 sr)
  return light;
}

SeedStrategy Strategy(bool allSolutions) {
  SeedStrategy s;
  s.allSolutions = allSolutions;
  return s;
}

const char* StrategyName(bool allSolutions) { return allSolutions ? "MNEE all-solutions" : "MNEE single-seed"; }

// ------------------------------------------------------------------- the path-tracing baseline

/// First t > 0 where the ray o + t d (d unit) meets the sphere (c, r), if any.
bool RayHitsSphere(const Vec3d& o, const Vec3d& d, const Vec3d& c, double r) {
  const Vec3d oc = o - c;
  const double b = glm::dot(oc, d);
  const double disc = b * b - (glm::dot(oc, oc) - r * r);
  if (disc < 0) return false;
  const double s = std::sqrt(disc);
  return -b + s > 0;  // the far root is ahead (the origin is outside the sphere, so both are)
}

/// The exit of a ray that leaves iris point x along unit `dir` (inside the chamber) through the
/// anterior surface: the refracted direction outside and the Fresnel transmittance.
struct Exit {
  Vec3d point, dir;
  double transmittance = 0;
};

/// pbrt conventions (optics.h): Refract takes wi pointing away from the surface on the side the normal
/// points into and eta = n_t / n_i. Inside, wi = -dir lies on the side of -N (N is the outward normal),
/// and light would go into air (n = 1) from the cornea (n = ior): eta = 1 / ior. The transmittance is
/// evaluated from the outside, as the light tracer does: cos = dot(wt, N) > 0 with eta = ior.
std::optional<Exit> ExitCornea(const Chamber& chamber, const Vec3d& x, const Vec3d& dir) {
  const auto hit = chamber.Surface().Intersect({x, dir});
  if (!hit || hit->fromOutside) return std::nullopt;
  const double ior = chamber.CorneaIor();
  Exit exit;
  exit.point = hit->point;
  if (!eyelib::Refract(-dir, -hit->normal, 1 / ior, &exit.dir)) return std::nullopt;  // total internal reflection
  exit.transmittance = 1 - eyelib::FresnelDielectric(glm::dot(exit.dir, hit->normal), ior);
  return exit;
}

/// One path-tracing (BSDF-sampling) estimate of the irradiance at iris point x from a sphere light of
/// radiance L: a cosine-weighted direction about the iris normal +z, the exit through the cornea, and
/// the light if the exit ray hits it. E = integral of L_in cos dw over the hemisphere; with pdf
/// cos / pi the estimate is pi L_in. Radiance entering a denser medium is compressed into a smaller
/// solid angle: L_in = (n_in / n_out)^2 T L = ior^2 T L (pbrt's non-symmetric BTDF for radiance).
/// Reflected and totally internally reflected paths are dropped, as in the light-tracing reference.
double PathTraceSample(const Chamber& chamber, const Vec3d& x, const EyeLight& sphere, double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2 * kPi * u2;
  const Vec3d dir(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1)));
  const std::optional<Exit> exit = ExitCornea(chamber, x, dir);
  if (!exit || !RayHitsSphere(exit->point, exit->dir, sphere.position, sphere.radius)) return 0;
  const double ior = chamber.CorneaIor();
  return kPi * ior * ior * exit->transmittance * sphere.power;
}

/// Checks ExitCornea against Snell's law, reversibility and Fresnel reciprocity on many random rays;
/// aborts on failure. Returns the number of rays checked.
int SelfTestRefraction() {
  int checked = 0;
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    const Chamber chamber(ChamberParams{model});
    const double ior = chamber.CorneaIor();
    for (int k = 0; k < 20000; ++k) {
      const double rho =
          chamber.PupilRadius() + (chamber.IrisRadius() - chamber.PupilRadius()) * UniformAt(kSeed, 100, k);
      const double psi = 2 * kPi * UniformAt(kSeed, 101, k);
      const Vec3d x(rho * std::cos(psi), rho * std::sin(psi), chamber.IrisZ());
      const double u1 = UniformAt(kSeed, 102, k), phi = 2 * kPi * UniformAt(kSeed, 103, k);
      const Vec3d dir(std::sqrt(u1) * std::cos(phi), std::sqrt(u1) * std::sin(phi), std::sqrt(1 - u1));
      const auto hit = chamber.Surface().Intersect({x, dir});
      if (!hit) {
        // The ellipsoid-cone rim plane (z = -3.7341) is 1 um above the iris plane, and that iris reaches
        // the rim: rays from its outer edge can leave under the rim (into the sclera, which the path
        // tracer counts as 0). Any other miss is a failure.
        const double rim = chamber.Surface().RimRadius();
        const double b = x.x * dir.x + x.y * dir.y, a = dir.x * dir.x + dir.y * dir.y;
        const double tRim = (-b + std::sqrt(b * b - a * (x.x * x.x + x.y * x.y - rim * rim))) / a;
        if (!(x.z + tRim * dir.z < chamber.Surface().Sag(rim))) {
          std::fprintf(stderr, "self-test: a ray from the iris (rho %.6f, dir.z %.3g) missed the cornea\n",
                       std::hypot(x.x, x.y), dir.z);
          std::abort();
        }
        continue;
      }
      const Vec3d n = hit->normal;
      const double sinIn = glm::length(glm::cross(dir, n));
      const std::optional<Exit> exit = ExitCornea(chamber, x, dir);
      if (ior * sinIn >= 1) {  // beyond the critical angle
        if (exit) {
          std::fprintf(stderr, "self-test: refraction past the critical angle\n");
          std::abort();
        }
        continue;
      }
      ++checked;
      const double sinOut = glm::length(glm::cross(exit->dir, n));
      const double coplanar = glm::dot(glm::cross(dir, n), exit->dir);
      // The reverse path: light arriving from outside along -exit.dir (wi = exit.dir, on N's side,
      // eta = ior) must continue inside along -dir.
      Vec3d back;
      const bool backOk = eyelib::Refract(exit->dir, n, ior, &back);
      const double tInside = 1 - eyelib::FresnelDielectric(glm::dot(-dir, n), ior);
      const bool ok = std::abs(glm::length(exit->dir) - 1) < 1e-12 && glm::dot(exit->dir, n) > 0 &&
                      std::abs(ior * sinIn - sinOut) < 1e-9 && std::abs(coplanar) < 1e-9 && backOk &&
                      glm::length(back + dir) < 1e-9 && std::abs(tInside - exit->transmittance) < 1e-12 &&
                      exit->transmittance > 0 && exit->transmittance <= 1;
      if (!ok) {
        std::fprintf(stderr,
                     "self-test failed (%s, ray %d): ior sin_in %.12g sin_out %.12g coplanar %.3g "
                     "|back + dir| %.3g T %.12g T(inside) %.12g\n",
                     ModelName(model), k, ior * sinIn, sinOut, coplanar, glm::length(back + dir), exit->transmittance,
                     tInside);
        std::abort();
      }
    }
  }
  return checked;
}

// -------------------------------------------------------------------------- 1. solve cost

/// Iris points at the centres of an n x n grid over the iris disk, pupil < r < iris radius.
std::vector<Vec3d> IrisPoints(const Chamber& chamber, int n) {
  std::vector<Vec3d> points;
  const double half = chamber.IrisRadius(), step = 2 * half / n;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec3d x(-half + (i + 0.5) * step, -half + (j + 0.5) * step, chamber.IrisZ());
      const double r = std::hypot(x.x, x.y);
      if (r > chamber.PupilRadius() && r < chamber.IrisRadius()) points.push_back(x);
    }
  return points;
}

struct SolveRow {
  std::string model, method;
  double degrees = 0;
  std::size_t points = 0;
  double nsPerCall = 0, solvesPerCall = 0, nsPerSolve = 0, solutionsPerCall = 0, failureRate = 0;
  double itMeanSolutions = 0, itMeanAll = 0;
  int itMax = 0;
  int callsWithMultiple = 0;
};

SolveRow BenchSolve(CorneaModel model, double degrees, bool allSolutions, const Options& opt) {
  const Chamber chamber(ChamberParams{model});
  const std::vector<Vec3d> points = IrisPoints(chamber, opt.solveGrid);
  LightEnd light;
  light.position = OffAxis(degrees, kLightDistance);
  const SeedStrategy seeds = Strategy(allSolutions);
  const MneeOptions mnee;

  SolveRow row;
  row.model = ModelName(model);
  row.method = StrategyName(allSolutions);
  row.degrees = degrees;
  row.points = points.size();

  // Untimed pass: counts and Newton iterations (per solve, and per distinct solution found).
  long solves = 0, failures = 0, solutions = 0, itSolutions = 0, itAll = 0;
  for (const Vec3d& x : points) {
    const eyelib::MneeResult r = eyelib::FindRefractionPaths(chamber, x, light, seeds, mnee);
    solves += r.solves;
    failures += r.failures;
    solutions += long(r.solutions.size());
    row.callsWithMultiple += r.solutions.size() > 1;
    itAll += r.iterations;
    row.itMax = std::max(row.itMax, r.maxIterations);
    for (const eyelib::MneeSolution& sol : r.solutions) itSolutions += sol.iterations;
  }
  const double n = double(points.size());
  row.solvesPerCall = solves / n;
  row.solutionsPerCall = solutions / n;
  row.failureRate = solves ? double(failures) / solves : 0;
  row.itMeanSolutions = solutions ? double(itSolutions) / solutions : 0;
  row.itMeanAll = solves ? double(itAll) / double(solves) : 0;

  // Timed passes (each after a warm-up pass); the median pass over all points.
  double sink = 0;
  std::vector<double> passNs;
  for (int rep = 0; rep <= opt.reps; ++rep) {
    const auto t0 = Clock::now();
    for (const Vec3d& x : points) sink += eyelib::FindRefractionPaths(chamber, x, light, seeds, mnee).transfer;
    const double ns = Seconds(Clock::now() - t0) * 1e9;
    if (rep > 0) passNs.push_back(ns);
  }
  if (!std::isfinite(sink)) std::fprintf(stderr, "warning: non-finite transfer sum in the solve benchmark\n");
  row.nsPerCall = Median(passNs) / n;
  row.nsPerSolve = row.nsPerCall / row.solvesPerCall;
  return row;
}

void SectionSolveCost(const Options& opt) {
  std::printf("## 1. Solve cost\n\n");
  const Chamber probe;
  const MneeOptions mnee;
  const SeedStrategy all = Strategy(true);
  std::printf(
      "Point light %.0f mm from the apex; iris points at the centres of a %d x %d grid over the iris disk\n"
      "(pupil radius %.2f mm < r < iris radius %.3f mm, ellipsoid-cone). One FindRefractionPaths call per\n"
      "point, default MneeOptions (tolerance %.0e, at most %d iterations, max step %.2g mm) and\n"
      "SeedStrategy (single: the straight-line seed; all solutions: it + %d seeds along the light's\n"
      "azimuth + %s). ns/call: median of %d timed passes over all points (each after\n"
      "a warm-up pass), one thread. Iterations: Newton iterations per solve (all) and per distinct\n"
      "solution found (solutions), from FindRefractionPaths' counts. Failed solves include points no path reaches.\n\n",
      kLightDistance, opt.solveGrid, opt.solveGrid, probe.PupilRadius(), probe.IrisRadius(), mnee.tolerance,
      mnee.maxIterations, mnee.maxStep, all.meridianSeeds,
      all.rings > 0 ? (std::to_string(all.rings) + " x " + std::to_string(all.segments) + " polar grid seeds").c_str()
                    : "no polar grid",
      opt.reps);
  Table table{{"model", "light (deg)", "method", "points", "ns/call", "solves/call", "ns/solve", "solutions/call",
               "points with >1 solution", "failed solves", "iterations mean (solutions)", "iterations mean (all)",
               "iterations max"},
              {false, true, false, true, true, true, true, true, true, true, true, true, true},
              {}};
  std::vector<std::vector<std::string>> csv;
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid})
    for (double degrees : {30.0, 75.0})
      for (bool all : {false, true}) {
        std::fprintf(stderr, "[1] solve cost: %s, %.0f deg, %s\n", ModelName(model), degrees, StrategyName(all));
        const SolveRow r = BenchSolve(model, degrees, all, opt);
        table.rows.push_back({r.model, Format("%.0f", r.degrees), r.method, std::to_string(r.points),
                              Format("%.0f", r.nsPerCall), Format("%.1f", r.solvesPerCall),
                              Format("%.0f", r.nsPerSolve), Format("%.3f", r.solutionsPerCall),
                              std::to_string(r.callsWithMultiple), Format("%.1f %%", 100 * r.failureRate),
                              Format("%.2f", r.itMeanSolutions), Format("%.2f", r.itMeanAll), std::to_string(r.itMax)});
        csv.push_back({r.model, Format("%.0f", r.degrees), r.method, std::to_string(r.points),
                       Format("%.6g", r.nsPerCall), Format("%.6g", r.solvesPerCall), Format("%.6g", r.nsPerSolve),
                       Format("%.6g", r.solutionsPerCall), std::to_string(r.callsWithMultiple),
                       Format("%.6g", r.failureRate), Format("%.6g", r.itMeanSolutions), Format("%.6g", r.itMeanAll),
                       std::to_string(r.itMax)});
      }
  table.Print();
  WriteCsv(CsvPath(opt, "solve"),
           {"model", "light_deg", "method", "points", "ns_per_call", "solves_per_call", "ns_per_solve",
            "solutions_per_call", "points_multiple", "failure_rate", "it_mean_converged", "it_mean_all", "it_max"},
           csv);
}

// ------------------------------------------------------------------------------ the reference

/// LightTraceIris split over two threads (seeds `seed` and `seed + 1`, half the rays each), merged:
/// the mean of the two maps, with the standard errors combined. Only the reference is threaded; every
/// timed estimator runs on one thread, with nothing else running.
IrradianceMap LightTraceIrisTwoThreads(const Chamber& chamber, const EyeLight& light, const IrisGrid& grid,
                                       std::int64_t rays, std::uint64_t seed) {
  IrradianceMap second;
  std::thread worker([&] { second = eyelib::LightTraceIris(chamber, light, grid, rays - rays / 2, seed + 1); });
  IrradianceMap map = eyelib::LightTraceIris(chamber, light, grid, rays / 2, seed);
  worker.join();
  const double w1 = double(rays / 2) / double(rays), w2 = 1 - w1;
  for (std::size_t c = 0; c < map.irradiance.size(); ++c) {
    map.irradiance[c] = w1 * map.irradiance[c] + w2 * second.irradiance[c];
    map.stdError[c] = std::hypot(w1 * map.stdError[c], w2 * second.stdError[c]);
  }
  map.rays = rays;
  return map;
}

// -------------------------------------------------------------------- 2. speed versus error

enum class Method { MneeSingle, MneeAll, PathTrace };
const Method kMethods[] = {Method::MneeSingle, Method::MneeAll, Method::PathTrace};

const char* MethodName(Method m) {
  switch (m) {
    case Method::MneeSingle: return "MNEE single-seed";
    case Method::MneeAll: return "MNEE all-solutions";
    case Method::PathTrace: return "path tracing";
  }
  return "?";
}

struct Cell {
  int i, j;
  double eRef, sigmaRef;  // reference irradiance and its standard error
  bool scored;            // E_ref > 10 % of the maximum over the cells on the iris
};

struct Level {
  Method method;
  long spp;
  double seconds;
  double relRmse;        ///< over the scored cells, against the reference
  double relRmseExcess;  ///< sqrt(max(0, relMSE - mean relative reference variance))
  double bias;           ///< mean of (E - E_ref) / E_ref over the scored cells
  double maxAbsRel;      ///< worst |E - E_ref| / E_ref
  bool finite;           ///< every estimate was finite
};

/// The cell-averaged irradiance of every cell in `cells` with `spp` jittered samples per cell (a
/// kx x ky stratification of the cell, kx * ky = spp). Single thread.
std::vector<double> EstimateMap(const Chamber& chamber, const IrisGrid& grid, const std::vector<Cell>& cells,
                                const EyeLight& light, Method method, long spp, std::uint64_t seed, bool* finite) {
  int log2 = 0;
  while ((1L << log2) < spp) ++log2;
  const long kx = 1L << ((log2 + 1) / 2), ky = spp / kx;
  const double size = grid.CellSize();
  const SeedStrategy seeds = Strategy(method == Method::MneeAll);
  const MneeOptions mnee;
  std::vector<double> out(cells.size());
  *finite = true;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const eyelib::Vec2<double> centre = grid.CellCenter(cells[c].i, cells[c].j);
    const double x0 = centre.x - size / 2, y0 = centre.y - size / 2;
    const std::uint64_t stream = 8 * std::uint64_t(cells[c].j * grid.cells + cells[c].i);
    double sum = 0;
    for (long s = 0; s < spp; ++s) {
      const double jx = (double(s % kx) + UniformAt(seed, stream + 0, s)) / double(kx);
      const double jy = (double(s / kx) + UniformAt(seed, stream + 1, s)) / double(ky);
      const Vec3d x(x0 + jx * size, y0 + jy * size, chamber.IrisZ());
      const double u1 = UniformAt(seed, stream + 2, s), u2 = UniformAt(seed, stream + 3, s);
      const double e = method == Method::PathTrace
                           ? PathTraceSample(chamber, x, light, u1, u2)
                           : eyelib::EstimateIrisIrradiance(chamber, x, light, u1, u2, seeds, mnee).irradiance;
      if (!std::isfinite(e)) *finite = false;
      sum += e;
    }
    out[c] = sum / double(spp);
  }
  return out;
}

struct Config {
  CorneaModel model;
  double degrees;
  std::string Name() const {
    return std::string(ModelName(model)) + ", sphere light at " + Format("%.0f", degrees) + " deg";
  }
};

struct ReferenceStats {
  std::size_t onIris = 0, scored = 0;
  double medianRelSigma = 0, rmsRelSigma = 0, maxE = 0, seconds = 0;
};

/// Time (s) to reach relative RMSE `target`: log-log interpolation between the first level at or
/// below the target and the one before; if never reached, 1/sqrt(time) extrapolation from the last
/// level (flagged), unless the bias alone exceeds half the target.
struct TimeToError {
  double seconds = NAN;
  bool extrapolated = false;
  std::string note;  ///< why there is no number
};

TimeToError TimeTo(const std::vector<Level>& levels, double target, double floor, std::size_t cells) {
  TimeToError out;
  if (target < 2 * floor) {
    out.note = "below ref. noise";
    return out;
  }
  auto err = [](const Level& l) { return std::max(l.relRmseExcess, 1e-12); };
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (err(levels[k]) > target) continue;
    if (k == 0) {  // already at the first level: scale back with the 1/sqrt(time) law
      out.seconds = levels[0].seconds * std::pow(err(levels[0]) / target, 2);
      out.extrapolated = true;
      return out;
    }
    const Level &a = levels[k - 1], &b = levels[k];
    const double f = std::log(err(a) / target) / std::log(err(a) / err(b));
    out.seconds = std::exp(std::log(a.seconds) + f * (std::log(b.seconds) - std::log(a.seconds)));
    return out;
  }
  const Level& last = levels.back();
  // Refuse to extrapolate when the bias is significant (3 standard errors) and above half the target.
  if (std::abs(last.bias) > target / 2 && std::abs(last.bias) > 3 * err(last) / std::sqrt(double(cells))) {
    out.note = "not reached (bias)";
    return out;
  }
  out.seconds = last.seconds * std::pow(err(last) / target, 2);
  out.extrapolated = true;
  return out;
}

std::string FormatTime(const TimeToError& t) {
  if (!std::isfinite(t.seconds)) return t.note;
  return Format(t.seconds < 0.01 ? "%.2g" : "%.3g", t.seconds) + (t.extrapolated ? " *" : "");
}

std::string FormatRatio(const TimeToError& pt, const TimeToError& mnee) {
  if (!std::isfinite(pt.seconds) || !std::isfinite(mnee.seconds)) return "-";
  return Format("%.3g", pt.seconds / mnee.seconds) + (pt.extrapolated || mnee.extrapolated ? " *" : "");
}

/// Efficiency 1 / (relMSE x time) averaged over the levels whose RMSE is above twice the reference
/// floor and which take at least 20 ms (so timer noise does not dominate); NaN if none.
double Efficiency(const std::vector<Level>& levels, double floor) {
  double sum = 0;
  int n = 0;
  for (const Level& l : levels) {
    if (l.relRmse < 2 * floor || l.seconds < 0.02) continue;
    sum += 1 / (l.relRmseExcess * l.relRmseExcess * l.seconds);
    ++n;
  }
  return n ? sum / n : NAN;
}

void SectionSpeedVersusError(const Options& opt) {
  std::printf("## 2. Speed versus error: iris irradiance from a sphere light\n\n");
  const IrisGrid grid{16, 7.54};
  std::printf(
      "Sphere light, radius %.0f mm, centre %.0f mm from the apex, in the xz-plane; unit radiance. IrisGrid %d x %d\n"
      "over half-width %.2f mm (cells of %.4f mm); cells wholly on the iris (CellOnIris) are estimated, the\n"
      "error is scored over those with E_ref > 10 %% of the maximum. Reference: LightTraceIris, %lld rays\n"
      "(two threads, seeds 1 and 2, merged; the only multi-threaded part).\n"
      "Each estimator runs independently (fresh random numbers) at each sample count, with\n"
      "jittered (stratified) positions in the cell; the light point (MNEE) or the direction (path tracing)\n"
      "is sampled independently. Time: single thread, the whole map. rel RMSE = sqrt(mean((E - E_ref)^2 /\n"
      "E_ref^2)); it includes the reference's own noise, so rel RMSE excess subtracts the reference's mean\n"
      "relative variance. bias = mean((E - E_ref) / E_ref) +- its standard error rel RMSE / sqrt(cells).\n"
      "The tables list every other sample count (powers of 4, and the last); the CSV has all.\n\n",
      kSphereRadius, kLightDistance, grid.cells, grid.cells, grid.halfWidth, grid.CellSize(),
      static_cast<long long>(opt.refRays));

  std::vector<std::vector<std::string>> convergenceCsv, timeCsv;
  Table summary{{"model", "light (deg)", "target rel RMSE", "MNEE single-seed (s)", "MNEE all-solutions (s)",
                 "path tracing (s)", "PT / MNEE single", "PT / MNEE all"},
                {false, true, true, true, true, true, true, true},
                {}};
  Table efficiency{{"model", "light (deg)", "ref. noise: median rel sigma", "ref. noise: rms rel sigma",
                    "cells scored / on iris", "MNEE single 1/(MSE t)", "MNEE all 1/(MSE t)", "PT 1/(MSE t)",
                    "PT / MNEE single (equal error)", "PT / MNEE all (equal error)"},
                   {false, true, true, true, true, true, true, true, true, true},
                   {}};
  const double targets[] = {0.01, 0.02, 0.05};

  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid})
    for (double degrees : {30.0, 75.0}) {
      const Config config{model, degrees};
      const Chamber chamber(ChamberParams{model});
      const EyeLight light = SphereLight(degrees);

      std::fprintf(stderr, "[2] %s: reference, %lld rays ...\n", config.Name().c_str(),
                   static_cast<long long>(opt.refRays));
      ReferenceStats ref;
      const auto t0 = Clock::now();
      const IrradianceMap map = LightTraceIrisTwoThreads(chamber, light, grid, opt.refRays, 1);
      ref.seconds = Seconds(Clock::now() - t0);
      std::vector<Cell> cells;
      for (int j = 0; j < grid.cells; ++j)
        for (int i = 0; i < grid.cells; ++i)
          if (eyelib::CellOnIris(chamber, grid, i, j)) {
            cells.push_back({i, j, map.At(i, j), map.ErrorAt(i, j), false});
            ref.maxE = std::max(ref.maxE, map.At(i, j));
          }
      std::vector<double> relSigma;
      double relVar = 0;
      for (Cell& c : cells) {
        c.scored = c.eRef > 0.1 * ref.maxE;
        if (!c.scored) continue;
        relSigma.push_back(c.sigmaRef / c.eRef);
        relVar += std::pow(c.sigmaRef / c.eRef, 2);
      }
      ref.onIris = cells.size();
      ref.scored = relSigma.size();
      ref.medianRelSigma = Median(relSigma);
      relVar /= double(ref.scored);
      ref.rmsRelSigma = std::sqrt(relVar);

      std::printf("### %s\n\n", config.Name().c_str());
      std::printf(
          "Reference: %.1f s; max E_ref %.4g W/mm^2 (unit radiance); %zu cells on the iris, %zu scored;\n"
          "its noise: median relative std error %.3f %%, rms %.3f %% over the scored cells. A rel RMSE\n"
          "below about %.2f %% is not measurable against this reference.\n\n",
          ref.seconds, ref.maxE, ref.onIris, ref.scored, 100 * ref.medianRelSigma, 100 * ref.rmsRelSigma,
          100 * 2 * ref.rmsRelSigma);

      std::vector<std::vector<Level>> levelsByMethod;
      Table table{{"method", "spp", "time (s)", "rel RMSE", "rel RMSE excess", "bias", "max |rel err|"},
                  {false, true, true, true, true, true, true},
                  {}};
      for (Method method : kMethods) {
        const int maxLog2 = method == Method::PathTrace ? opt.maxLog2SppPt
                            : method == Method::MneeAll ? opt.maxLog2SppAll
                                                        : opt.maxLog2SppSingle;
        std::vector<Level> levels;
        for (int l = 0; l <= maxLog2; ++l) {
          const long spp = 1L << l;
          const std::uint64_t seed =
              eyelib::SplitMix64(kSeed ^ (std::uint64_t(method) << 8) ^ (std::uint64_t(model) << 16) ^
                                 (std::uint64_t(degrees) << 24) ^ (std::uint64_t(l) << 40));
          bool finite = true;
          const auto start = Clock::now();
          const std::vector<double> est = EstimateMap(chamber, grid, cells, light, method, spp, seed, &finite);
          const double seconds = Seconds(Clock::now() - start);
          Level lv{method, spp, seconds, 0, 0, 0, 0, finite};
          for (std::size_t c = 0; c < cells.size(); ++c) {
            if (!cells[c].scored) continue;
            const double rel = (est[c] - cells[c].eRef) / cells[c].eRef;
            lv.relRmse += rel * rel;
            lv.bias += rel;
            lv.maxAbsRel = std::max(lv.maxAbsRel, std::abs(rel));
          }
          lv.relRmseExcess = std::sqrt(std::max(0.0, lv.relRmse / double(ref.scored) - relVar));
          lv.relRmse = std::sqrt(lv.relRmse / double(ref.scored));
          lv.bias /= double(ref.scored);
          if (!finite)
            std::fprintf(stderr, "warning: non-finite estimate (%s, %s, spp %ld)\n", config.Name().c_str(),
                         MethodName(method), spp);
          levels.push_back(lv);
          std::fprintf(stderr, "[2]   %-18s spp %7ld  %8.3f s  rel RMSE %.4f  bias %+.4f\n", MethodName(method), spp,
                       seconds, lv.relRmse, lv.bias);
          if (l % 2 == 0 || l == maxLog2)  // the CSV has every level
            table.rows.push_back(
                {MethodName(method), std::to_string(spp), Format("%.3g", seconds), Format("%.4f", lv.relRmse),
                 Format("%.4f", lv.relRmseExcess),
                 Format("%+.4f", lv.bias) + " +- " + Format("%.4f", lv.relRmse / std::sqrt(double(ref.scored))),
                 Format("%.3f", lv.maxAbsRel) + (finite ? "" : " NaN!")});
          convergenceCsv.push_back({ModelName(model), Format("%.0f", degrees), MethodName(method), std::to_string(spp),
                                    Format("%.6g", seconds), Format("%.6g", lv.relRmse),
                                    Format("%.6g", lv.relRmseExcess), Format("%.6g", lv.bias),
                                    Format("%.6g", lv.maxAbsRel), Format("%.6g", ref.rmsRelSigma),
                                    Format("%.6g", ref.medianRelSigma)});
        }
        levelsByMethod.push_back(levels);
      }
      table.Print();

      const double floor = ref.rmsRelSigma;
      for (double target : targets) {
        const TimeToError single = TimeTo(levelsByMethod[0], target, floor, ref.scored);
        const TimeToError all = TimeTo(levelsByMethod[1], target, floor, ref.scored);
        const TimeToError pt = TimeTo(levelsByMethod[2], target, floor, ref.scored);
        summary.rows.push_back({ModelName(model), Format("%.0f", degrees), Format("%.0f %%", 100 * target),
                                FormatTime(single), FormatTime(all), FormatTime(pt), FormatRatio(pt, single),
                                FormatRatio(pt, all)});
        timeCsv.push_back({ModelName(model), Format("%.0f", degrees), Format("%.3g", target),
                           Format("%.6g", single.seconds), Format("%.6g", all.seconds), Format("%.6g", pt.seconds),
                           single.extrapolated ? "1" : "0", all.extrapolated ? "1" : "0", pt.extrapolated ? "1" : "0"});
      }
      const double effSingle = Efficiency(levelsByMethod[0], floor), effAll = Efficiency(levelsByMethod[1], floor),
                   effPt = Efficiency(levelsByMethod[2], floor);
      efficiency.rows.push_back({ModelName(model), Format("%.0f", degrees), Format("%.3f %%", 100 * ref.medianRelSigma),
                                 Format("%.3f %%", 100 * floor),
                                 std::to_string(ref.scored) + " / " + std::to_string(ref.onIris),
                                 Format("%.3g", effSingle), Format("%.3g", effAll), Format("%.3g", effPt),
                                 Format("%.3g", effSingle / effPt), Format("%.3g", effAll / effPt)});
    }

  std::printf("### Time to reach a relative RMSE, and the path-tracing / MNEE time ratio at equal error\n\n");
  std::printf(
      "On rel RMSE excess (the reference's noise subtracted). Interpolated (log-log) between measured\n"
      "sample counts; * = extrapolated from the last (or first) level with RMSE proportional to\n"
      "1/sqrt(time), which holds for an unbiased estimator. \"below ref. noise\": the target is under\n"
      "twice the reference's rms relative noise, not measurable. \"not reached (bias)\": the estimator's\n"
      "bias is significant (3 standard errors) and above half the target.\n\n");
  summary.Print();
  std::printf(
      "Efficiency 1/(relMSE x time) (relMSE with the reference's variance subtracted), averaged over the\n"
      "levels above twice the reference noise that take at least 20 ms. For unbiased estimators the\n"
      "ratio of efficiencies is the ratio of times to any equal error; a biased estimator's efficiency\n"
      "is only meaningful while its noise dominates its bias.\n\n");
  efficiency.Print();
  WriteCsv(CsvPath(opt, "convergence"),
           {"model", "light_deg", "method", "spp", "seconds", "rel_rmse", "rel_rmse_excess", "bias", "max_abs_rel",
            "ref_rms_rel_sigma", "ref_median_rel_sigma"},
           convergenceCsv);
  WriteCsv(CsvPath(opt, "time_to_error"),
           {"model", "light_deg", "target", "mnee_single_s", "mnee_all_s", "pt_s", "mnee_single_extrap",
            "mnee_all_extrap", "pt_extrap"},
           timeCsv);
}

// --------------------------------------------------------------- 3. energy missed by one seed

struct FluxRow {
  std::string model;
  double degrees;
  double single, all, lt, ltSigma;
  double pointsWithMultiple, pointsFoundOnlyByGrid;
  double failuresSingle, failuresAll;
};

void SectionMissedEnergy(const Options& opt) {
  std::printf("## 3. Energy a single-solution solver misses (point light)\n\n");
  std::printf(
      "Point light, 1 W/sr, %.0f mm from the apex at each angle. MNEE flux onto the iris annulus\n"
      "(pupil < r < iris radius) = sum of FindRefractionPaths transfer x area over a %d (radial) x %d\n"
      "(angular) midpoint grid in polar coordinates. Light tracing: LightTraceIris with %lld rays (2 threads) on a\n"
      "64 x 64 grid, summed over all cells (the tracer bins only hits on the iris annulus); +- its standard\n"
      "error. missed = 1 - single / all. \"only extra seeds\": points where the straight-line seed found no\n"
      "solution but the extra all-solutions seeds found one.\n\n",
      kLightDistance, opt.fluxRadial, opt.fluxAngular, static_cast<long long>(opt.fluxRefRays));
  Table table{{"model", "light (deg)", "flux LT (uW)", "flux MNEE all (uW)", "flux MNEE single (uW)",
               "missed by single-seed", "all vs LT", "single vs LT", "points with >1 solution", "only extra seeds",
               "failed solves single", "failed solves all"},
              {false, true, true, true, true, true, true, true, true, true, true, true},
              {}};
  std::vector<std::vector<std::string>> csv;
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    const Chamber chamber(ChamberParams{model});
    const double r0 = chamber.PupilRadius(), r1 = chamber.IrisRadius();
    const double dr = (r1 - r0) / opt.fluxRadial, dphi = 2 * kPi / opt.fluxAngular;
    for (double degrees : {0.0, 30.0, 60.0, 75.0, 85.0}) {
      std::fprintf(stderr, "[3] flux: %s, %.0f deg\n", ModelName(model), degrees);
      const EyeLight light = PointLight(degrees);
      LightEnd end;
      end.position = light.position;
      FluxRow row{ModelName(model), degrees, 0, 0, 0, 0, 0, 0, 0, 0};
      long solvesSingle = 0, solvesAll = 0, failSingle = 0, failAll = 0, points = 0, multiple = 0, onlyGrid = 0;
      for (int a = 0; a < opt.fluxRadial; ++a)
        for (int b = 0; b < opt.fluxAngular; ++b) {
          const double r = r0 + (a + 0.5) * dr, phi = (b + 0.5) * dphi;
          const Vec3d x(r * std::cos(phi), r * std::sin(phi), chamber.IrisZ());
          const double area = r * dr * dphi;
          const eyelib::MneeResult single = eyelib::FindRefractionPaths(chamber, x, end, Strategy(false));
          const eyelib::MneeResult all = eyelib::FindRefractionPaths(chamber, x, end, Strategy(true));
          if (!std::isfinite(single.transfer) || !std::isfinite(all.transfer))
            std::fprintf(stderr, "warning: non-finite transfer at (%.6f, %.6f, %.6f)\n", x.x, x.y, x.z);
          row.single += light.power * single.transfer * area;
          row.all += light.power * all.transfer * area;
          solvesSingle += single.solves, failSingle += single.failures;
          solvesAll += all.solves, failAll += all.failures;
          ++points;
          multiple += all.solutions.size() > 1;
          onlyGrid += single.solutions.empty() && !all.solutions.empty();
        }
      const IrisGrid fine{64, 7.54};
      const IrradianceMap map = LightTraceIrisTwoThreads(chamber, light, fine, opt.fluxRefRays, 7);
      double var = 0;
      const double cellArea = fine.CellSize() * fine.CellSize();
      for (std::size_t c = 0; c < map.irradiance.size(); ++c) {
        row.lt += map.irradiance[c] * cellArea;
        var += std::pow(map.stdError[c] * cellArea, 2);
      }
      row.ltSigma = std::sqrt(var);
      row.pointsWithMultiple = double(multiple) / points;
      row.pointsFoundOnlyByGrid = double(onlyGrid) / points;
      row.failuresSingle = solvesSingle ? double(failSingle) / solvesSingle : 0;
      row.failuresAll = solvesAll ? double(failAll) / solvesAll : 0;
      const double missed = row.all > 0 ? 1 - row.single / row.all : 0;
      auto pct = [](double v) { return Format("%+.2f %%", 100 * v); };
      table.rows.push_back({row.model, Format("%.0f", degrees),
                            Format("%.3f", 1e6 * row.lt) + " +- " + Format("%.3f", 1e6 * row.ltSigma),
                            Format("%.3f", 1e6 * row.all), Format("%.3f", 1e6 * row.single),
                            Format("%.2f %%", 100 * missed), pct(row.all / row.lt - 1), pct(row.single / row.lt - 1),
                            Format("%.1f %%", 100 * row.pointsWithMultiple),
                            Format("%.1f %%", 100 * row.pointsFoundOnlyByGrid),
                            Format("%.1f %%", 100 * row.failuresSingle), Format("%.1f %%", 100 * row.failuresAll)});
      csv.push_back({row.model, Format("%.0f", degrees), Format("%.8g", row.lt), Format("%.8g", row.ltSigma),
                     Format("%.8g", row.all), Format("%.8g", row.single), Format("%.6g", missed),
                     Format("%.6g", row.pointsWithMultiple), Format("%.6g", row.pointsFoundOnlyByGrid),
                     Format("%.6g", row.failuresSingle), Format("%.6g", row.failuresAll)});
    }
  }
  table.Print();
  WriteCsv(CsvPath(opt, "flux"),
           {"model", "light_deg", "flux_lt_w", "flux_lt_sigma_w", "flux_mnee_all_w", "flux_mnee_single_w",
            "missed_fraction", "points_multiple", "points_only_grid", "failure_rate_single", "failure_rate_all"},
           csv);
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = ParseOptions(argc, argv);
  const auto start = Clock::now();
  std::printf("# bench_mnee: MNEE through the analytic cornea vs path tracing, against light tracing\n\n");
  std::printf("Single-threaded timings (std::chrono::steady_clock); this machine has %u hardware threads.%s\n\n",
              std::thread::hardware_concurrency(), opt.quick ? " --quick: small sizes, numbers are a smoke test." : "");
  const int checked = SelfTestRefraction();
  std::printf(
      "Self-test of the path tracer's exit refraction: Snell, coplanarity, reversibility and Fresnel\n"
      "reciprocity hold to 1e-9 on %d random iris-to-cornea rays (both models).\n\n",
      checked);
  SectionSolveCost(opt);
  SectionSpeedVersusError(opt);
  SectionMissedEnergy(opt);
  std::fprintf(stderr, "total %.1f s\n", Seconds(Clock::now() - start));
  return 0;
}
