#pragma once
// Deformed eyes on meshes: the procedural eyeball, the deformations, and the read-back of the
// iris caustic in iris texture space, shared by tests/delegate/test_deformed_eye.cpp and
// bench/bench_deformed_eye.cpp.
//
// Read-back: the iris is textured with (R, G, B) = (u, v, 1) (irisColor white), so the irisMnee AOV of a
// pixel is (sum E u, sum E v, sum E) over its samples: R / B and G / B are the light-weighted mean iris
// texture position the pixel sees and B its iris radiance. Pixels are binned by that (u, v); a bin's
// mean B is the caustic there, whatever the camera, the mesh or the mapping did to get there.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <eyelib/anterior_surface.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace test {

constexpr double kEyePi = 3.14159265358979323846;

/// The EyeballMesh (canonical frame, mm) with its centre, and its deformed points and rest primvar.
struct Eyeball {
  hdeye::MeshTopology topology;
  std::vector<hdeye::Vec3f> points;
  double zCentre = 0;  ///< mm: the back sphere's centre on the axis (the eyeball's centre)

  Eyeball(int rings, int front, int segments, int refineLevel)
      : zCentre(EyeballMesh(rings, front, segments, refineLevel, &topology, &points)) {}

  std::vector<hdeye::Vec3f> Deformed(const std::function<glm::dvec3(const glm::dvec3&)>& f) const {
    std::vector<hdeye::Vec3f> out;
    for (const hdeye::Vec3f& p : points) out.push_back(hdeye::Vec3f(f(glm::dvec3(p))));
    return out;
  }
  hdeye::Primvar Rest() const {
    std::vector<float> values;
    for (const hdeye::Vec3f& p : points) values.insert(values.end(), {p.x, p.y, p.z});
    return hdeye::Primvar{hdeye::Interpolation::Vertex, 3, values};
  }
};

/// A 256 x 256 EXR with (R, G, B) = (u, v, 1) at each texel centre (row 0 at the top: v = 1).
inline const std::string& UvIrisTexture() {
  static const std::string path = [] {
    const std::string p = "/tmp/hdeye_test_iris_uv.exr";
    const int n = 256;
    std::vector<float> r(n * n), g(n * n), b(n * n, 1.0f);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) r[y * n + x] = (x + 0.5f) / n, g[y * n + x] = 1 - (y + 0.5f) / n;
    hdeye::WriteExr(p, n, n, {{"R", r}, {"G", g}, {"B", b}});
    return p;
  }();
  return path;
}

/// An eye mesh seen head-on by a camera on its gaze axis (focal 100 mm on a 36 mm aperture: the image
/// spans +-0.18 x the distance), lit by a small sphere light 0.5 rad off the gaze at 100 mm (2 mm radius). `frame` (a
/// similarity) places the camera and lights, so a scaled eye sees the same scene scaled.
struct DeformedEyeScene : RenderStack {
  int size;

  /// The camera sits at (offset.x, offset.y, distance) in the frame, looking down -z.
  DeformedEyeScene(int size, double distance, const hdeye::Matrix4d& frame = hdeye::Matrix4d(1.0),
                   glm::dvec2 offset = glm::dvec2(0))
      : size(size) {
    const double scale = std::cbrt(glm::determinant(glm::dmat3(frame)));
    hdeye::Matrix4d rotation = frame;
    for (int c = 0; c < 3; ++c) rotation[c] /= scale;
    hdeye::CameraParams lens;
    lens.focalLength = 100;
    lens.verticalAperture = 36;
    lens.nearClip = 1e-3 * scale;
    lens.farClip = 1e4 * scale;
    hdeye::Matrix4d camera = rotation;
    camera[3] = frame * glm::dvec4(offset.x, offset.y, distance, 1);
    scene.AddCamera("/cam", lens, camera);
    AddSphereLight(scene, "/key", float(2 * scale), 400,
                   glm::dvec3(frame * glm::dvec4(100 * std::sin(0.5), 0, 100 * std::cos(0.5), 1)));
    for (const char* b : {"/color", "/iris"}) scene.AddRenderBuffer(b, size, size, b[1] == 'c' ? 4 : 3);
  }
  hdeye::RenderStats Render(int spp, unsigned seed = 0) {
    delegate.Settings().samplesPerPixel = spp;
    delegate.Settings().seed = seed;
    // The sclera's random walk costs 6-10x the whole iris render here and adds nothing to the irisMnee
    // AOV these scenes read: the sclera shades as a diffuse surface.
    delegate.Settings().eyeSwitches.scleraScattering = false;
    for (const char* b : {"/color", "/iris"}) Buffer(b).Clear();
    return pass.Execute("/cam", {{"color", "/color"}, {"irisMnee", "/iris"}});
  }
  /// The colour AOV's RGB, for PNG previews.
  std::vector<float> Rgb() {
    std::vector<float> rgb;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        for (int c = 0; c < 3; ++c) rgb.push_back(float(Buffer("/color").Resolved(x, y, c)));
    return rgb;
  }
  /// The iris radiance (the irisMnee AOV's B channel: the caustic as seen, whatever the iris texture) as grey
  /// RGB over the colour image, for PNG previews: iris pixels show the caustic, the rest the render.
  std::vector<float> CausticRgb() {
    std::vector<float> rgb;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const double b = Buffer("/iris").Resolved(x, y, 2);
        for (int c = 0; c < 3; ++c) rgb.push_back(float(b > 0 ? 0.7 * b : 0.5 * Buffer("/color").Resolved(x, y, c)));
      }
    return rgb;
  }
  /// Pixels the eye covers (colour alpha 1).
  int Coverage() {
    int n = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) n += Buffer("/color").Resolved(x, y, 3) > 0.999;
    return n;
  }
};

/// The iris caustic binned in iris texture space: bins x bins square bins over [0, 1]^2 (the 15.08 mm
/// iris square), each holding the iris radiance of the pixels that see it. A bin's value is their median:
/// MNEE's per-pixel estimates are heavy-tailed near caustic folds, and a mean of a few dozen pixels is
/// then ruled by its brightest one (the mean's seed-to-seed difference did not fall with samples).
struct IrisMap {
  int bins;
  std::vector<std::vector<double>> values;
  explicit IrisMap(int bins) : bins(bins), values(bins * bins) {}
  double Count(int i) const { return double(values[i].size()); }
  double Sum(int i) const {
    double s = 0;
    for (double v : values[i]) s += v;
    return s;
  }
  double Value(int i) const {
    std::vector<double> v = values[i];
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
  double Total() const {
    double s = 0;
    for (int i = 0; i < bins * bins; ++i) s += Sum(i);
    return s;
  }
  /// Canonical position (mm) of bin i's centre.
  glm::dvec2 Centre(int i) const {
    const double d = 15.08;
    return glm::dvec2(((i % bins) + 0.5) / bins - 0.5, ((i / bins) + 0.5) / bins - 0.5) * d;
  }
};

inline IrisMap ReadIris(DeformedEyeScene& s, int bins) {
  IrisMap map(bins);
  for (int y = 0; y < s.size; ++y)
    for (int x = 0; x < s.size; ++x) {
      const double r = s.Buffer("/iris").Resolved(x, y, 0), g = s.Buffer("/iris").Resolved(x, y, 1),
                   b = s.Buffer("/iris").Resolved(x, y, 2);
      if (!(b > 1e-9)) continue;
      const double u = r / b, v = g / b;
      const int i = std::min(bins - 1, std::max(0, int(u * bins))), j = std::min(bins - 1, std::max(0, int(v * bins)));
      map.values[j * bins + i].push_back(b);
    }
  return map;
}

/// How far a caustic departs from a reference, over the bins both see with at least `minCount` pixels
/// whose centres lie in the iris annulus innerMm..outerMm. The default 2.6-4.4 mm keeps clear of the pupil
/// edge and of the outer iris, which a head-on camera sees through the cornea near the limbus: there the
/// limbus blend and the entry angle (which follows the deformed surface) decide how much of a pixel is
/// iris, a view effect, not the caustic (measured separately, docs/deformed_eyes.md).
struct CausticDifference {
  double relativeRms = 0;    ///< sqrt(sum (m - m_ref)^2 / sum m_ref^2) over the bins' (median) radiance
  double centroidShift = 0;  ///< mm: distance between the radiance-weighted centroids of the two
  int bins = 0;              ///< bins compared
};

inline CausticDifference Compare(const IrisMap& a, const IrisMap& ref, double innerMm = 2.6, double outerMm = 4.4,
                                 double minCount = 3) {
  CausticDifference out;
  double num = 0, den = 0, wa = 0, wr = 0;
  glm::dvec2 ca(0), cr(0);
  for (int i = 0; i < ref.bins * ref.bins; ++i) {
    const double radius = glm::length(ref.Centre(i));
    if (radius < innerMm || radius > outerMm || a.Count(i) < minCount || ref.Count(i) < minCount) continue;
    const double ma = a.Value(i), mr = ref.Value(i);
    num += (ma - mr) * (ma - mr), den += mr * mr;
    ca += ma * ref.Centre(i), cr += mr * ref.Centre(i), wa += ma, wr += mr;
    ++out.bins;
  }
  out.relativeRms = den > 0 ? std::sqrt(num / den) : 0;
  out.centroidShift = wa > 0 && wr > 0 ? glm::length(ca / wa - cr / wr) : 0;
  return out;
}

}  // namespace test
