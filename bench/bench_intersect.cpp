// bench_intersect: what it costs, and how much geometric error it leaves, to intersect camera rays
// with the anterior surface of the eye analytically (eyelib) or as a triangle mesh (Embree 3).
//
// For each cornea model (ellipsoid-cone, paraboloid) one fixed batch of rays (std::mt19937_64, fixed
// seed; bit-identical rays for every method) is traced by
//   - eyelib's AnteriorSurface<T>::Intersect with T = float and T = double;
//   - Embree 3 rtcIntersect1 (single rays, RTC_SCENE_FLAG_ROBUST) against polar-grid tessellations of
//     the same cap: N rings x 4N segments, vertices on the surface, one ring on the ellipsoid/cone
//     junction, for several N.
// The double analytic hit of each ray is the reference. The table (markdown on stdout, optionally
// CSV) has, per model and method:
//   Embree MiB           memory Embree holds for the mesh (BVH and buffers), from its memory monitor
//   ns/ray               median over --reps timed passes of the whole batch, each after an untimed
//                        warm-up pass, rounds interleaved across methods; one thread, steady_clock
//   sag err (um)         worst |z - f(r)| over the method's hits, f the double analytic sag
//   pos err (um)         worst and 99th percentile |p - p_ref| over the rays both hit
//   normal err (deg)     worst angle to the reference hit's normal over the rays both hit; meshes give
//                        the triangle's geometric normal ("flat") and the barycentric blend of the
//                        analytic vertex normals ("interp.")
//   hit/miss mismatches  rays the method and the reference disagree about hitting
// The scene is in millimetres in the canonical eye frame (apex at the origin, gaze +z); the report
// is in nanoseconds, micrometres and degrees.
//
// Usage: bench_intersect [--rays N] [--reps K] [--csv PATH] [--quick]
#include "bench_util.h"
#include "eyelib/anterior_surface.h"
#include "eyelib/vec.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace {

using eyelib::AnteriorSurface;
using eyelib::CorneaModel;
using eyelib::Ray;
using eyelib::SurfaceHit;
using eyelib::SurfacePiece;
using Vec3d = eyelib::Vec3<double>;
using Vec3f = eyelib::Vec3<float>;

constexpr double kPi = eyelib::paper::kPi;
constexpr double kUmPerMm = 1000.0;
constexpr std::uint64_t kRaySeed = 0x5eed2018;

// ------------------------------------------------------------------------------------- options

struct Options {
  std::size_t rays = 200000;
  int reps = 7;
  std::string csvPath;
  std::vector<int> rings = {8, 16, 32, 64, 128, 256};
};

[[noreturn]] void Usage(const char* argv0, int exitCode) {
  std::fprintf(exitCode ? stderr : stdout,
               "usage: %s [--rays N] [--reps K] [--csv PATH] [--quick]\n"
               "  --rays N    rays in the batch (default 200000; 20000 with --quick)\n"
               "  --reps K    timed passes per method, the median is reported (default 7)\n"
               "  --csv PATH  also write the table as CSV\n"
               "  --quick     fewer rays and tessellation levels (8, 32, 128 rings)\n",
               argv0);
  std::exit(exitCode);
}

Options ParseOptions(int argc, char** argv) {
  Options opt;
  std::optional<long long> rays;
  bool quick = false;
  bench::ParseArgs(argc, argv, Usage, [&](const std::string& arg, const auto& value) {
    if (arg == "--rays")
      rays = std::stoll(value());
    else if (arg == "--reps")
      opt.reps = std::stoi(value());
    else if (arg == "--csv")
      opt.csvPath = value();
    else if (arg == "--quick")
      quick = true;
    else
      return false;
    return true;
  });
  if (quick) {
    opt.rays = 20000;
    opt.rings = {8, 32, 128};
  }
  if (rays && *rays < 1) Usage(argv[0], 2);
  if (rays) opt.rays = std::size_t(*rays);
  if (opt.reps < 1) Usage(argv[0], 2);
  return opt;
}

// ---------------------------------------------------------------------------------------- rays

/// The ray batch in both precisions. The double rays are the float rays widened, so that every
/// method traces exactly the same rays.
struct RayBatch {
  std::vector<Ray<float>> f;
  std::vector<Ray<double>> d;

  template <class T> const std::vector<Ray<T>>& In() const {
    if constexpr (std::is_same_v<T, float>)
      return f;
    else
      return d;
  }
};

/// Uniform in [0, 1) from the top 53 bits: the same numbers with every standard library.
double Uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1p-53; }

/// A camera-like ray: origin uniform on the front hemisphere (z > -2 mm) of the 50 mm sphere about
/// (0, 0, -2), aimed at a uniform point of the disc r < 8 mm in the plane z = -1.5 mm. Unit direction.
Ray<double> CameraRay(std::mt19937_64& rng) {
  constexpr double kSphereRadius = 50, kDiscRadius = 8, kDiscZ = -1.5;
  const Vec3d center(0, 0, -2);
  const double cosTheta = 1 - Uniform01(rng);  // (0, 1]: uniform in solid angle
  const double sinTheta = std::sqrt(1 - cosTheta * cosTheta);
  const double phi = 2 * kPi * Uniform01(rng);
  const Vec3d origin = center + kSphereRadius * Vec3d(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
  const double rho = kDiscRadius * std::sqrt(Uniform01(rng));
  const double psi = 2 * kPi * Uniform01(rng);
  const Vec3d target(rho * std::cos(psi), rho * std::sin(psi), kDiscZ);
  return {origin, glm::normalize(target - origin)};
}

RayBatch MakeRayBatch(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  RayBatch batch;
  batch.f.reserve(count);
  batch.d.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Ray<double> ray = CameraRay(rng);
    const Ray<float> narrow{Vec3f(ray.origin), Vec3f(ray.dir)};
    batch.f.push_back(narrow);
    batch.d.push_back({Vec3d(narrow.origin), Vec3d(narrow.dir)});
  }
  return batch;
}

// ------------------------------------------------------------------------------------- methods

/// One ray's result, widened to double for the accuracy pass.
struct HitRecord {
  bool hit = false;
  Vec3d point{0};                           ///< mm
  Vec3d normal{0};                          ///< unit: the analytic normal, or the triangle's
  std::optional<Vec3d> interpolatedNormal;  ///< meshes only: blend of the vertex normals, unit
};

/// An intersection method under test. Trace() is the timed part: it intersects every ray of the
/// batch and keeps only the raw outputs; Resolve() turns one raw output into a HitRecord, untimed.
class Method {
 public:
  virtual ~Method() = default;
  virtual std::string Name() const = 0;
  /// "rings x segments" for meshes, empty for analytic methods.
  virtual std::string Tessellation() const { return {}; }
  virtual std::size_t Triangles() const { return 0; }
  /// Memory the ray tracer holds for the geometry (Embree: BVH and buffers), MiB; 0 if none.
  virtual double SceneMegabytes() const { return 0; }
  virtual void Trace() = 0;
  virtual HitRecord Resolve(std::size_t ray) const = 0;
};

/// eyelib's exact intersection in precision T.
template <class T> class AnalyticMethod final : public Method {
 public:
  AnalyticMethod(CorneaModel model, const RayBatch& rays) : surface_(model), rays_(rays.In<T>()), hits_(rays_.size()) {}

  std::string Name() const override { return std::is_same_v<T, float> ? "analytic float" : "analytic double"; }

  void Trace() override {
    for (std::size_t i = 0; i < rays_.size(); ++i) hits_[i] = surface_.Intersect(rays_[i]);
  }

  HitRecord Resolve(std::size_t i) const override {
    const std::optional<SurfaceHit<T>>& hit = hits_[i];
    if (!hit) return {};
    return {true, Vec3d(hit->point), Vec3d(hit->normal), std::nullopt};
  }

 private:
  AnteriorSurface<T> surface_;
  const std::vector<Ray<T>>& rays_;
  std::vector<std::optional<SurfaceHit<T>>> hits_;
};

// -------------------------------------------------------------------------------- tessellation

/// A triangle mesh of the surface cap. Positions are on the surface up to rounding to float; the
/// analytic normal of each vertex is kept in double beside it.
struct CapMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3d> normals;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

struct Ring {
  double radius;  ///< mm
  SurfacePiece piece;
};

/// The rings of an N-ring grid, apex excluded, out to the rim: uniform in radius within each piece,
/// with a ring exactly on the ellipsoid/cone junction so that no triangle straddles the slope kink.
/// The junction ring is listed once per piece, so that each side gets its own piece's normals.
std::vector<Ring> CapRings(const AnteriorSurface<double>& surface, int rings) {
  const double rim = surface.RimRadius(), junction = surface.JunctionRadius();
  const SurfacePiece inner = surface.PieceAt(0), outer = surface.PieceAt(rim);
  const int innerRings = junction < rim ? std::clamp(int(std::lround(rings * junction / rim)), 1, rings - 1) : rings;
  std::vector<Ring> out;
  auto appendUniform = [&](double r0, double r1, int count, SurfacePiece piece, bool includeStart) {
    for (int i = includeStart ? 0 : 1; i <= count; ++i)
      out.push_back({i == count ? r1 : r0 + (r1 - r0) * i / count, piece});
  };
  appendUniform(0, junction, innerRings, inner, false);
  if (junction < rim) appendUniform(junction, rim, rings - innerRings, outer, true);
  return out;
}

/// Appends a vertex on the surface at polar (r, phi) with the normal of `piece`; returns its index.
std::uint32_t AddVertex(CapMesh& mesh, const AnteriorSurface<double>& surface, SurfacePiece piece, double r,
                        double phi) {
  const Vec3d p(r * std::cos(phi), r * std::sin(phi), surface.Sag(r));
  mesh.positions.emplace_back(p);
  mesh.normals.push_back(glm::normalize(surface.Quadric(piece).Gradient(p)));
  return std::uint32_t(mesh.positions.size() - 1);
}

/// Appends `segments` vertices evenly around a ring; returns the index of the first.
std::uint32_t AddRing(CapMesh& mesh, const AnteriorSurface<double>& surface, const Ring& ring, int segments) {
  const std::uint32_t first = std::uint32_t(mesh.positions.size());
  for (int j = 0; j < segments; ++j) AddVertex(mesh, surface, ring.piece, ring.radius, 2 * kPi * j / segments);
  return first;
}

// Triangles wind counter-clockwise seen from +z (outside the eye).
void AddApexFan(CapMesh& mesh, std::uint32_t apex, std::uint32_t ring, int segments) {
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back({apex, ring + j, ring + (j + 1) % segments});
}

void StitchRings(CapMesh& mesh, std::uint32_t inner, std::uint32_t outer, int segments) {
  for (int j = 0; j < segments; ++j) {
    const std::uint32_t k = (j + 1) % segments;
    mesh.triangles.push_back({inner + j, outer + j, outer + k});
    mesh.triangles.push_back({inner + j, outer + k, inner + k});
  }
}

/// Polar grid of `rings` rings by 4 * rings segments: 8 N^2 - 4 N triangles.
CapMesh TessellateCap(const AnteriorSurface<double>& surface, int rings) {
  const int segments = 4 * rings;
  CapMesh mesh;
  const std::uint32_t apex = AddVertex(mesh, surface, surface.PieceAt(0), 0, 0);
  std::optional<std::pair<std::uint32_t, SurfacePiece>> previous;  // first vertex, piece
  for (const Ring& ring : CapRings(surface, rings)) {
    const std::uint32_t first = AddRing(mesh, surface, ring, segments);
    if (!previous)
      AddApexFan(mesh, apex, first, segments);
    else if (previous->second == ring.piece)
      StitchRings(mesh, previous->first, first, segments);
    previous = {first, ring.piece};
  }
  return mesh;
}

// -------------------------------------------------------------------------------------- embree

using EmbreeScene = std::unique_ptr<RTCSceneTy, decltype(&rtcReleaseScene)>;

void ReportEmbreeError(void*, RTCError code, const char* message) {
  std::fprintf(stderr, "embree error %d: %s\n", int(code), message);
  std::exit(1);
}

/// An Embree device that counts the bytes it holds (through its memory monitor), so that each
/// scene's size (BVH and buffers) can be reported.
class EmbreeDevice {
 public:
  EmbreeDevice() : device_(rtcNewDevice(nullptr)) {
    if (!device_) {
      std::fprintf(stderr, "embree: cannot create a device (error %d)\n", int(rtcGetDeviceError(nullptr)));
      std::exit(1);
    }
    rtcSetDeviceErrorFunction(device_, ReportEmbreeError, nullptr);
    rtcSetDeviceMemoryMonitorFunction(device_, CountBytes, &bytes_);
  }
  ~EmbreeDevice() { rtcReleaseDevice(device_); }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice Get() const { return device_; }
  std::int64_t BytesInUse() const { return bytes_.load(); }

 private:
  static bool CountBytes(void* counter, ssize_t bytes, bool /*post*/) {
    *static_cast<std::atomic<std::int64_t>*>(counter) += bytes;
    return true;
  }

  std::atomic<std::int64_t> bytes_{0};
  RTCDevice device_;
};

/// A committed scene holding the mesh as one triangle geometry. Robust mode makes the traversal
/// watertight, so hit/miss mismatches measure the geometry and not cracks between triangles.
EmbreeScene BuildScene(const EmbreeDevice& embree, const CapMesh& mesh) {
  RTCDevice device = embree.Get();
  EmbreeScene scene(rtcNewScene(device), &rtcReleaseScene);
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.positions.size()));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) vertices[3 * i + c] = mesh.positions[i][c];
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) indices[3 * i + c] = mesh.triangles[i][c];
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene.get(), geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene.get());
  return scene;
}

RTCRayHit MakeRayHit(const Ray<float>& ray) {
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.tnear = 0;
  rh.ray.dir_x = ray.dir.x;
  rh.ray.dir_y = ray.dir.y;
  rh.ray.dir_z = ray.dir.z;
  rh.ray.time = 0;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

/// What rtcIntersect1 returns that a renderer keeps.
struct MeshHit {
  float t, u, v;
  std::uint32_t primID;
  Vec3f ng;  ///< geometric normal, not normalised
  bool hit;
};

/// Embree single-ray intersection against a tessellation of the cap.
class EmbreeMeshMethod final : public Method {
 public:
  EmbreeMeshMethod(const EmbreeDevice& device, const AnteriorSurface<double>& surface, int rings, const RayBatch& rays)
      : rings_(rings),
        mesh_(TessellateCap(surface, rings)),
        bytesBefore_(device.BytesInUse()),
        scene_(BuildScene(device, mesh_)),
        sceneBytes_(device.BytesInUse() - bytesBefore_),
        rays_(rays.f),
        hits_(rays_.size()) {}

  std::string Name() const override { return "embree rtcIntersect1"; }
  std::string Tessellation() const override { return std::to_string(rings_) + " x " + std::to_string(4 * rings_); }
  std::size_t Triangles() const override { return mesh_.triangles.size(); }
  double SceneMegabytes() const override { return double(sceneBytes_) / (1 << 20); }

  void Trace() override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = 0; i < rays_.size(); ++i) {
      RTCRayHit rh = MakeRayHit(rays_[i]);
      rtcIntersect1(scene_.get(), &context, &rh);
      hits_[i] = {rh.ray.tfar,
                  rh.hit.u,
                  rh.hit.v,
                  rh.hit.primID,
                  Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
                  rh.hit.geomID != RTC_INVALID_GEOMETRY_ID};
    }
  }

  HitRecord Resolve(std::size_t i) const override {
    const MeshHit& h = hits_[i];
    if (!h.hit) return {};
    const Ray<float>& ray = rays_[i];
    const Vec3f point = ray.origin + h.t * ray.dir;  // in float, as a float renderer would
    // The cap is a height field, so its outward side is +z whatever Embree's winding convention.
    const Vec3d flat = glm::normalize(Vec3d(h.ng)) * (h.ng.z < 0 ? -1.0 : 1.0);
    const std::array<std::uint32_t, 3>& tri = mesh_.triangles[h.primID];
    const Vec3d blend = (1.0 - h.u - h.v) * mesh_.normals[tri[0]] + double(h.u) * mesh_.normals[tri[1]] +
                        double(h.v) * mesh_.normals[tri[2]];
    return {true, Vec3d(point), flat, glm::normalize(blend)};
  }

 private:
  int rings_;
  CapMesh mesh_;
  std::int64_t bytesBefore_;  // device memory before the build; declared first to be read first
  EmbreeScene scene_;
  std::int64_t sceneBytes_;
  const std::vector<Ray<float>>& rays_;
  std::vector<MeshHit> hits_;
};

// ---------------------------------------------------------------------------------- measuring

/// The q-quantile by nearest rank (q = 0.5 is the median, the lower one for an even count).
double NearestRank(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const std::size_t rank = std::size_t(std::ceil(q * double(values.size())));
  const std::size_t k = std::min(values.size() - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

/// Angle between unit vectors, degrees; accurate for tiny angles, where acos is not.
double AngleDeg(const Vec3d& a, const Vec3d& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * 180 / kPi;
}

double SagErrorUm(const AnteriorSurface<double>& exact, const Vec3d& p) {
  return std::abs(p.z - exact.Sag(std::sqrt(eyelib::RadiusSquared(p)))) * kUmPerMm;
}

struct Accuracy {
  std::size_t hits = 0, mismatches = 0;
  double sagUm = 0, posMaxUm = 0, posP99Um = 0, normalDeg = 0;
  std::optional<double> interpolatedNormalDeg;
};

std::vector<HitRecord> ResolveAll(const Method& method, std::size_t rays) {
  std::vector<HitRecord> out(rays);
  for (std::size_t i = 0; i < rays; ++i) out[i] = method.Resolve(i);
  return out;
}

Accuracy MeasureAccuracy(const Method& method, const std::vector<HitRecord>& reference,
                         const AnteriorSurface<double>& exact) {
  Accuracy acc;
  std::vector<double> posUm;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const HitRecord got = method.Resolve(i);
    const HitRecord& want = reference[i];
    if (got.hit != want.hit) ++acc.mismatches;
    if (!got.hit) continue;
    ++acc.hits;
    acc.sagUm = std::max(acc.sagUm, SagErrorUm(exact, got.point));
    if (!want.hit) continue;
    posUm.push_back(glm::distance(got.point, want.point) * kUmPerMm);
    acc.normalDeg = std::max(acc.normalDeg, AngleDeg(got.normal, want.normal));
    if (got.interpolatedNormal)
      acc.interpolatedNormalDeg =
          std::max(acc.interpolatedNormalDeg.value_or(0), AngleDeg(*got.interpolatedNormal, want.normal));
  }
  acc.posMaxUm = posUm.empty() ? 0 : *std::max_element(posUm.begin(), posUm.end());
  acc.posP99Um = NearestRank(std::move(posUm), 0.99);
  return acc;
}

/// One timed pass of the whole batch, ns per ray.
double TimeNsPerRay(Method& method, std::size_t rays) {
  const auto start = std::chrono::steady_clock::now();
  method.Trace();
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(stop - start).count() / double(rays);
}

/// Median ns per ray of each method. Rounds are interleaved (every method once per round), so that
/// a burst of load from elsewhere on the machine costs each method one sample, not all of them;
/// each timed pass follows an untimed pass of the same method, so that its data are as warm in the
/// caches as they would be if it ran alone.
std::vector<double> MedianNsPerRay(const std::vector<std::unique_ptr<Method>>& methods, int reps, std::size_t rays) {
  std::vector<std::vector<double>> samples(methods.size());
  for (int r = 0; r < reps; ++r)
    for (std::size_t m = 0; m < methods.size(); ++m) {
      methods[m]->Trace();
      samples[m].push_back(TimeNsPerRay(*methods[m], rays));
    }
  std::vector<double> medians;
  for (std::vector<double>& s : samples) medians.push_back(NearestRank(std::move(s), 0.5));
  return medians;
}

struct Row {
  std::string model, method, tessellation;
  std::size_t triangles;
  double nsPerRay;
  double sceneMegabytes;
  Accuracy acc;
};

std::vector<std::unique_ptr<Method>> MakeMethods(CorneaModel model, const RayBatch& rays, const EmbreeDevice& device,
                                                 const Options& opt) {
  const AnteriorSurface<double> exact(model);
  std::vector<std::unique_ptr<Method>> methods;
  methods.push_back(std::make_unique<AnalyticMethod<float>>(model, rays));
  methods.push_back(std::make_unique<AnalyticMethod<double>>(model, rays));
  for (int rings : opt.rings) methods.push_back(std::make_unique<EmbreeMeshMethod>(device, exact, rings, rays));
  return methods;
}

std::vector<Row> BenchModel(CorneaModel model, const RayBatch& rays, const EmbreeDevice& device, const Options& opt) {
  const AnteriorSurface<double> exact(model);
  AnalyticMethod<double> referenceMethod(model, rays);
  referenceMethod.Trace();
  const std::vector<HitRecord> reference = ResolveAll(referenceMethod, rays.d.size());

  const std::vector<std::unique_ptr<Method>> methods = MakeMethods(model, rays, device, opt);
  std::vector<Accuracy> accuracy;
  for (const std::unique_ptr<Method>& method : methods) {
    method->Trace();  // warm-up; also the outputs the accuracy pass reads
    accuracy.push_back(MeasureAccuracy(*method, reference, exact));
  }
  const std::vector<double> ns = MedianNsPerRay(methods, opt.reps, rays.d.size());

  std::vector<Row> rows;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const Method& method = *methods[m];
    rows.push_back({eyelib::ToString(model), method.Name(), method.Tessellation(), method.Triangles(), ns[m],
                    method.SceneMegabytes(), accuracy[m]});
  }
  return rows;
}

// ------------------------------------------------------------------------------------- output

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

void PrintPreamble(const Options& opt) {
  std::printf("# bench_intersect: rays against the anterior surface, eyelib analytic vs Embree %s mesh\n\n",
              RTC_VERSION_STRING);
  std::printf(
      "%zu camera-like rays (seed %#llx), %d timed passes per method; this machine has %u cores\n"
      "(std::thread::hardware_concurrency).\n",
      opt.rays, static_cast<unsigned long long>(kRaySeed), opt.reps, std::thread::hardware_concurrency());
  std::printf(
      "Times are single-threaded: medians of whole-batch passes, each after a warm-up pass,\n"
      "in ns per ray. Errors are against the double analytic hit of the same ray (pos, normal)\n"
      "and the double analytic sag (sag).\n\n");
}

std::string Join(const std::vector<std::string>& cells, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < cells.size(); ++i) out += (i ? separator : "") + cells[i];
  return out;
}

const std::vector<std::string> kMarkdownHeader = {"model",
                                                  "method",
                                                  "tessellation",
                                                  "triangles",
                                                  "Embree MiB",
                                                  "ns/ray",
                                                  "hits",
                                                  "hit/miss mismatches",
                                                  "sag err max (um)",
                                                  "pos err max (um)",
                                                  "pos err p99 (um)",
                                                  "normal err max (deg) flat",
                                                  "normal err max (deg) interp."};
const std::vector<std::string> kCsvHeader = {"model",
                                             "method",
                                             "tessellation",
                                             "triangles",
                                             "scene_mib",
                                             "ns_per_ray",
                                             "hits",
                                             "mismatches",
                                             "sag_err_max_um",
                                             "pos_err_max_um",
                                             "pos_err_p99_um",
                                             "normal_err_max_deg",
                                             "interp_normal_err_max_deg"};

/// One row's cells in the header's column order; `errorFormat` for the error columns, `none` where
/// a column does not apply to the method.
std::vector<std::string> Cells(const Row& r, const char* errorFormat, const std::string& none) {
  const bool mesh = r.triangles > 0;
  return {r.model,
          r.method,
          mesh ? r.tessellation : none,
          mesh ? std::to_string(r.triangles) : none,
          mesh ? Format("%.2f", r.sceneMegabytes) : none,
          Format("%.1f", r.nsPerRay),
          std::to_string(r.acc.hits),
          std::to_string(r.acc.mismatches),
          Format(errorFormat, r.acc.sagUm),
          Format(errorFormat, r.acc.posMaxUm),
          Format(errorFormat, r.acc.posP99Um),
          Format(errorFormat, r.acc.normalDeg),
          r.acc.interpolatedNormalDeg ? Format(errorFormat, *r.acc.interpolatedNormalDeg) : none};
}

void PrintMarkdown(const std::vector<Row>& rows) {
  std::printf("| %s |\n", Join(kMarkdownHeader, " | ").c_str());
  std::string rule = "|";  // text columns left-aligned, numbers right-aligned
  for (std::size_t i = 0; i < kMarkdownHeader.size(); ++i) rule += i < 3 ? "---|" : "--:|";
  std::printf("%s\n", rule.c_str());
  for (const Row& r : rows) std::printf("| %s |\n", Join(Cells(r, "%.3g", "-"), " | ").c_str());
  std::printf(
      "\nflat: the analytic normal (analytic rows) or the triangle's geometric normal (mesh rows);\n"
      "interp.: barycentric blend of the analytic vertex normals (mesh rows only).\n");
}

bool WriteCsv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << Join(kCsvHeader, ",") << '\n';
  for (const Row& r : rows) out << Join(Cells(r, "%.6g", ""), ",") << '\n';
  return bool(out);
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = ParseOptions(argc, argv);
  PrintPreamble(opt);
  const RayBatch rays = MakeRayBatch(opt.rays, kRaySeed);
  const EmbreeDevice device;
  std::vector<Row> rows;
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    const std::vector<Row> modelRows = BenchModel(model, rays, device, opt);
    rows.insert(rows.end(), modelRows.begin(), modelRows.end());
  }
  PrintMarkdown(rows);
  if (!opt.csvPath.empty() && !WriteCsv(opt.csvPath, rows)) {
    std::fprintf(stderr, "cannot write %s\n", opt.csvPath.c_str());
    return 1;
  }
  return 0;
}
