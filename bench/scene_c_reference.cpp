// scene_c_reference: the reference image of scene C's rect key and textured dome seen through the analytic eye,
// computed without the renderer: eyelib's surface and optics only (the anterior surface, the chamber, Fresnel,
// Snell), deterministic quadrature instead of Monte Carlo, everything in double precision.
//
// 1. The irradiance the rect and the dome bring the iris plane (W/mm^2 per unit radiance), at the nodes of a square
//    grid over the iris disk: at each node, the cosine-weighted hemisphere towards the cornea (the concentric map of
//    the unit square) by the midpoint rule on a base grid of cells, every cell whose value differs from a
//    neighbour's by more than a tolerance refined into sub-cells (the rect's edges, the dome's window). Each
//    direction is followed through the cornea with its Fresnel weights, both branches: what leaves the eye sees the
//    dome and, on its front face, the rect; what the inside of the cornea reflects goes on (total internal reflection
//    included), up to eight events.
// 2. The chamber's light: a grid of directions' returns to the iris plane (refined where the returned weight
//    changes fast: the critical angle), on a coarser grid, iterated to a fixed point (the iris radiance albedo E / pi;
//    the pupil absorbs).
// 3. The camera image: per pixel an n x n grid of sub-pixel rays (the box filter), each refracted and reflected at
//    the cornea with its Fresnel weights, the reflection seeing the lights, the refraction the iris (its radiance
//    from the two grids, bilinear) or, past internal reflections, the lights.
//
// The scene arrives as `key value...` lines (bench/scene_c.py writes them from the stage); the image leaves as raw
// float32 rows, top to bottom. Lengths are millimetres in the eye's canonical frame, which is the world frame here.
//
//   scene_c_reference SCENE.txt OUT.f32 [--check]
// --check also prints the quadrature's and the interpolation's own error on sample points, and the rect's direct light
// against eyelib's light tracer (CheckAgainstLightTracer).
#include <eyelib/anterior_chamber.h>
#include <eyelib/iris_light_tracer.h>
#include <eyelib/optics.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

using V = glm::dvec3;
constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxEvents = 8;
constexpr double kMinWeight = 1e-7;

/// The scene file: `key v1 v2 ...` per line.
using SceneFile = std::map<std::string, std::vector<double>>;

SceneFile ReadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  SceneFile scene;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    double v;
    while (words >> v) scene[key].push_back(v);
  }
  return scene;
}

const std::vector<double>& Values(const SceneFile& s, const std::string& key, std::size_t count) {
  const auto it = s.find(key);
  if (it == s.end() || it->second.size() != count)
    throw std::runtime_error("scene file: '" + key + "' wants " + std::to_string(count) + " numbers");
  return it->second;
}
double Value(const SceneFile& s, const std::string& key) { return Values(s, key, 1)[0]; }
V Vec(const SceneFile& s, const std::string& key) {
  const auto& v = Values(s, key, 3);
  return {v[0], v[1], v[2]};
}

/// What lies outside the eye: a lat-long dome (OpenEXR's convention, as UsdLux's DomeLight: row 0 at latitude
/// +pi/2, column 0 at longitude +pi, longitude 0 along +z, pi/2 along +x) and a one-sided rect.
struct Environment {
  int domeWidth = 0, domeHeight = 0;
  std::vector<float> dome;  // radiance per texel, rows top to bottom
  double domeScale = 1;
  V rectCenter, rectU, rectV, rectEmit;  // half edges (mm) and the emitting side's unit normal
  double rectRadiance = 0;

  double Dome(const V& d) const {
    const double lat = std::asin(std::clamp(d.y, -1.0, 1.0)), lon = std::atan2(d.x, d.z);
    const double x = (kPi - lon) / (2 * kPi) * domeWidth - 0.5, y = (kPi / 2 - lat) / kPi * domeHeight - 0.5;
    const double fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
    auto texel = [&](int i, int j) {
      i = ((i % domeWidth) + domeWidth) % domeWidth;
      j = std::clamp(j, 0, domeHeight - 1);
      return double(dome[std::size_t(j) * domeWidth + i]);
    };
    const int i = int(fx), j = int(fy);
    return domeScale * ((1 - ay) * ((1 - ax) * texel(i, j) + ax * texel(i + 1, j)) +
                        ay * ((1 - ax) * texel(i, j + 1) + ax * texel(i + 1, j + 1)));
  }
  double Rect(const V& p, const V& d) const {
    const double facing = glm::dot(d, rectEmit);
    if (!(facing < 0)) return 0;  // the back, or edge-on
    const double t = glm::dot(rectCenter - p, rectEmit) / facing;
    if (!(t > 0)) return 0;
    const V q = p + t * d - rectCenter;
    const double s = glm::dot(q, rectU) / glm::dot(rectU, rectU), r = glm::dot(q, rectV) / glm::dot(rectV, rectV);
    return std::abs(s) <= 1 && std::abs(r) <= 1 ? rectRadiance : 0;
  }
  /// Radiance arriving at p from direction d outside the eye (lights do not occlude one another).
  double Radiance(const V& p, const V& d) const { return Dome(d) + Rect(p, d); }
};

struct IrisReturn {
  V point;
  double weight;
};

/// Follows a path backwards from p inside the chamber along unit d: adds weight x T x (radiance outside) at every
/// exit through the cornea to *outside, and every arrival on the iris (not the pupil) to *returns, for up to
/// `events` cornea events.
void TraceInside(const eyelib::AnteriorChamber<double>& chamber, const Environment& env, V p, V d, double weight,
                 double* outside, std::vector<IrisReturn>* returns, int events = kMaxEvents) {
  const double ior = chamber.CorneaIor();
  for (int event = 0; event < events && weight > kMinWeight; ++event) {
    const auto hit = chamber.NextSurfaceFromInside(p, d);
    if (hit.kind == eyelib::ChamberSurfaceHit<double>::Iris) {
      if (returns) returns->push_back({hit.point, weight});
      return;
    }
    if (hit.kind != eyelib::ChamberSurfaceHit<double>::Cornea) return;
    const V n = hit.normal;
    const double F = eyelib::FresnelDielectric(-glm::dot(d, n), ior);  // arriving from inside
    V out;
    if (F < 1 && eyelib::Refract(-d, -n, 1 / ior, &out)) *outside += weight * (1 - F) * env.Radiance(hit.point, out);
    weight *= F;
    d = d - 2 * glm::dot(d, n) * n;
    p = hit.point - 1e-9 * n;
  }
}

/// Shirley and Chiu's concentric map of the unit square to the unit disk, lifted to the cosine-weighted
/// hemisphere about +z.
V ConcentricHemisphere(double u, double v) {
  const double a = 2 * u - 1, b = 2 * v - 1;
  double r, phi;
  if (a == 0 && b == 0) return {0, 0, 1};
  if (std::abs(a) > std::abs(b)) {
    r = a, phi = kPi / 4 * (b / a);
  } else {
    r = b, phi = kPi / 2 - kPi / 4 * (a / b);
  }
  const double x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, std::sqrt(std::max(0.0, 1 - x * x - y * y))};
}

struct Quadrature {
  int baseCells = 48;       // per side of the unit square
  int subCells = 8;         // a refined cell takes subCells^2 points
  double tolerance = 0;     // refine where neighbours differ by more than this fraction of the mean
  int chamberSubCells = 4;  // the chamber directions' refined cells (ChamberReturns)
};

/// Which cells of an n x n grid of values to refine: those with any of their eight neighbours differing from them by
/// more than `limit`, and every cell next to one. An edge that passes a cell by its corner, or crosses it between two
/// midpoints that agree, is still resolved (with four neighbours and no margin the quadrature lost 0.24 % of the
/// rect's light, against eyelib's light tracer).
std::vector<char> RefinedCells(const std::vector<double>& cells, int n, double limit) {
  std::vector<char> differs(cells.size(), 0), refined(cells.size(), 0);
  auto forNeighbours = [n](int i, int j, const auto& body) {
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di)
        if ((di || dj) && i + di >= 0 && i + di < n && j + dj >= 0 && j + dj < n)
          body(std::size_t(j + dj) * n + std::size_t(i + di));
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t k = std::size_t(j) * n + i;
      forNeighbours(i, j, [&](std::size_t m) { differs[k] |= std::abs(cells[m] - cells[k]) > limit; });
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t k = std::size_t(j) * n + i;
      refined[k] = differs[k];
      forNeighbours(i, j, [&](std::size_t m) { refined[k] |= differs[m]; });
    }
  return refined;
}

/// Point k of Roberts' R2 sequence in the unit square: subCells^2 of them integrate an edge through a refined cell to
/// about N^-3/4, where a regular grid's error stays aligned with the grid.
std::pair<double, double> R2Point(int k) {
  return {std::fmod(0.5 + 0.7548776662466927 * (k + 1), 1.0), std::fmod(0.5 + 0.5698402909980532 * (k + 1), 1.0)};
}

/// Irradiance at iris point x from outside the eye, through the cornea (W/mm^2 for unit radiance units), by paths of
/// up to `events` cornea events (1: the direct, once-refracted light).
double IrradianceFromOutside(const eyelib::AnteriorChamber<double>& chamber, const Environment& env, const V& x,
                             const Quadrature& q, int events = kMaxEvents) {
  const V start = x + V(0, 0, 1e-9);
  auto value = [&](double u, double v) {
    double outside = 0;
    TraceInside(chamber, env, start, ConcentricHemisphere(u, v), 1, &outside, nullptr, events);
    return outside;
  };
  const int n = q.baseCells;
  std::vector<double> cells(std::size_t(n) * n);
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) sum += cells[std::size_t(j) * n + i] = value((i + 0.5) / n, (j + 0.5) / n);
  const double mean = sum / (double(n) * n), limit = q.tolerance * mean;
  const std::vector<char> refined = RefinedCells(cells, n, limit);
  double total = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double c = cells[std::size_t(j) * n + i];
      if (!refined[std::size_t(j) * n + i]) {
        total += c;
        continue;
      }
      const int count = q.subCells * q.subCells;
      double fine = 0;
      for (int k = 0; k < count; ++k) {
        const auto [a, b] = R2Point(k);
        fine += value((i + a) / n, (j + b) / n);
      }
      total += fine / count;
    }
  return kPi * total / (double(n) * n);
}

/// A square grid of values over the iris disk, bilinear between nodes.
struct IrisGrid {
  int nodes = 0;
  double half = 0;  // mm
  std::vector<double> values;

  V Node(int i, int j) const {
    V p(-half + 2 * half * i / (nodes - 1), -half + 2 * half * j / (nodes - 1), 0);
    // Nodes beyond the rim carry the value at the rim (bilinear interpolation just inside it reads them).
    const double r = std::hypot(p.x, p.y), rim = half * (1 - 1e-6);
    if (r > rim) p.x *= rim / r, p.y *= rim / r;
    return p;
  }
  double At(double x, double y) const {
    const double gx = (x + half) / (2 * half) * (nodes - 1), gy = (y + half) / (2 * half) * (nodes - 1);
    const int i = std::clamp(int(std::floor(gx)), 0, nodes - 2), j = std::clamp(int(std::floor(gy)), 0, nodes - 2);
    const double ax = gx - i, ay = gy - j;
    auto v = [&](int a, int b) { return values[std::size_t(b) * nodes + a]; };
    return (1 - ay) * ((1 - ax) * v(i, j) + ax * v(i + 1, j)) + ay * ((1 - ax) * v(i, j + 1) + ax * v(i + 1, j + 1));
  }
};

/// Runs body(k) for k in [0, count) on `threads` threads.
void ParallelFor(int count, int threads, const std::function<void(int)>& body) {
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      for (int k; (k = next.fetch_add(1)) < count;) body(k);
    });
  for (auto& t : pool) t.join();
}

/// Every node's irradiance from outside.
IrisGrid OutsideGrid(const eyelib::AnteriorChamber<double>& chamber, const Environment& env, int nodes,
                     const Quadrature& q, int threads) {
  IrisGrid grid{nodes, chamber.IrisRadius(), std::vector<double>(std::size_t(nodes) * nodes)};
  std::atomic<int> done{0};
  const double spacing = 2 * grid.half / (nodes - 1);
  ParallelFor(nodes * nodes, threads, [&](int k) {
    const int i = k % nodes, j = k / nodes;
    const double r = std::hypot(-grid.half + spacing * i, -grid.half + spacing * j);
    if (r > grid.half + 1.5 * spacing) return;  // no iris point interpolates it
    const V x = grid.Node(i, j) + V(0, 0, chamber.IrisZ());
    grid.values[k] = IrradianceFromOutside(chamber, env, x, q);
    if (++done % (nodes * 8) == 0) std::fprintf(stderr, "\r  irradiance: %d / %d nodes", done.load(), nodes * nodes);
  });
  std::fprintf(stderr, "\n");
  return grid;
}

/// The returns to the iris of one node's chamber directions, each weighing its share of the cosine-weighted hemisphere:
/// a side x side grid of directions, cells where the returned weight changes fast (the critical angle's circle: the
/// Fresnel reflectance climbs to total internal reflection there like a square root, which a regular grid
/// underestimates, 0.5 % of scene C's key light at 48 x 48) refined into subCells^2 R2 points.
/// A kept return of the chamber grid, compact (a node keeps thousands): where it lands on the iris plane (mm) and
/// its weight.
struct StoredReturn {
  float x, y, weight;
};

std::vector<StoredReturn> ChamberReturns(const eyelib::AnteriorChamber<double>& chamber, const Environment& env,
                                         const V& x, int side, int subCells, double tolerance) {
  std::vector<std::vector<IrisReturn>> byCell(std::size_t(side) * side);
  std::vector<double> returned(byCell.size(), 0.0);
  double ignored = 0, sum = 0;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const std::size_t k = std::size_t(j) * side + i;
      TraceInside(chamber, env, x, ConcentricHemisphere((i + 0.5) / side, (j + 0.5) / side), 1, &ignored, &byCell[k]);
      for (const IrisReturn& r : byCell[k]) returned[k] += r.weight;
      sum += returned[k];
    }
  const std::vector<char> refined = RefinedCells(returned, side, tolerance * sum / double(byCell.size()));
  std::vector<StoredReturn> out;
  const double cell = 1 / (double(side) * side), count = double(subCells) * subCells;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const std::size_t k = std::size_t(j) * side + i;
      if (!refined[k]) {
        for (const IrisReturn& r : byCell[k])
          out.push_back({float(r.point.x), float(r.point.y), float(r.weight * cell)});
        continue;
      }
      std::vector<IrisReturn> fine;
      for (int p = 0; p < subCells * subCells; ++p) {
        const auto [a, b] = R2Point(p);
        TraceInside(chamber, env, x, ConcentricHemisphere((i + a) / side, (j + b) / side), 1, &ignored, &fine);
      }
      for (const IrisReturn& r : fine)
        out.push_back({float(r.point.x), float(r.point.y), float(r.weight * cell / count)});
    }
  return out;
}

/// The chamber's light on a coarser grid: E_c(x) = integral of the returns' albedo E(y) / pi, E = outside + E_c,
/// iterated `iterations` times; each node's returns (ChamberReturns) are kept.
IrisGrid ChamberGrid(const eyelib::AnteriorChamber<double>& chamber, const Environment& env, const IrisGrid& outside,
                     double albedo, int nodes, int side, int iterations, const Quadrature& q, int threads) {
  IrisGrid grid{nodes, chamber.IrisRadius(), std::vector<double>(std::size_t(nodes) * nodes, 0.0)};
  std::vector<std::vector<StoredReturn>> returns(grid.values.size());
  ParallelFor(nodes * nodes, threads, [&](int k) {
    const V x = grid.Node(k % nodes, k / nodes) + V(0, 0, chamber.IrisZ() + 1e-9);
    returns[std::size_t(k)] = ChamberReturns(chamber, env, x, side, q.chamberSubCells, q.tolerance);
  });
  for (int it = 0; it < iterations; ++it) {
    std::vector<double> next(grid.values.size());
    for (std::size_t k = 0; k < next.size(); ++k) {
      double sum = 0;
      for (const StoredReturn& r : returns[k])
        sum += double(r.weight) * albedo / kPi * (outside.At(r.x, r.y) + grid.At(r.x, r.y));
      next[k] = kPi * sum;
    }
    grid.values = next;
  }
  return grid;
}

struct Camera {
  glm::dmat4 toWorld{1.0};
  double tanHalfX = 0, tanHalfY = 0;
  int width = 0, height = 0;
};

/// The radiance a camera ray brings back: reflection and refraction at the cornea, each with its Fresnel weight.
double CameraRadiance(const eyelib::AnteriorChamber<double>& chamber, const Environment& env, const IrisGrid& outside,
                      const IrisGrid& inside, double albedo, const V& o, const V& d) {
  const auto hit = chamber.Surface().Intersect({o, d});
  if (!hit || !hit->fromOutside) return 0;  // the dome is hidden from the camera, the rect out of view
  const V n = hit->normal;
  const double ior = chamber.CorneaIor(), F = eyelib::FresnelDielectric(-glm::dot(d, n), ior);
  double radiance = F * env.Radiance(hit->point, d - 2 * glm::dot(d, n) * n);
  V in;
  if (!eyelib::Refract(-d, n, ior, &in)) return radiance;
  double outsideLight = 0;
  std::vector<IrisReturn> returns;
  TraceInside(chamber, env, hit->point - 1e-9 * n, in, 1 - F, &outsideLight, &returns);
  radiance += outsideLight;
  for (const IrisReturn& r : returns)
    radiance += r.weight * albedo / kPi * (outside.At(r.point.x, r.point.y) + inside.At(r.point.x, r.point.y));
  return radiance;
}

std::vector<float> RenderImage(const eyelib::AnteriorChamber<double>& chamber, const Environment& env,
                               const IrisGrid& outside, const IrisGrid& inside, double albedo, const Camera& cam,
                               int sub, int threads) {
  std::vector<float> image(std::size_t(cam.width) * cam.height);
  const V o(cam.toWorld * glm::dvec4(0, 0, 0, 1));
  ParallelFor(cam.height, threads, [&](int row) {
    for (int col = 0; col < cam.width; ++col) {
      double sum = 0;
      for (int b = 0; b < sub; ++b)
        for (int a = 0; a < sub; ++a) {
          const double x = 2 * (col + (a + 0.5) / sub) / cam.width - 1,
                       y = 1 - 2 * (row + (b + 0.5) / sub) / cam.height;
          const V d = glm::normalize(V(cam.toWorld * glm::dvec4(x * cam.tanHalfX, y * cam.tanHalfY, -1, 0)));
          sum += CameraRadiance(chamber, env, outside, inside, albedo, o, d);
        }
      image[std::size_t(row) * cam.width + col] = float(sum / (double(sub) * sub));
    }
  });
  return image;
}

/// The rect's direct (once-refracted) light on the iris, cell by cell, by eyelib's light tracer (rays from the rect
/// binned where they meet the iris: an estimator that shares only the surface and optics with the quadrature) against
/// the quadrature at 4 x 4 points per cell. The tracer reports the irradiance inside the cornea, where radiance is
/// n^2 times the outside's (the camera's refraction out divides it again): the ratio compared is tracer / (n^2 x
/// quadrature). Prints it over the cells wholly on the iris, with the tracer's standard error.
void CheckAgainstLightTracer(const eyelib::AnteriorChamber<double>& chamber, const Environment& env,
                             const Quadrature& q, int threads) {
  Environment rect = env;
  rect.domeScale = 0;
  eyelib::EyeLight light;
  light.shape = eyelib::LightShape::Rect;
  light.position = env.rectCenter;
  light.power = env.rectRadiance;
  // The tracer's rect emits along edgeU x edgeV.
  const bool keep = glm::dot(glm::cross(env.rectU, env.rectV), env.rectEmit) > 0;
  light.edgeU = keep ? env.rectU : env.rectV, light.edgeV = keep ? env.rectV : env.rectU;
  eyelib::IrisGrid cells;
  cells.cells = 8, cells.halfWidth = chamber.IrisRadius();
  constexpr std::int64_t kRaysPerThread = 20000000;
  std::vector<eyelib::IrradianceMap> maps(std::size_t(std::max(1, threads)));
  ParallelFor(int(maps.size()), int(maps.size()), [&](int k) {
    maps[std::size_t(k)] = eyelib::LightTraceIris(chamber, light, cells, kRaysPerThread, 101 + std::uint64_t(k));
  });
  const double n2 = chamber.CorneaIor() * chamber.CorneaIor(), h = cells.CellSize();
  double traced = 0, variance = 0, quadrature = 0;
  for (int j = 0; j < cells.cells; ++j)
    for (int i = 0; i < cells.cells; ++i) {
      if (!eyelib::CellOnIris(chamber, cells, i, j)) continue;
      for (const eyelib::IrradianceMap& m : maps) {
        traced += m.At(i, j) / double(maps.size());
        variance += m.ErrorAt(i, j) * m.ErrorAt(i, j) / double(maps.size() * maps.size());
      }
      const auto c = cells.CellCenter(i, j);
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
          const V x(c.x + h * ((a + 0.5) / 4 - 0.5), c.y + h * ((b + 0.5) / 4 - 0.5), chamber.IrisZ());
          quadrature += IrradianceFromOutside(chamber, rect, x, q, 1) / 16;
        }
    }
  std::printf("check: the rect's direct light, light tracer / quadrature %.5f +- %.5f (one standard error)\n",
              traced / (n2 * quadrature), std::sqrt(variance) / (n2 * quadrature));
}

Environment ReadEnvironment(const SceneFile& s) {
  Environment env;
  env.domeWidth = int(Value(s, "dome_size_width")), env.domeHeight = int(Value(s, "dome_size_height"));
  env.domeScale = Value(s, "dome_scale");
  env.rectCenter = Vec(s, "rect_center"), env.rectU = Vec(s, "rect_half_u"), env.rectV = Vec(s, "rect_half_v");
  env.rectEmit = glm::normalize(Vec(s, "rect_emit"));
  env.rectRadiance = Value(s, "rect_radiance");
  return env;
}

std::vector<float> ReadFloats(const std::string& path, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  std::vector<float> data(count);
  if (!in.read(reinterpret_cast<char*>(data.data()), std::streamsize(count * sizeof(float))))
    throw std::runtime_error("cannot read " + std::to_string(count) + " floats from " + path);
  return data;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 3) throw std::runtime_error("usage: scene_c_reference SCENE.txt OUT.f32 [--check]");
    const bool check = argc > 3 && std::string(argv[3]) == "--check";
    const SceneFile s = ReadScene(argv[1]);
    eyelib::ChamberParams params;
    params.irisDepth = Value(s, "iris_depth");
    params.pupilDiameter = Value(s, "pupil_diameter");
    params.corneaIor = Value(s, "cornea_ior");
    params.limbusInnerRatio = params.limbusOuterRatio = 1;
    if (const std::string problem = eyelib::ValidateChamberParams(params); !problem.empty())
      throw std::runtime_error(problem);
    const eyelib::AnteriorChamber<double> chamber(params);
    Environment env = ReadEnvironment(s);
    // The dome's texels beside the scene file, float32 rows top to bottom: the values its EXR holds.
    env.dome = ReadFloats(std::string(argv[1]) + ".dome.f32", std::size_t(env.domeWidth) * env.domeHeight);
    Camera cam;
    const auto& m = Values(s, "camera_to_world", 16);  // column-major, glm's layout
    for (int k = 0; k < 16; ++k) cam.toWorld[k / 4][k % 4] = m[k];
    cam.tanHalfX = Value(s, "tan_half_x"), cam.tanHalfY = Value(s, "tan_half_y");
    cam.width = int(Value(s, "width")), cam.height = int(Value(s, "height"));
    const double albedo = Value(s, "iris_albedo");
    const int threads = int(Value(s, "threads"));
    const Quadrature q{int(Value(s, "base_cells")), int(Value(s, "sub_cells")), Value(s, "refine_tolerance"),
                       int(Value(s, "chamber_sub_cells"))};

    const IrisGrid outside = OutsideGrid(chamber, env, int(Value(s, "grid_nodes")), q, threads);
    const IrisGrid inside =
        ChamberGrid(chamber, env, outside, albedo, int(Value(s, "chamber_nodes")), int(Value(s, "chamber_directions")),
                    int(Value(s, "chamber_iterations")), q, threads);
    if (check) {
      // The quadrature against a finer one, and the grid's interpolation against direct evaluation, on points
      // spread over the iris annulus.
      const Quadrature fine{q.baseCells * 2, q.subCells, q.tolerance / 2};
      double worstQ = 0, worstI = 0, sumQ = 0, sumI = 0;
      const int samples = 64;
      for (int k = 0; k < samples; ++k) {
        const double r = params.pupilDiameter / 2 +
                         (chamber.IrisRadius() - params.pupilDiameter / 2) * (k + 0.5) / samples,
                     phi = 2.399963 * k;
        const V x(r * std::cos(phi), r * std::sin(phi), chamber.IrisZ());
        const double direct = IrradianceFromOutside(chamber, env, x, q);
        const double finer = IrradianceFromOutside(chamber, env, x, fine);
        const double interpolated = outside.At(x.x, x.y);
        const double eq = std::abs(direct - finer) / finer, ei = std::abs(interpolated - direct) / direct;
        worstQ = std::max(worstQ, eq), worstI = std::max(worstI, ei), sumQ += eq * eq, sumI += ei * ei;
      }
      std::printf(
          "check: quadrature vs twice as fine: rms %.2e worst %.2e; interpolation vs direct: rms %.2e worst "
          "%.2e (relative, %d iris points)\n",
          std::sqrt(sumQ / samples), worstQ, std::sqrt(sumI / samples), worstI, samples);
      CheckAgainstLightTracer(chamber, env, q, threads);
    }
    const std::vector<float> image =
        RenderImage(chamber, env, outside, inside, albedo, cam, int(Value(s, "subpixels")), threads);
    const std::string out = argv[2], tmp = out + ".tmp";
    {
      std::ofstream f(tmp, std::ios::binary);
      f.write(reinterpret_cast<const char*>(image.data()), std::streamsize(image.size() * sizeof(float)));
      if (!f) throw std::runtime_error("cannot write " + out);
    }
    if (std::rename(tmp.c_str(), out.c_str()) != 0) throw std::runtime_error("cannot write " + out);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_c_reference: %s\n", e.what());
    return 1;
  }
}
