// BasisCurves and Points: the Embree layout of every basis and wrap (segment counts, pinned ends through their
// end points, periodic copies, varying widths), bad input reported by prim, and rendered tubes, ribbons and
// spheres (their depth, normal and material through the AOVs, their shadow on a plane under a dome).
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/basisCurves.h"
#include "hdeye/prims/curveSegments.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"
#include "test_support.h"

#include <catch2/catch.hpp>

using namespace hdeye;
using T = BasisCurvesTopology;

namespace {

T Topology(T::Type type, T::Basis basis, T::Wrap wrap, std::vector<int> counts) {
  T t;
  t.type = type, t.basis = basis, t.wrap = wrap, t.curveVertexCounts = std::move(counts);
  return t;
}

std::vector<Vec3f> Line(int n) {
  std::vector<Vec3f> p;
  for (int i = 0; i < n; ++i) p.push_back({float(i), float(i * i) * 0.1f, 0});
  return p;
}

/// The uniform cubic B-spline segment over four control points at parameter u.
glm::vec3 Bspline(const glm::vec4* v, float u) {
  const float b0 = (1 - u) * (1 - u) * (1 - u) / 6, b1 = (3 * u * u * u - 6 * u * u + 4) / 6,
              b2 = (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6, b3 = u * u * u / 6;
  return glm::vec3(b0 * v[0] + b1 * v[1] + b2 * v[2] + b3 * v[3]);
}

}  // namespace

TEST_CASE("curve segments: counts and first vertices for every basis and wrap") {
  struct Case {
    T topology;
    int points;
    std::vector<unsigned> segments;
    std::size_t vertices;
  };
  const Case cases[] = {
      {Topology(T::Type::Linear, T::Basis::Bezier, T::Wrap::Nonperiodic, {4}), 4, {0, 1, 2}, 4},
      {Topology(T::Type::Linear, T::Basis::Bezier, T::Wrap::Periodic, {4}), 4, {0, 1, 2, 3}, 5},
      {Topology(T::Type::Cubic, T::Basis::Bezier, T::Wrap::Nonperiodic, {7}), 7, {0, 3}, 7},
      {Topology(T::Type::Cubic, T::Basis::Bezier, T::Wrap::Periodic, {6}), 6, {0, 3}, 7},
      {Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {6}), 6, {0, 1, 2}, 6},
      {Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Periodic, {5}), 5, {0, 1, 2, 3, 4}, 8},
      {Topology(T::Type::Cubic, T::Basis::CatmullRom, T::Wrap::Pinned, {5}), 5, {0, 1, 2, 3}, 7},
      {Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {4, 5}), 9, {0, 4, 5}, 9},
  };
  for (const Case& c : cases) {
    const CurveSegments s = BuildCurveSegments(c.topology, Line(c.points), {}, {});
    CHECK(s.segments == c.segments);
    CHECK(s.vertices.size() == c.vertices);
    for (const glm::vec4& v : s.vertices) CHECK(v.w == 0.5f);  // unauthored widths are 1
  }
}

TEST_CASE("segment colours run between the points each segment spans, for every basis and the pinned phantoms") {
  auto colors = [](int n) {  // point i has colour (i, 0, 0)
    std::vector<float> c;
    for (int i = 0; i < n; ++i) c.insert(c.end(), {float(i), 0, 0});
    return c;
  };
  auto starts_and_ends = [&](const T& t, int n) {
    const CurveSegments s = BuildCurveSegments(t, Line(n), {}, {});
    const std::vector<Vec3f> corners = SegmentEndColors(t, s, colors(n));
    REQUIRE(corners.size() == 3 * s.segments.size());
    std::vector<std::pair<float, float>> out;
    for (std::size_t k = 0; k < s.segments.size(); ++k) {
      CHECK(corners[3 * k + 2] == corners[3 * k]);  // (start, end, start): v drops out of the lookup
      out.push_back({corners[3 * k].x, corners[3 * k + 1].x});
    }
    return out;
  };
  using P = std::vector<std::pair<float, float>>;
  CHECK(starts_and_ends(Topology(T::Type::Linear, T::Basis::Bezier, T::Wrap::Nonperiodic, {3}), 3) ==
        P{{0, 1}, {1, 2}});
  CHECK(starts_and_ends(Topology(T::Type::Linear, T::Basis::Bezier, T::Wrap::Periodic, {3}), 3) ==
        P{{0, 1}, {1, 2}, {2, 0}});
  CHECK(starts_and_ends(Topology(T::Type::Cubic, T::Basis::Bezier, T::Wrap::Nonperiodic, {7}), 7) == P{{0, 3}, {3, 6}});
  CHECK(starts_and_ends(Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {5}), 5) ==
        P{{1, 2}, {2, 3}});
  // Pinned: the phantom ends stand for the end points, so the first segment starts at point 0's colour.
  CHECK(starts_and_ends(Topology(T::Type::Cubic, T::Basis::CatmullRom, T::Wrap::Pinned, {4}), 4) ==
        P{{0, 1}, {1, 2}, {2, 3}});
}

TEST_CASE("a pinned bspline curve passes through its end points and a periodic one closes") {
  const std::vector<Vec3f> points = Line(5);
  const CurveSegments pinned =
      BuildCurveSegments(Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Pinned, {5}), points, {}, {});
  const glm::vec3 start = Bspline(&pinned.vertices[pinned.segments.front()], 0.0f);
  const glm::vec3 end = Bspline(&pinned.vertices[pinned.segments.back()], 1.0f);
  INFO("start " << start.x << " " << start.y << ", end " << end.x << " " << end.y);
  CHECK(glm::length(start - points.front()) < 1e-6f);
  CHECK(glm::length(end - points.back()) < 1e-5f);

  const CurveSegments periodic =
      BuildCurveSegments(Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Periodic, {5}), points, {}, {});
  const glm::vec3 last = Bspline(&periodic.vertices[periodic.segments.back()], 1.0f);
  const glm::vec3 first = Bspline(&periodic.vertices[periodic.segments.front()], 0.0f);
  CHECK(glm::length(last - first) < 1e-5f);
}

TEST_CASE("curve widths: constant, per curve, per vertex and varying (spread along the vertices) become radii") {
  const T t = Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {6, 4});
  const std::vector<Vec3f> points = Line(10);
  auto radii = [&](Interpolation i, std::vector<float> w) {
    std::vector<float> r;
    for (const glm::vec4& v : BuildCurveSegments(t, points, Primvar{i, 1, std::move(w)}, {}).vertices) r.push_back(v.w);
    return r;
  };
  CHECK(radii(Interpolation::Constant, {0.2f}) == std::vector<float>(10, 0.1f));
  CHECK(radii(Interpolation::Uniform, {0.2f, 0.4f}) ==
        std::vector<float>{0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.2f, 0.2f, 0.2f, 0.2f});
  // Varying: segments + 1 values per curve (4 and 2), spread evenly over its vertices.
  const std::vector<float> varying = radii(Interpolation::Varying, {0, 0.3f, 0.6f, 0.9f, 1, 2});
  CHECK(varying[0] == Approx(0));
  CHECK(varying[5] == Approx(0.45));
  CHECK(varying[1] == Approx(0.5 * 0.18));  // 1/5 of the way: 0.6 of the first span
  CHECK(varying[6] == Approx(0.5));
  CHECK(varying[9] == Approx(1));
}

TEST_CASE(
    "bad curves are one-line errors: counts, too few vertices, bezier counts, widths sizes, NaN, negative widths") {
  auto error = [](T t, int n, Primvar widths = {}) {
    try {
      BuildCurveSegments(t, Line(n), widths, {});
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const T cubic = Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {5});
  CHECK_THAT(error(cubic, 6), Catch::Contains("add up to 5 but there are 6 points"));
  CHECK_THAT(error(Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Nonperiodic, {3}), 3),
             Catch::Contains("curve 0 has 3 vertices, need at least 4"));
  CHECK_THAT(error(Topology(T::Type::Cubic, T::Basis::Bezier, T::Wrap::Nonperiodic, {5}), 5),
             Catch::Contains("3 k + 1"));
  CHECK_THAT(error(cubic, 5, Primvar{Interpolation::Vertex, 1, {1, 1}}), Catch::Contains("widths needs 5 values"));
  CHECK_THAT(error(cubic, 5, Primvar{Interpolation::Constant, 1, {std::nanf("")}}), Catch::Contains("not finite"));
  CHECK_THAT(error(cubic, 5, Primvar{Interpolation::Constant, 1, {-1}}), Catch::Contains("negative"));
}

namespace {

/// A plane z = 0 (albedo 0.5, Lambert) under a white dome, seen from (0, 0, 5) by 21 x 21 pixels over 4 x 4 units.
struct Scene : test::RenderStack {
  static constexpr int kSize = 21;
  Scene() {
    delegate.Settings().samplesPerPixel = 1;
    MaterialParams grey;
    grey.diffuseColor = {0.5f, 0.5f, 0.5f};
    grey.ior = 1;
    scene.AddMaterial("/grey", grey);
    MaterialParams red = grey;
    red.diffuseColor = {0.8f, 0.1f, 0.1f};
    scene.AddMaterial("/red", red);
    MeshTopology plane;
    plane.faceVertexCounts = {4};
    plane.faceVertexIndices = {0, 1, 2, 3};
    scene.AddMesh("/plane", plane, {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}}, Matrix4d(1.0), "/grey");
    scene.AddLight("/dome", primTypes::kDomeLight, LightParams{});
    CameraParams camera;
    camera.horizontalAperture = camera.verticalAperture = 4.0 * camera.focalLength / 5.0;
    scene.AddCamera("/cam", camera, test::LookDownZ(5));
    for (const char* b : {"/color", "/albedo", "/normal", "/depth"})
      scene.AddRenderBuffer(b, kSize, kSize, b[1] == 'c' ? 4 : b[1] == 'd' ? 1 : 3);
  }
  void Render(int spp) {
    delegate.Settings().samplesPerPixel = spp;
    for (const char* b : {"/color", "/albedo", "/normal", "/depth"}) Buffer(b).Clear();
    pass.Execute("/cam", {{"color", "/color"}, {"albedo", "/albedo"}, {"normal", "/normal"}, {"depth", "/depth"}});
  }
  glm::dvec3 Pixel(const PrimId& b, int x, int y) {
    const RenderBuffer& r = Buffer(b);
    return {r.Resolved(x, y, 0), r.Components() > 1 ? r.Resolved(x, y, 1) : 0,
            r.Components() > 2 ? r.Resolved(x, y, 2) : 0};
  }
};

}  // namespace

TEST_CASE("a round bspline tube renders at its radius with its material, and shadows the plane under the dome") {
  Scene s;
  // A straight tube along x at height 0.4, width 0.6, pinned so it spans its end points.
  s.scene.AddBasisCurves("/hair", Topology(T::Type::Cubic, T::Basis::Bspline, T::Wrap::Pinned, {5}),
                         {{-3, 0, 0.4f}, {-1.5f, 0, 0.4f}, {0, 0, 0.4f}, {1.5f, 0, 0.4f}, {3, 0, 0.4f}}, Matrix4d(1.0),
                         "/red");
  s.scene.SetPrimvar("/hair", "widths", Primvar{Interpolation::Constant, 1, {0.6f}});
  s.Render(256);
  const int c = Scene::kSize / 2;
  const glm::dvec3 albedo = s.Pixel("/albedo", c, c), normal = s.Pixel("/normal", c, c);
  const double depth = s.Pixel("/depth", c, c).x;
  // The plane 0.57 units beside the tube's foot, where the tube hides a quarter of the dome's cosine-weighted
  // light (the 2-D view factor of its cross-section, 0.5 (sin 80.5 deg - sin 29.5 deg) = 0.25), against the plane
  // 1.9 units away (0.03 hidden); each the mean of 7 pixels along the tube, in blue (the tube's albedo 0.1 there, so
  // little of the hidden light comes back off the tube).
  auto rowMean = [&](int y) {
    double sum = 0;
    for (int x = c - 3; x <= c + 3; ++x) sum += s.Pixel("/color", x, y).z;  // blue: the red tube reflects little
    return sum / 7;
  };
  const double nearTube = rowMean(c + 3), farAway = rowMean(0);
  INFO("tube: albedo " << albedo.x << " " << albedo.y << " " << albedo.z << ", normal " << normal.z << ", depth "
                       << depth << "; plane beside it " << nearTube << ", far away " << farAway);
  CHECK(albedo == glm::dvec3(glm::vec3(0.8f, 0.1f, 0.1f)));
  CHECK(depth == Approx(5 - 0.4 - 0.3).margin(1e-3));
  CHECK(normal.z > 0.999);
  // Closed form (1 - 0.247) / (1 - 0.028) = 0.775, less what the tube reflects back; measured 0.782.
  CHECK(nearTube / farAway == Approx(0.775).margin(0.03));
  CHECK(farAway > 0.45);
  CHECK(static_cast<const BasisCurves*>(s.index.GetRprim("/hair"))->SegmentCount() == 4);
}

TEST_CASE("a ribbon faces its normals and a sphere point renders at its width") {
  Scene s;
  // A flat linear ribbon along x at height 1, width 0.8, facing +z; a sphere of diameter 0.6 at (0, 1, 1).
  BasisCurvesTopology linear = Topology(T::Type::Linear, T::Basis::Bezier, T::Wrap::Nonperiodic, {2});
  s.scene.AddBasisCurves("/ribbon", linear, {{-3, 0, 1}, {3, 0, 1}}, Matrix4d(1.0), "/red");
  s.scene.SetPrimvar("/ribbon", "widths", Primvar{Interpolation::Constant, 1, {0.8f}});
  s.scene.SetPrimvar("/ribbon", "normals", Primvar{Interpolation::Constant, 3, {0, 0, 1}});
  s.scene.AddPoints("/dot", {{0, 1, 1}}, Matrix4d(1.0), "/red");
  s.scene.SetPrimvar("/dot", "widths", Primvar{Interpolation::Vertex, 1, {0.6f}});
  s.Render(1);
  const int c = Scene::kSize / 2;
  CHECK(s.Pixel("/depth", c, c).x == Approx(4).margin(1e-3));  // the flat ribbon at z = 1
  CHECK(s.Pixel("/normal", c, c).z > 0.999);
  // Depth is the distance along the camera ray: pixel (c + k, c - j) looks along (k, j, -5) x 4/21 / 5 ...
  auto ray = [](int k, int j) { return glm::normalize(glm::dvec3(k * 4.0 / 21, j * 4.0 / 21, -5)); };
  CHECK(s.Pixel("/depth", c + 2, c).x == Approx(4 / -ray(2, 0).z).margin(1e-4));
  // ... and meets the sphere (centre (0, 1, 1), radius 0.3) at the smaller root.
  const glm::dvec3 d = ray(0, 7), oc = glm::dvec3(0, 0, 5) - glm::dvec3(0, 1, 1);
  const double b = glm::dot(oc, d), expected = -b - std::sqrt(b * b - (glm::dot(oc, oc) - 0.09));
  const double sphereDepth = s.Pixel("/depth", c, c - 7).x;
  INFO("sphere depth " << sphereDepth << ", expected " << expected);
  CHECK(sphereDepth == Approx(expected).margin(1e-3));
}

TEST_CASE("bad curves and points are reported naming the prim") {
  Scene s;
  s.scene.AddBasisCurves("/bad", Topology(T::Type::Cubic, T::Basis::Bezier, T::Wrap::Nonperiodic, {5}), Line(5));
  CHECK_THAT(test::ErrorOf([&] { s.Render(1); }), Catch::Contains("curves /bad: bezier curve 0 has 5 vertices"));
  s.scene.RemovePrim("/bad");
  s.scene.AddPoints("/dots", {{0, 0, 1}});
  s.scene.SetPrimvar("/dots", "widths", Primvar{Interpolation::Vertex, 1, {1, 2}});
  CHECK_THAT(test::ErrorOf([&] { s.Render(1); }), Catch::Contains("points /dots: widths needs 1 values, got 2"));
}
