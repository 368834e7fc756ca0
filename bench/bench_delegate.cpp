// bench_delegate: what the hdeye render delegate costs per ray and per frame.
//
// Three measurements, each printed as a markdown table (and optionally written as CSV):
//   1. Renderer throughput through the whole Hydra-style flow (InMemorySceneDelegate -> RenderIndex ->
//      RenderPass -> Renderer) on two scenes built here: "ball" (the subdivided cube on a floor of
//      delegate/examples/renderScene.cpp, a sphere light and a dome) and "eye" (an analytic eye, a
//      sphere light 75 deg off its gaze, a dim dome). Only the color AOV is bound. rays/s is
//      RenderStats::rays / RenderStats::seconds: every closest-hit ray (camera and bounce) and every
//      shadow ray (next event estimation, and the eye's MNEE shadow rays) the renderer cast. The run
//      is repeated (same samples each time) and the median time is reported, for 1 thread and all.
//   2. Bare Embree on the ball scene's own committed root scene (RenderDelegate::RootScene() after a
//      RenderPass::Execute, so the same BVHs and instances): the same number of random incoherent
//      single rays as one render traced, split like the render's rays: closest-hit rays
//      (rtcIntersect1: camera rays in the render's proportion, the rest cosine-distributed from
//      surface points, as bounce rays) and shadow rays (rtcOccluded1: from surface points to a
//      point on the sphere light, or to the dome along a cosine direction). The render's mix of
//      closest-hit and shadow rays is counted exactly: this program interposes rtcIntersect1 and
//      rtcOccluded1 (it defines them and forwards to Embree's through dlsym(RTLD_NEXT)), and counts
//      only during one extra untimed render; the timed renders and bare traces pay the same
//      forwarding call and nothing else. The blended ceiling is the bare rays/s at that mix.
//      2b. Minimal path tracers (minimal_path_tracer.h) on the same root scene, timed with each
//      back-to-back render and bare pass: how near bare Embree the least code doing this scene's
//      transport gets, with a counter hash or the renderer's ZSobol sampler, Lambert or the
//      renderer's UsdPreviewSurface BSDF.
//   3. Per-frame sync of an animated Catmull-Clark mesh (a jittered torus of quads) at refine levels
//      2 and 3: the time of RenderIndex::SyncAll plus the root scene commit (exactly what
//      RenderPass::Execute does before rendering) for a first sync (a new render index each frame), a
//      frame where only the points moved (InMemorySceneDelegate::SetPoints), and a frame where the
//      topology changed (SetTopology, alternating between two tessellations with the same face
//      count); medians over the frames, with Mesh::Stats() counters per frame. A reference table
//      times the parts alone: SubdivRefiner construction, EvaluatePoints and EvaluateLimit on the same
//      torus, and bare Embree building (and, in a dynamic scene, refitting) a mesh of as many triangles.
// Times are steady_clock; the 1-minute load average is printed at the start and the end, since other
// work on the machine skews the all-threads numbers. The 1-thread renders and bare passes also report
// the calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), which other processes on a shared machine
// skew far less than wall time; the most robust ratio pairs each 1-thread render with a bare pass right
// after it (the median of the per-pair ratios). The default run takes about 40 s on 2 cores.
//
// Usage: bench_delegate [--quick] [--throughput-only] [--csv PREFIX] [--threads N]
//   --quick       smaller images, fewer rays and frames (a smoke run of a few seconds)
//   --throughput-only  measurements 1 and 2 only (no per-frame sync)
//   --csv PREFIX  also write PREFIX_render.csv, PREFIX_embree.csv, PREFIX_sync.csv and
//                 PREFIX_sync_reference.csv
//   --threads N   the "all threads" count (default: std::thread::hardware_concurrency)
#include "bench_util.h"
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/camera.h"
#include "hdeye/prims/light.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/sampleStream.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "hdeye/scene/sampleScenes.h"
#include "minimal_path_tracer.h"

#include <eyelib/sampling.h>
#include "hdeye/prims/subdivRefiner.h"

#include <embree3/rtcore.h>

#include <dlfcn.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

// ------------------------------------------------------------------------------ ray counting
// Interposed Embree entry points. hdeye is a static library, so its calls to rtcIntersect1 and
// rtcOccluded1 bind to these definitions at link time; they forward to libembree3's.

namespace {

using bench::Median;

std::atomic<bool> gCountRays{false};
std::atomic<std::int64_t> gClosestHitRays{0}, gShadowRays{0};

template <class Fn> Fn RealEmbree(const char* name) {
  void* symbol = dlsym(RTLD_NEXT, name);
  if (!symbol) {
    std::fprintf(stderr, "bench_delegate: cannot find Embree's %s (%s)\n", name, dlerror());
    std::abort();
  }
  return reinterpret_cast<Fn>(symbol);
}

using Intersect1Fn = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*);
using Occluded1Fn = void (*)(RTCScene, RTCIntersectContext*, RTCRay*);
const Intersect1Fn gRealIntersect1 = RealEmbree<Intersect1Fn>("rtcIntersect1");
const Occluded1Fn gRealOccluded1 = RealEmbree<Occluded1Fn>("rtcOccluded1");

}  // namespace

extern "C" void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit) {
  if (gCountRays.load(std::memory_order_relaxed)) gClosestHitRays.fetch_add(1, std::memory_order_relaxed);
  gRealIntersect1(scene, context, rayhit);
}

extern "C" void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray) {
  if (gCountRays.load(std::memory_order_relaxed)) gShadowRays.fetch_add(1, std::memory_order_relaxed);
  gRealOccluded1(scene, context, ray);
}

namespace {

using namespace hdeye;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kSeed = 0x5eedde1e;

// ------------------------------------------------------------------------------------- options

struct Options {
  bool quick = false;
  bool throughputOnly = false;  ///< skip the per-frame sync measurement
  std::string csvPrefix;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  int renderRuns = 5;  ///< timed renders per scene and thread count
  int bareRuns = 5;    ///< timed passes over each bare-Embree batch
  int syncFrames = 5;  ///< frames per sync case
};

[[noreturn]] void Usage(const char* argv0, int exitCode) {
  std::fprintf(exitCode ? stderr : stdout,
               "usage: %s [--quick] [--throughput-only] [--csv PREFIX] [--threads N]\n"
               "  --quick       smaller images, fewer rays and frames\n"
               "  --throughput-only  renderer and bare Embree throughput only (no per-frame sync)\n"
               "  --csv PREFIX  also write PREFIX_{render,embree,minimal,sync,sync_reference}.csv\n"
               "  --threads N   the \"all threads\" count (default: hardware concurrency)\n",
               argv0);
  std::exit(exitCode);
}

Options ParseOptions(int argc, char** argv) {
  Options opt;
  bench::ParseArgs(argc, argv, Usage, [&](const std::string& arg, const auto& value) {
    if (arg == "--quick")
      opt.quick = true;
    else if (arg == "--throughput-only")
      opt.throughputOnly = true;
    else if (arg == "--csv")
      opt.csvPrefix = value();
    else if (arg == "--threads")
      opt.threads = std::stoi(value());
    else
      return false;
    return true;
  });
  if (opt.threads < 1) Usage(argv[0], 2);
  if (opt.quick) opt.syncFrames = opt.renderRuns = opt.bareRuns = 3;
  return opt;
}

// --------------------------------------------------------------------------------------- helpers

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The calling thread's CPU time in seconds: what a 1-thread measurement costs, whatever else the machine runs.
double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// The 1-minute load average: other work on the machine skews the "all threads" numbers.
double LoadAverage() {
  double load[1] = {-1};
  return getloadavg(load, 1) == 1 ? load[0] : -1;
}

double Uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1p-53; }

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

/// A table: printed as markdown, optionally written as CSV.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  void Print() const {
    auto line = [](const std::vector<std::string>& cells) {
      std::string s = "|";
      for (const std::string& c : cells) s += " " + c + " |";
      std::printf("%s\n", s.c_str());
    };
    line(header);
    line(std::vector<std::string>(header.size(), "---"));
    for (const auto& r : rows) line(r);
    std::printf("\n");
  }

  void WriteCsv(const std::string& path) const {
    std::ofstream out(path);
    auto line = [&](const std::vector<std::string>& cells) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        std::string cell = cells[i];
        cell.erase(std::remove(cell.begin(), cell.end(), '*'), cell.end());  // markdown bold
        out << (i ? "," : "") << cell;
      }
      out << "\n";
    };
    line(header);
    for (const auto& r : rows) line(r);
    if (!out) throw std::runtime_error("cannot write " + path);
  }
};

// ----------------------------------------------------------------------------------------- scenes

/// One render delegate, its render index, a scene delegate and a render pass; destroyed in reverse.
struct Stage {
  RenderDelegate delegate;
  RenderIndex index{&delegate};
  InMemorySceneDelegate scene{&index};
  RenderPass pass{&index};
  std::uint64_t committedVersion = ~0ull;  ///< for SyncAndCommit, which stands in for the pass
};

const char* const kColor = "/Render/color";
const PrimId& kCamera = sampleScenes::kCamera;

/// The sample scenes (hdeye/scene/sampleScenes.h) with a colour buffer.
void BuildBallScene(InMemorySceneDelegate& scene, int width, int height) {
  sampleScenes::AddBallOnFloor(scene);
  scene.AddRenderBuffer(kColor, width, height, 4);
}

void BuildEyeScene(InMemorySceneDelegate& scene, int width, int height) {
  sampleScenes::AddSideLitEye(scene);
  scene.AddRenderBuffer(kColor, width, height, 4);
}

// --------------------------------------------------------------------------- 1. render throughput

struct RenderCase {
  std::string name;
  void (*build)(InMemorySceneDelegate&, int, int);
  int width, height, spp;
};

struct RenderResult {
  std::string scene;
  int threads = 0;
  RenderStats stats;  ///< of the first timed run (every run traces the same rays)
  double medianSeconds = 0;
  double medianCpuSeconds = 0;        ///< the calling thread's CPU time (1 thread: the render runs on it)
  std::int64_t nonFiniteSamples = 0;  ///< summed over the runs
  double RaysPerSecond() const { return double(stats.rays) / medianSeconds; }
  double RaysPerCpuSecond() const { return double(stats.rays) / medianCpuSeconds; }
  double SamplesPerSecond() const { return double(stats.samples) / medianSeconds; }
};

/// The closest-hit and shadow rays of one render, counted through the interposed Embree calls.
struct RayMix {
  std::int64_t closestHit = 0, shadow = 0, samples = 0, reported = 0;  ///< reported: RenderStats::rays
  double ShadowFraction() const { return double(shadow) / double(closestHit + shadow); }
};

RenderStats Render(Stage& stage, int spp, int threads) {
  stage.delegate.Settings().samplesPerPixel = spp;
  stage.delegate.Settings().threads = threads;
  return stage.pass.Execute(kCamera, {{"color", kColor}});
}

RenderResult MeasureRender(Stage& stage, const RenderCase& c, int threads, int runs) {
  RenderResult r;
  r.scene = c.name, r.threads = threads;
  std::vector<double> seconds, cpuSeconds;
  for (int run = 0; run < runs; ++run) {
    const double cpuStart = ThreadCpuSeconds();
    const RenderStats s = Render(stage, c.spp, threads);
    cpuSeconds.push_back(ThreadCpuSeconds() - cpuStart);
    if (run == 0) r.stats = s;
    seconds.push_back(s.seconds);
    r.nonFiniteSamples += s.nonFiniteSamples;
  }
  r.medianSeconds = Median(seconds);
  r.medianCpuSeconds = Median(cpuSeconds);
  return r;
}

RayMix CountRayMix(Stage& stage, const RenderCase& c, int threads) {
  gClosestHitRays = 0, gShadowRays = 0;
  gCountRays = true;
  const RenderStats s = Render(stage, c.spp, threads);
  gCountRays = false;
  return {gClosestHitRays.load(), gShadowRays.load(), s.samples, s.rays};
}

// ------------------------------------------------------------------------------ 2. bare Embree

/// A single ray as the renderer builds it (float origin and direction, tnear 0).
struct BareRay {
  float org[3], dir[3];
  float tfar;
};

BareRay MakeRay(const glm::dvec3& o, const glm::dvec3& d, double tfar) {
  return {{float(o.x), float(o.y), float(o.z)},
          {float(d.x), float(d.y), float(d.z)},
          tfar < 3e38 ? float(tfar) : std::numeric_limits<float>::infinity()};
}

struct SurfacePoint {
  glm::dvec3 p, n;  ///< offset origin (as the renderer offsets it) and the normal facing the camera ray
};

glm::dvec3 UniformSphere(double u1, double u2) {
  const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// A camera ray through a uniformly random film point.
WorldRay RandomCameraRay(const CameraView& view, double aspect, std::mt19937_64& rng) {
  const double u = Uniform01(rng);
  return view.GenerateRay(u, Uniform01(rng), aspect);
}

/// Points the camera sees, found by tracing random camera rays. The geometric normal Embree
/// returns for an instanced mesh is in the instance's object space; the ball scene's instances are
/// translations only, so it is the world normal.
std::vector<SurfacePoint> VisibleSurfacePoints(RTCScene scene, const CameraView& view, double aspect, std::size_t count,
                                               std::mt19937_64& rng) {
  std::vector<SurfacePoint> points;
  while (points.size() < count) {
    const WorldRay w = RandomCameraRay(view, aspect, rng);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    const BareRay b = MakeRay(w.origin, w.dir, w.tFar);
    rh.ray.org_x = b.org[0], rh.ray.org_y = b.org[1], rh.ray.org_z = b.org[2];
    rh.ray.dir_x = b.dir[0], rh.ray.dir_y = b.dir[1], rh.ray.dir_z = b.dir[2];
    rh.ray.tnear = float(w.tNear), rh.ray.tfar = b.tfar, rh.ray.mask = ~0u;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    const glm::dvec3 p = w.origin + double(rh.ray.tfar) * w.dir;
    glm::dvec3 n = glm::normalize(glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    if (glm::dot(n, w.dir) > 0) n = -n;
    points.push_back({p + n * (1e-5 * (1 + glm::length(p))), n});
  }
  return points;
}

/// Closest-hit rays: `cameraRays` camera rays, the rest cosine-distributed from surface points.
std::vector<BareRay> ClosestHitBatch(std::size_t count, std::size_t cameraRays, const CameraView& view, double aspect,
                                     const std::vector<SurfacePoint>& surface, std::mt19937_64& rng) {
  std::vector<BareRay> rays;
  rays.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (i < cameraRays) {
      const WorldRay w = RandomCameraRay(view, aspect, rng);
      rays.push_back(MakeRay(w.origin, w.dir, w.tFar));
      continue;
    }
    const SurfacePoint& s = surface[rng() % surface.size()];
    const double u1 = Uniform01(rng);
    rays.push_back(
        MakeRay(s.p, eyelib::SampleCosineHemisphere(s.n, u1, Uniform01(rng)), std::numeric_limits<double>::infinity()));
  }
  std::shuffle(rays.begin(), rays.end(), rng);  // incoherent: camera and bounce rays interleaved
  return rays;
}

/// Shadow rays from surface points: half to a uniform point on the key light's sphere (ending just
/// short of it), half to the dome along a cosine direction; directions below the surface redrawn.
std::vector<BareRay> ShadowBatch(std::size_t count, const std::vector<SurfacePoint>& surface, std::mt19937_64& rng) {
  std::vector<BareRay> rays;
  rays.reserve(count);
  while (rays.size() < count) {
    const SurfacePoint& s = surface[rng() % surface.size()];
    const double pick = Uniform01(rng), u1 = Uniform01(rng), u2 = Uniform01(rng);
    if (pick < 0.5) {
      const glm::dvec3 target =
          sampleScenes::kBallKeyPosition + double(sampleScenes::kBallKeyRadius) * UniformSphere(u1, u2);
      const glm::dvec3 d = target - s.p;
      const double distance = glm::length(d);
      if (glm::dot(d, s.n) <= 0) continue;
      rays.push_back(MakeRay(s.p, d / distance, distance * (1 - 1e-6)));
    } else {
      rays.push_back(
          MakeRay(s.p, eyelib::SampleCosineHemisphere(s.n, u1, u2), std::numeric_limits<double>::infinity()));
    }
  }
  return rays;
}

void TraceClosest(RTCScene scene, const BareRay* rays, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = rays[i].org[0], rh.ray.org_y = rays[i].org[1], rh.ray.org_z = rays[i].org[2];
    rh.ray.dir_x = rays[i].dir[0], rh.ray.dir_y = rays[i].dir[1], rh.ray.dir_z = rays[i].dir[2];
    rh.ray.tnear = 0, rh.ray.tfar = rays[i].tfar;
    rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = 0;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
  }
}

void TraceShadow(RTCScene scene, const BareRay* rays, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = rays[i].org[0], ray.org_y = rays[i].org[1], ray.org_z = rays[i].org[2];
    ray.dir_x = rays[i].dir[0], ray.dir_y = rays[i].dir[1], ray.dir_z = rays[i].dir[2];
    ray.tnear = 0, ray.tfar = rays[i].tfar;
    ray.mask = ~0u, ray.flags = 0, ray.time = 0;
    rtcOccluded1(scene, &context, &ray);
  }
}

using TraceFn = void (*)(RTCScene, const BareRay*, std::size_t);

struct BatchTime {
  double seconds = 0, cpuSeconds = 0;  ///< medians; cpuSeconds: the calling thread's (1 thread only)
};

/// Median seconds to trace the whole batch with `threads` std::threads (contiguous slices; 1 thread:
/// the calling thread, like a 1-thread render), after one untimed warm-up pass.
BatchTime TimeBatch(TraceFn trace, RTCScene scene, const std::vector<BareRay>& rays, int threads, int runs) {
  auto pass = [&] {
    if (threads == 1) return trace(scene, rays.data(), rays.size());
    std::vector<std::thread> workers;
    const std::size_t slice = (rays.size() + threads - 1) / threads;
    for (int t = 0; t < threads; ++t) {
      const std::size_t begin = std::min(rays.size(), t * slice), end = std::min(rays.size(), begin + slice);
      workers.emplace_back([=, &rays] { trace(scene, rays.data() + begin, end - begin); });
    }
    for (std::thread& w : workers) w.join();
  };
  pass();
  std::vector<double> seconds, cpuSeconds;
  for (int run = 0; run < runs; ++run) {
    const auto start = Clock::now();
    const double cpuStart = ThreadCpuSeconds();
    pass();
    cpuSeconds.push_back(ThreadCpuSeconds() - cpuStart);
    seconds.push_back(Seconds(start));
  }
  return {Median(seconds), Median(cpuSeconds)};
}

struct BareResult {
  std::size_t closestRays = 0, shadowRays = 0;
  double closestSeconds[2] = {0, 0}, shadowSeconds[2] = {0, 0};  ///< [1 thread, all threads]
  double closestCpuSeconds = 0, shadowCpuSeconds = 0;            ///< 1 thread, the thread's CPU time
  double pairedCpuRatio = 0;  ///< renderer / bare rays per CPU second, 1 thread, median over back-to-back pairs
  /// The minimal path tracers (minimal_path_tracer.h) on the same BVH, 1 thread, timed with each pair.
  struct Minimal {
    bench::MinimalVariant variant;
    bench::MinimalResult result;
    double cpuSeconds = 0;        ///< median
    double ofBare = 0;            ///< its rays per CPU second over bare Embree's, median over the pairs
    double renderPerMinimal = 0;  ///< the renderer's rays per CPU second over its, median over the pairs
  };
  std::vector<Minimal> minimal;
};

/// The ball scene as the minimal path tracer sees it: the render's camera, image, samples and depth, the key and
/// dome lights as the renderer converts them.
bench::MinimalScene MinimalSceneOf(Stage& stage, const RenderCase& c, const CameraView& view,
                                   const eyelib::ZSobolKeyTable& keys) {
  auto light = [&](const PrimId& id) {
    const Light* l = dynamic_cast<const Light*>(stage.index.GetSprim(id));
    return RenderLight::FromParams(l->Params(), l->Transform());
  };
  const RenderLight key = light(sampleScenes::kBallKey), sky = light(sampleScenes::kBallSky);
  bench::MinimalScene m;
  m.sampleKeys = &keys;
  m.scene = stage.delegate.RootScene();
  m.camera = view;
  m.width = c.width, m.height = c.height, m.spp = c.spp;
  m.maxDepth = stage.delegate.Settings().maxDepth;
  m.keyPosition = key.position, m.keyRadius = key.radius;
  m.keyRadiance = key.radiance, m.domeRadiance = sky.radiance;
  return m;
}

BareResult MeasureBareEmbree(Stage& stage, const RayMix& mix, const RenderCase& c, const Options& opt) {
  const RTCScene scene = stage.delegate.RootScene();
  const CameraView view = dynamic_cast<const Camera*>(stage.index.GetSprim(kCamera))->View();
  const double aspect = double(c.width) / c.height;
  std::mt19937_64 rng(kSeed);
  const std::vector<SurfacePoint> surface = VisibleSurfacePoints(scene, view, aspect, opt.quick ? 4096 : 65536, rng);
  const std::vector<BareRay> closest =
      ClosestHitBatch(std::size_t(mix.closestHit), std::size_t(mix.samples), view, aspect, surface, rng);
  const std::vector<BareRay> shadow = ShadowBatch(std::size_t(mix.shadow), surface, rng);
  BareResult r;
  r.closestRays = closest.size(), r.shadowRays = shadow.size();
  const int threadCounts[2] = {1, opt.threads};
  for (int k = 0; k < 2; ++k) {
    const BatchTime closestTime = TimeBatch(TraceClosest, scene, closest, threadCounts[k], opt.bareRuns);
    const BatchTime shadowTime = TimeBatch(TraceShadow, scene, shadow, threadCounts[k], opt.bareRuns);
    r.closestSeconds[k] = closestTime.seconds, r.shadowSeconds[k] = shadowTime.seconds;
    if (k == 0) r.closestCpuSeconds = closestTime.cpuSeconds, r.shadowCpuSeconds = shadowTime.cpuSeconds;
  }
  // A 1-thread render, the 1-thread bare batches and the minimal path tracers back to back meet the same load on a
  // shared machine: the ratios of their rates per round, median over the rounds.
  const eyelib::ZSobolKeyTable keys = SampleStream::KeyTable(0);
  const bench::MinimalScene minimalScene = MinimalSceneOf(stage, c, view, keys);
  const bench::MinimalVariant variants[] = {bench::MinimalVariant::Lambert, bench::MinimalVariant::ZSobol,
                                            bench::MinimalVariant::PreviewSurface, bench::MinimalVariant::Both};
  std::vector<double> ratios;
  std::vector<std::vector<double>> minimalCpu(std::size(variants)), ofBare(std::size(variants)),
      renderPer(std::size(variants));
  for (const bench::MinimalVariant v : variants) r.minimal.push_back({v, {}});
  for (int run = 0; run < opt.renderRuns; ++run) {
    double start = ThreadCpuSeconds();
    const RenderStats s = Render(stage, c.spp, 1);
    const double renderRate = double(s.rays) / (ThreadCpuSeconds() - start);
    start = ThreadCpuSeconds();
    TraceClosest(scene, closest.data(), closest.size());
    TraceShadow(scene, shadow.data(), shadow.size());
    const double bareRate = double(closest.size() + shadow.size()) / (ThreadCpuSeconds() - start);
    ratios.push_back(renderRate / bareRate);
    for (std::size_t k = 0; k < r.minimal.size(); ++k) {
      start = ThreadCpuSeconds();
      r.minimal[k].result = bench::TraceMinimal(minimalScene, r.minimal[k].variant);
      minimalCpu[k].push_back(ThreadCpuSeconds() - start);
      const double rate = double(r.minimal[k].result.rays) / minimalCpu[k].back();
      ofBare[k].push_back(rate / bareRate);
      renderPer[k].push_back(renderRate / rate);
    }
  }
  r.pairedCpuRatio = Median(ratios);
  for (std::size_t k = 0; k < r.minimal.size(); ++k)
    r.minimal[k].cpuSeconds = Median(minimalCpu[k]), r.minimal[k].ofBare = Median(ofBare[k]),
    r.minimal[k].renderPerMinimal = Median(renderPer[k]);
  return r;
}

// ------------------------------------------------------------------------------ 3. per-frame sync

/// A torus of nu x nv quads (major radius 1, minor 0.35), control points jittered radially by a
/// fixed seed, and displaced along the tube's normal by a travelling wave of phase `phase`.
struct Torus {
  int nu, nv;
  int refineLevel;

  MeshTopology Topology() const {
    MeshTopology t;
    t.refineLevel = refineLevel;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
        t.faceVertexCounts.push_back(4);
        for (int v : {i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1}) t.faceVertexIndices.push_back(v);
      }
    return t;
  }

  std::vector<Vec3f> Points(double phase) const {
    std::mt19937_64 rng(kSeed + std::uint64_t(nu) * 1000 + std::uint64_t(nv));
    std::vector<Vec3f> points;
    points.reserve(std::size_t(nu) * nv);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
        const double jitter = 0.01 * (Uniform01(rng) - 0.5);
        const double r = 0.35 + jitter + 0.03 * std::sin(6 * u + phase);
        const glm::dvec3 center(std::cos(u), std::sin(u), 0);
        const glm::dvec3 normal(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
        points.push_back(Vec3f(center + r * normal));
      }
    return points;
  }
};

const char* const kAnimated = "/World/animated";

struct SyncTiming {
  double syncSeconds = 0, commitSeconds = 0;
};

/// RenderIndex::SyncAll plus the root commit when a prim edited the scene: RenderPass::Execute's
/// work before it renders.
SyncTiming SyncAndCommit(Stage& stage) {
  SyncTiming t;
  auto start = Clock::now();
  stage.index.SyncAll();
  t.syncSeconds = Seconds(start);
  start = Clock::now();
  const std::uint64_t version = stage.delegate.GetRenderParam()->SceneVersion();
  if (version != stage.committedVersion) {
    rtcCommitScene(stage.delegate.RootScene());
    stage.committedVersion = version;
  }
  t.commitSeconds = Seconds(start);
  return t;
}

const Mesh& AnimatedMesh(const Stage& stage) { return *dynamic_cast<const Mesh*>(stage.index.GetRprim(kAnimated)); }

/// Mesh::Stats() counted over `frames` frames, per frame (every frame of a case does the same work).
MeshSyncStats PerFrame(const MeshSyncStats& after, const MeshSyncStats& before, int frames) {
  MeshSyncStats d;
  d.topologyBuilds = (after.topologyBuilds - before.topologyBuilds) / frames;
  d.refinements = (after.refinements - before.refinements) / frames;
  d.stencilEvaluations = (after.stencilEvaluations - before.stencilEvaluations) / frames;
  d.pointUploads = (after.pointUploads - before.pointUploads) / frames;
  d.normalEvaluations = (after.normalEvaluations - before.normalEvaluations) / frames;
  d.transformUpdates = (after.transformUpdates - before.transformUpdates) / frames;
  return d;
}

struct SyncResult {
  std::string kind;
  int refineLevel = 0, controlFaces = 0, triangles = 0, frames = 0;
  double medianSync = 0, medianCommit = 0, medianTotal = 0;
  MeshSyncStats perFrame;  ///< Mesh::Stats() change over one frame (every frame did the same)
};

SyncResult Summarize(const std::string& kind, const Torus& torus, int triangles, const std::vector<SyncTiming>& timings,
                     const MeshSyncStats& perFrame) {
  std::vector<double> sync, commit, total;
  for (const SyncTiming& t : timings) {
    sync.push_back(t.syncSeconds), commit.push_back(t.commitSeconds);
    total.push_back(t.syncSeconds + t.commitSeconds);
  }
  return {kind,         torus.refineLevel, torus.nu * torus.nv, triangles, int(timings.size()),
          Median(sync), Median(commit),    Median(total),       perFrame};
}

/// First sync: a new render delegate and index each frame, the mesh added, then synced.
SyncResult MeasureFirstSync(const Torus& torus, int frames) {
  std::vector<SyncTiming> timings;
  MeshSyncStats stats;
  int triangles = 0;
  for (int f = 0; f < frames; ++f) {
    auto stage = std::make_unique<Stage>();
    stage->scene.AddMesh(kAnimated, torus.Topology(), torus.Points(0));
    timings.push_back(SyncAndCommit(*stage));
    stats = AnimatedMesh(*stage).Stats();
    triangles = AnimatedMesh(*stage).TriangleCount();
  }
  return Summarize("first sync", torus, triangles, timings, stats);
}

/// Frames where only the points moved.
SyncResult MeasurePointsOnly(const Torus& torus, int frames) {
  Stage stage;
  stage.scene.AddMesh(kAnimated, torus.Topology(), torus.Points(0));
  SyncAndCommit(stage);
  const MeshSyncStats before = AnimatedMesh(stage).Stats();
  std::vector<SyncTiming> timings;
  for (int f = 1; f <= frames; ++f) {
    stage.scene.SetPoints(kAnimated, torus.Points(0.3 * f));
    timings.push_back(SyncAndCommit(stage));
  }
  const MeshSyncStats perFrame = PerFrame(AnimatedMesh(stage).Stats(), before, frames);
  return Summarize("points only", torus, AnimatedMesh(stage).TriangleCount(), timings, perFrame);
}

/// Frames where the topology changed: alternately `torus` and its transpose (nv x nu, the same
/// face count, other connectivity and point count).
SyncResult MeasureTopologyChange(const Torus& torus, int frames) {
  const Torus other{torus.nv, torus.nu, torus.refineLevel};
  Stage stage;
  stage.scene.AddMesh(kAnimated, torus.Topology(), torus.Points(0));
  SyncAndCommit(stage);
  const MeshSyncStats before = AnimatedMesh(stage).Stats();
  std::vector<SyncTiming> timings;
  for (int f = 1; f <= frames; ++f) {
    const Torus& next = f % 2 ? other : torus;
    stage.scene.SetTopology(kAnimated, next.Topology(), next.Points(0.3 * f));
    timings.push_back(SyncAndCommit(stage));
  }
  const MeshSyncStats perFrame = PerFrame(AnimatedMesh(stage).Stats(), before, frames);
  return Summarize("topology changed", torus, AnimatedMesh(stage).TriangleCount(), timings, perFrame);
}

/// Reference: bare Embree on a triangle mesh with the refined torus's triangle count (a grid torus of
/// (nu 2^L) x (nv 2^L) quads, two triangles each). `build`: median seconds of rtcCommitScene of a
/// new scene (the default build quality, as Mesh uses: a points-only frame rebuilds its prototype);
/// `refit`: median seconds to move every vertex and recommit a scene built with
/// RTC_BUILD_QUALITY_REFIT in a dynamic, low build quality scene (what a points-only frame could cost).
struct BareBuild {
  int triangles = 0;
  double build = 0, refit = 0;
};

/// The OpenSubdiv side of the same torus, alone (median seconds): building the refiner (refinement
/// and stencil table, a topology frame's work) and evaluating refined points or limit positions
/// with normals (a points frame's work).
struct RefinerCost {
  double construct = 0, evaluatePoints = 0, evaluateLimit = 0;
};

RefinerCost MeasureRefiner(const Torus& torus, int runs) {
  const MeshTopology topology = torus.Topology();
  const std::vector<Vec3f> control = torus.Points(0);
  std::vector<double> construct, points, limit;
  std::vector<Vec3f> refined, positions, normals;
  for (int run = 0; run < runs; ++run) {
    auto start = Clock::now();
    const SubdivRefiner refiner(topology, int(control.size()), torus.refineLevel);
    construct.push_back(Seconds(start));
    start = Clock::now();
    refiner.EvaluatePoints(control, &refined);
    points.push_back(Seconds(start));
    start = Clock::now();
    refiner.EvaluateLimit(control, &positions, &normals);
    limit.push_back(Seconds(start));
  }
  return {Median(construct), Median(points), Median(limit)};
}

BareBuild MeasureBareBuild(RTCDevice device, const Torus& torus, int runs) {
  const Torus fine{torus.nu << torus.refineLevel, torus.nv << torus.refineLevel, 0};
  const MeshTopology quads = fine.Topology();
  BareBuild r;
  r.triangles = 2 * int(quads.faceVertexCounts.size());
  auto makeScene = [&](RTCBuildQuality quality, double phase) {
    const std::vector<Vec3f> points = fine.Points(phase);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, quality);
    std::copy(points.begin(), points.end(),
              static_cast<Vec3f*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          sizeof(Vec3f), points.size())));
    auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), std::size_t(r.triangles)));
    const std::vector<int>& q = quads.faceVertexIndices;
    for (std::size_t f = 0; f < q.size() / 4; ++f)
      for (int k : {0, 1, 2, 0, 2, 3}) *index++ = unsigned(q[4 * f + std::size_t(k)]);
    rtcCommitGeometry(geometry);
    RTCScene scene = rtcNewScene(device);
    if (quality == RTC_BUILD_QUALITY_REFIT) {
      // Embree reads a geometry's build quality only in a two-level (low quality) scene.
      rtcSetSceneFlags(scene, RTC_SCENE_FLAG_DYNAMIC);
      rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
    }
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    return scene;
  };
  std::vector<double> build, refit;
  for (int run = 0; run < runs; ++run) {
    RTCScene scene = makeScene(RTC_BUILD_QUALITY_MEDIUM, 0);
    auto start = Clock::now();
    rtcCommitScene(scene);
    build.push_back(Seconds(start));
    rtcReleaseScene(scene);
  }
  RTCScene dynamic = makeScene(RTC_BUILD_QUALITY_REFIT, 0);
  rtcCommitScene(dynamic);
  RTCGeometry geometry = rtcGetGeometry(dynamic, 0);
  for (int run = 1; run <= runs; ++run) {
    const std::vector<Vec3f> points = fine.Points(0.3 * run);
    auto start = Clock::now();
    std::copy(points.begin(), points.end(),
              static_cast<Vec3f*>(rtcGetGeometryBufferData(geometry, RTC_BUFFER_TYPE_VERTEX, 0)));
    rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geometry);
    rtcCommitScene(dynamic);
    refit.push_back(Seconds(start));
  }
  rtcReleaseScene(dynamic);
  r.build = Median(build), r.refit = Median(refit);
  return r;
}

// ---------------------------------------------------------------------------------------- report

Table RenderTable(const std::vector<RenderResult>& results, const std::vector<RayMix>& mixes,
                  const std::vector<RenderCase>& cases) {
  Table t{{"scene", "image", "spp", "threads", "rays", "rays/sample", "shadow rays", "median s", "Mrays/s",
           "Msamples/s", "Msamples/CPU-s (1 thread)"},
          {}};
  for (const RenderResult& r : results) {
    const auto c = std::find_if(cases.begin(), cases.end(), [&](const RenderCase& k) { return k.name == r.scene; });
    const RayMix& mix = mixes[std::size_t(c - cases.begin())];
    t.rows.push_back({r.scene, std::to_string(c->width) + "x" + std::to_string(c->height), std::to_string(c->spp),
                      std::to_string(r.threads), std::to_string(r.stats.rays),
                      Format("%.2f", double(r.stats.rays) / double(r.stats.samples)),
                      Format("%.1f%%", 100 * mix.ShadowFraction()), Format("%.3f", r.medianSeconds),
                      Format("%.3f", r.RaysPerSecond() * 1e-6), Format("%.3f", r.SamplesPerSecond() * 1e-6),
                      r.threads == 1 ? Format("%.3f", double(r.stats.samples) / r.medianCpuSeconds * 1e-6) : ""});
  }
  return t;
}

/// Bare Embree rays/s and the renderer's rays/s as a fraction of them, for 1 thread and all.
Table EmbreeTable(const BareResult& bare, const RenderResult ours[2], int threads) {
  Table t{{"what", "rays", "Mrays/s 1 thread", "Mrays/s " + std::to_string(threads) + " threads"}, {}};
  auto rate = [](double rays, double seconds) { return Format("%.3f", rays / seconds * 1e-6); };
  std::vector<std::string> closest{"bare rtcIntersect1 (camera + cosine bounce rays)",
                                   std::to_string(bare.closestRays)};
  std::vector<std::string> shadow{"bare rtcOccluded1 (to sphere light / dome)", std::to_string(bare.shadowRays)};
  std::vector<std::string> blend{"bare Embree, blended at the render's mix",
                                 std::to_string(bare.closestRays + bare.shadowRays)};
  std::vector<std::string> render{"hdeye renderer (RenderStats::rays / seconds)", std::to_string(ours[0].stats.rays)};
  std::vector<std::string> fractionBlend{"**renderer / blended bare Embree**", ""};
  std::vector<std::string> fractionClosest{"renderer / bare rtcIntersect1 only", ""};
  for (int k = 0; k < 2; ++k) {
    const double blended =
        double(bare.closestRays + bare.shadowRays) / (bare.closestSeconds[k] + bare.shadowSeconds[k]);
    const double closestRate = double(bare.closestRays) / bare.closestSeconds[k];
    closest.push_back(rate(double(bare.closestRays), bare.closestSeconds[k]));
    shadow.push_back(rate(double(bare.shadowRays), bare.shadowSeconds[k]));
    blend.push_back(Format("%.3f", blended * 1e-6));
    render.push_back(Format("%.3f", ours[k].RaysPerSecond() * 1e-6));
    fractionBlend.push_back(Format("**%.1f%%**", 100 * ours[k].RaysPerSecond() / blended));
    fractionClosest.push_back(Format("%.1f%%", 100 * ours[k].RaysPerSecond() / closestRate));
  }
  const double blendedCpu =
      double(bare.closestRays + bare.shadowRays) / (bare.closestCpuSeconds + bare.shadowCpuSeconds);
  std::vector<std::string> fractionCpu{"renderer / blended bare Embree, by thread CPU time", "",
                                       Format("%.1f%%", 100 * ours[0].RaysPerCpuSecond() / blendedCpu), ""};
  std::vector<std::string> fractionPaired{"renderer / blended bare Embree, by thread CPU time, back-to-back pairs", "",
                                          Format("%.1f%%", 100 * bare.pairedCpuRatio), ""};
  t.rows = {closest, shadow, blend, render, fractionBlend, fractionClosest, fractionCpu, fractionPaired};
  return t;
}

Table MinimalTable(const BareResult& bare) {
  Table t{
      {"minimal path tracer", "rays", "shadow rays", "Mrays/CPU-s", "of bare Embree", "renderer / it", "mean radiance"},
      {}};
  for (const BareResult::Minimal& m : bare.minimal)
    t.rows.push_back(
        {bench::MinimalVariantName(m.variant), std::to_string(m.result.rays),
         Format("%.1f%%", 100.0 * double(m.result.shadowRays) / double(std::max<std::int64_t>(1, m.result.rays))),
         Format("%.3f", double(m.result.rays) / m.cpuSeconds * 1e-6), Format("%.1f%%", 100 * m.ofBare),
         Format("%.1f%%", 100 * m.renderPerMinimal), Format("%.4f", m.result.meanRadiance)});
  return t;
}

Table SyncTable(const std::vector<SyncResult>& results) {
  Table t{{"level", "control faces", "triangles", "frame", "frames", "sync ms", "root commit ms", "total ms",
           "x first sync", "topology builds", "refinements", "stencil evals", "point uploads", "normal evals",
           "transform updates"},
          {}};
  double first = 0;
  for (const SyncResult& r : results) {
    if (r.kind == "first sync") first = r.medianTotal;
    t.rows.push_back({std::to_string(r.refineLevel), std::to_string(r.controlFaces), std::to_string(r.triangles),
                      r.kind, std::to_string(r.frames), Format("%.2f", r.medianSync * 1e3),
                      Format("%.2f", r.medianCommit * 1e3), Format("%.2f", r.medianTotal * 1e3),
                      Format("%.3f", r.medianTotal / first), std::to_string(r.perFrame.topologyBuilds),
                      std::to_string(r.perFrame.refinements), std::to_string(r.perFrame.stencilEvaluations),
                      std::to_string(r.perFrame.pointUploads), std::to_string(r.perFrame.normalEvaluations),
                      std::to_string(r.perFrame.transformUpdates)});
  }
  return t;
}

void Emit(const Table& table, const Options& opt, const char* suffix) {
  table.Print();
  if (!opt.csvPrefix.empty()) table.WriteCsv(opt.csvPrefix + "_" + suffix + ".csv");
}

// ------------------------------------------------------------------------------------------ main

std::vector<RenderCase> RenderCases(bool quick) {
  if (quick) return {{"ball", BuildBallScene, 64, 48, 4}, {"eye", BuildEyeScene, 48, 48, 4}};
  return {{"ball", BuildBallScene, 320, 240, 16}, {"eye", BuildEyeScene, 160, 160, 8}};
}

void Run(const Options& opt) {
  std::printf("# bench_delegate: hdeye renderer throughput, bare Embree ceiling, per-frame mesh sync\n\n");
  std::printf(
      "%s run; this machine has %u cores (std::thread::hardware_concurrency); \"all threads\" = %d;\n"
      "load average %.2f at the start.\n\n",
      opt.quick ? "--quick" : "default", std::thread::hardware_concurrency(), opt.threads, LoadAverage());

  // 1 and 2: renders, then bare Embree against the ball scene's root scene.
  const std::vector<RenderCase> cases = RenderCases(opt.quick);
  std::vector<RenderResult> results;
  std::vector<RayMix> mixes;
  BareResult bare;
  RenderResult ballResults[2];
  for (const RenderCase& c : cases) {
    Stage stage;
    c.build(stage.scene, c.width, c.height);
    Render(stage, 1, opt.threads);  // warm-up: sync, commit, first touch
    mixes.push_back(CountRayMix(stage, c, opt.threads));
    const RayMix& mix = mixes.back();
    if (mix.closestHit + mix.shadow != mix.reported)
      std::printf("note: %s: counted %lld Embree calls but RenderStats::rays = %lld\n\n", c.name.c_str(),
                  (long long)(mix.closestHit + mix.shadow), (long long)mix.reported);
    const int threadCounts[2] = {1, opt.threads};
    for (int k = 0; k < 2; ++k) {
      results.push_back(MeasureRender(stage, c, threadCounts[k], opt.renderRuns));
      if (c.name == "ball") ballResults[k] = results.back();
    }
    if (c.name == "ball") bare = MeasureBareEmbree(stage, mix, c, opt);
  }

  std::printf("## 1. Renderer throughput (median of %d renders; only the color AOV bound)\n\n", opt.renderRuns);
  Emit(RenderTable(results, mixes, cases), opt, "render");
  std::int64_t nonFinite = 0;
  for (const RenderResult& r : results) nonFinite += r.nonFiniteSamples;
  std::printf(
      "rays: RenderStats::rays, closest-hit (camera and bounce) plus shadow rays; \"shadow rays\" is the\n"
      "share of rtcOccluded1 calls among them, counted in one extra untimed render. Non-finite samples\n"
      "dropped over all timed renders (RenderStats::nonFiniteSamples): %lld.\n\n",
      (long long)nonFinite);

  std::printf("## 2. Ball scene: bare Embree on the delegate's committed root scene (median of %d passes)\n\n",
              opt.bareRuns);
  Emit(EmbreeTable(bare, ballResults, opt.threads), opt, "embree");
  std::printf(
      "The bare batches have the render's ray counts: %lld closest-hit rays (%lld of them camera rays) and\n"
      "%lld shadow rays. Blended = all bare rays / (intersect time + occluded time).\n\n",
      (long long)mixes[0].closestHit, (long long)mixes[0].samples, (long long)mixes[0].shadow);

  std::printf("## 2b. Minimal path tracers on the same BVH (1 thread, timed with each back-to-back pair)\n\n");
  Emit(MinimalTable(bare), opt, "minimal");
  std::printf(
      "The least a path tracer does for this scene's light transport (bench/minimal_path_tracer.h): the\n"
      "render's camera, image, samples and depth, next event estimation of one of the two lights with MIS,\n"
      "one albedo (%.2f) everywhere, flat normals; with the renderer's ZSobol sampler and UsdPreviewSurface\n"
      "BSDF swapped in or not. \"of bare Embree\" and \"renderer / it\" are rays per CPU second, medians over\n"
      "the pairs; what bare Embree reaches is the ceiling, what these reach is how near a path tracer gets.\n\n",
      bench::MinimalScene{}.albedo);

  if (opt.throughputOnly) {
    std::printf("Load average %.2f at the end.\n", LoadAverage());
    return;
  }

  // 3: sync.
  std::vector<SyncResult> sync;
  const int nu = opt.quick ? 32 : 64, nv = opt.quick ? 24 : 48;
  for (int level : {2, 3}) {
    const Torus torus{nu, nv, level};
    MeasureFirstSync(torus, 1);  // warm-up: TBB and Embree's first builds
    sync.push_back(MeasureFirstSync(torus, opt.syncFrames));
    sync.push_back(MeasurePointsOnly(torus, opt.syncFrames));
    sync.push_back(MeasureTopologyChange(torus, opt.syncFrames));
  }
  std::printf(
      "## 3. Per-frame sync of an animated Catmull-Clark torus (medians; RenderIndex::SyncAll + root commit)\n\n");
  Emit(SyncTable(sync), opt, "sync");
  std::printf("Counters: Mesh::Stats() change over one frame. Embree builds use all cores (TBB).\n\n");

  std::printf(
      "Reference, the parts alone (median of %d): OpenSubdiv on the same torus; bare Embree on a triangle\n"
      "mesh of the same size (a grid torus of (%d 2^L) x (%d 2^L) quads, two triangles each).\n\n",
      opt.syncFrames, nu, nv);
  RTCDevice device = rtcNewDevice(nullptr);
  Table reference{{"level", "triangles", "SubdivRefiner build ms", "EvaluatePoints ms", "EvaluateLimit ms",
                   "Embree BVH build ms (new scene)", "Embree refit ms (geometry REFIT, scene LOW + DYNAMIC)"},
                  {}};
  for (int level : {2, 3}) {
    const Torus torus{nu, nv, level};
    const RefinerCost r = MeasureRefiner(torus, opt.syncFrames);
    const BareBuild b = MeasureBareBuild(device, torus, opt.syncFrames);
    reference.rows.push_back({std::to_string(level), std::to_string(b.triangles), Format("%.2f", r.construct * 1e3),
                              Format("%.2f", r.evaluatePoints * 1e3), Format("%.2f", r.evaluateLimit * 1e3),
                              Format("%.2f", b.build * 1e3), Format("%.2f", b.refit * 1e3)});
  }
  rtcReleaseDevice(device);
  Emit(reference, opt, "sync_reference");
  std::printf("Load average %.2f at the end.\n", LoadAverage());
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Run(ParseOptions(argc, argv));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_delegate: %s\n", e.what());
    return 1;
  }
}
