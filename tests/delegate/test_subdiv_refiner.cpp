// Specification of hdeye::SubdivRefiner: Catmull-Clark counts and shape, exactness of the per-frame
// stencil path, mixed polygons, limit normals, topology errors and affine invariance.
#include "hdeye/prims/subdivRefiner.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <random>

namespace {

using hdeye::MeshTopology;
using hdeye::SubdivRefiner;

struct Mesh {
  MeshTopology topology;
  std::vector<glm::vec3> points;
};

/// The cube [-1, 1]^3, faces counter-clockwise seen from outside.
Mesh Cube() {
  Mesh m;
  m.points = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  m.topology.faceVertexCounts = {4, 4, 4, 4, 4, 4};
  m.topology.faceVertexIndices = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 0, 4, 7, 3, 1, 2, 6, 5};
  return m;
}

/// A closed torus of nu x nv quads, major radius 1, minor radius 0.4, outward faces.
Mesh Torus(int nu, int nv) {
  Mesh m;
  const float twoPi = 6.28318530718f;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float u = twoPi * i / nu, v = twoPi * j / nv, rho = 1.0f + 0.4f * std::cos(v);
      m.points.push_back({rho * std::cos(u), rho * std::sin(u), 0.4f * std::sin(v)});
    }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.topology.faceVertexCounts.push_back(4);
      for (int k : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}) m.topology.faceVertexIndices.push_back(k);
    }
  return m;
}

/// A flat open mesh in z = 0, counter-clockwise seen from +z: triangle (0, 2, 1) below quad (1, 2, 6, 7),
/// pentagon (2, 3, 4, 5, 6) to their right. The triangle and quad share edge 1-2, the quad and pentagon
/// edge 2-6. Points 0, 3, 4, 5 and 7 each belong to one face only.
Mesh TriQuadPentagon() {
  Mesh m;
  m.points = {{0, -1, 0}, {0, 0, 0}, {1, 0, 0}, {2, -0.5f, 0}, {3, 0.5f, 0}, {2, 1.5f, 0}, {1, 1, 0}, {0, 1, 0}};
  m.topology.faceVertexCounts = {3, 4, 5};
  m.topology.faceVertexIndices = {0, 2, 1, /**/ 1, 2, 6, 7, /**/ 2, 3, 4, 5, 6};
  return m;
}

std::vector<glm::vec3> Refined(const SubdivRefiner& r, const std::vector<glm::vec3>& coarse) {
  std::vector<glm::vec3> out;
  r.EvaluatePoints(coarse, &out);
  return out;
}

float MaxDistance(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  REQUIRE(a.size() == b.size());
  float d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, glm::length(a[i] - b[i]));
  return d;
}

/// Distance from p to the nearest point of `set` (brute force; the sets here are small).
float NearestDistance(const glm::vec3& p, const std::vector<glm::vec3>& set) {
  float d = 1e30f;
  for (const glm::vec3& q : set) d = std::min(d, glm::length(p - q));
  return d;
}

std::vector<glm::vec3> Jittered(std::vector<glm::vec3> points, float amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-amount, amount);
  for (glm::vec3& p : points) p += glm::vec3(u(rng), u(rng), u(rng));
  return points;
}

/// Independent reference: OpenSubdiv's level-by-level PrimvarRefiner::Interpolate on a fresh refiner,
/// accumulated in double. It shares no code with SubdivRefiner's stencil path.
struct DoublePoint {
  glm::dvec3 p{0.0};
  void Clear() { p = glm::dvec3(0.0); }
  void AddWithWeight(const DoublePoint& src, float w) { p += double(w) * src.p; }
};

std::vector<glm::vec3> ReferenceRefine(const Mesh& mesh, int level) {
  namespace Far = OpenSubdiv::Far;
  namespace Sdc = OpenSubdiv::Sdc;
  Far::TopologyDescriptor desc;
  desc.numVertices = static_cast<int>(mesh.points.size());
  desc.numFaces = static_cast<int>(mesh.topology.faceVertexCounts.size());
  desc.numVertsPerFace = mesh.topology.faceVertexCounts.data();
  desc.vertIndicesPerFace = mesh.topology.faceVertexIndices.data();
  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
  refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(level));

  std::vector<DoublePoint> src(mesh.points.size());
  for (size_t i = 0; i < src.size(); ++i) src[i].p = glm::dvec3(mesh.points[i]);
  Far::PrimvarRefiner primvar(*refiner);
  for (int l = 1; l <= level; ++l) {
    std::vector<DoublePoint> dst(refiner->GetLevel(l).GetNumVertices());
    primvar.Interpolate(l, src, dst);
    src.swap(dst);
  }
  std::vector<glm::vec3> out;
  for (const DoublePoint& d : src) out.push_back(glm::vec3(d.p));
  return out;
}

/// The message SubdivRefiner's constructor throws for (topology, pointCount, level), or "" if none.
std::string ConstructionError(const MeshTopology& topology, int pointCount, int level = 1) {
  try {
    SubdivRefiner r(topology, pointCount, level);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

template <class F> double SecondsPerCall(int calls, F&& f) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < calls; ++i) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / calls;
}

}  // namespace

TEST_CASE("a refined cube has Catmull-Clark's face and point counts at every level", "[subdiv]") {
  const Mesh cube = Cube();
  for (int level = 1; level <= 4; ++level) {
    const SubdivRefiner r(cube.topology, 8, level);
    const int faces = 6 << (2 * level);  // 6 * 4^L
    INFO("level " << level);
    CHECK(r.Level() == level);
    CHECK(r.RefinedFaceIndices().size() == 4u * faces);
    CHECK(r.RefinedFaceParents().size() == size_t(faces));
    CHECK(r.RefinedPointCount() == faces + 2);  // closed quad mesh of genus 0: V = F + 2 (Euler)
  }
}

TEST_CASE("the cube's limit surface lies in the analytic radius band and keeps the cube's symmetry", "[subdiv]") {
  // Catmull-Clark limit masks on the cube [-1, 1]^3: a corner (valence 3) goes to (1/2, 1/2, 1/2),
  // radius sqrt(3)/2; a face centre (valence 4 after one step) goes to radius 68/81. These are the
  // extremes of the limit surface's distance from the centre.
  const float rMin = 68.0f / 81.0f, rMax = std::sqrt(3.0f) / 2.0f, tol = 1e-5f;
  const Mesh cube = Cube();
  float previousGap = 1e30f;
  for (int level = 1; level <= 4; ++level) {
    const SubdivRefiner r(cube.topology, 8, level);
    std::vector<glm::vec3> limit, normals;
    r.EvaluateLimit(cube.points, &limit, &normals);
    float lo = 1e30f, hi = 0;
    for (const glm::vec3& p : limit) lo = std::min(lo, glm::length(p)), hi = std::max(hi, glm::length(p));
    INFO("level " << level << ": limit radii in [" << lo << ", " << hi << "], band [" << rMin << ", " << rMax << "]");
    CHECK(lo >= rMin - tol);
    CHECK(hi <= rMax + tol);
    CHECK(lo <= rMin + tol);  // the face centres are refined vertices at every level
    CHECK(hi >= rMax - tol);  // and so are the corners

    // Refined points converge to the limit: their gap shrinks by about 4x per level (O(h^2)).
    const float gap = MaxDistance(Refined(r, cube.points), limit);
    INFO("max |refined - limit| = " << gap << ", previous level " << previousGap);
    CHECK(gap < 0.5f * previousGap);
    previousGap = gap;

    // Symmetric: mirror images in each axis plane and the x <-> y swap are again limit points.
    float asymmetry = 0;
    for (const glm::vec3& p : limit)
      for (const glm::vec3& q :
           {glm::vec3(-p.x, p.y, p.z), glm::vec3(p.x, -p.y, p.z), glm::vec3(p.x, p.y, -p.z), glm::vec3(p.y, p.x, p.z)})
        asymmetry = std::max(asymmetry, NearestDistance(q, limit));
    INFO("largest distance from a mirrored limit point to the limit points: " << asymmetry);
    CHECK(asymmetry < tol);
  }
}

TEST_CASE("re-evaluating stencils with moved points equals refining from scratch", "[subdiv]") {
  const Mesh torus = Torus(48, 24);
  const int level = 3;
  const SubdivRefiner refiner(torus.topology, static_cast<int>(torus.points.size()), level);
  for (unsigned frame = 0; frame < 3; ++frame) {
    Mesh moved = torus;
    moved.points = Jittered(torus.points, 0.05f, frame);
    const std::vector<glm::vec3> perFrame = Refined(refiner, moved.points);
    const SubdivRefiner fresh(moved.topology, static_cast<int>(moved.points.size()), level);
    const float vsFresh = MaxDistance(perFrame, Refined(fresh, moved.points));
    const float vsReference = MaxDistance(perFrame, ReferenceRefine(moved, level));
    INFO("frame " << frame << ": max |per-frame - new refiner| = " << vsFresh
                  << ", max |per-frame - level-by-level double reference| = " << vsReference);
    CHECK(vsFresh <= 1e-6f);
    CHECK(vsReference <= 1e-6f);
  }

  // Timing, reported only: the per-frame path against building a refiner and evaluating it.
  const std::vector<glm::vec3> moved = Jittered(torus.points, 0.05f, 7);
  std::vector<glm::vec3> out;
  const double perFrame = SecondsPerCall(50, [&] { refiner.EvaluatePoints(moved, &out); });
  const double rebuild = SecondsPerCall(5, [&] {
    const SubdivRefiner fresh(torus.topology, static_cast<int>(torus.points.size()), level);
    fresh.EvaluatePoints(moved, &out);
  });
  std::cout << "[subdiv] torus " << torus.topology.faceVertexCounts.size() << " quads, level " << level << " ("
            << refiner.RefinedPointCount() << " refined points): stencil evaluation " << perFrame * 1e3
            << " ms, rebuild + evaluation " << rebuild * 1e3 << " ms, ratio " << rebuild / perFrame << "x\n";
}

TEST_CASE("triangles, quads and pentagons refine to quads with the right face parents", "[subdiv]") {
  const Mesh mesh = TriQuadPentagon();
  const std::vector<int>& counts = mesh.topology.faceVertexCounts;
  for (int level = 1; level <= 3; ++level) {
    const SubdivRefiner r(mesh.topology, 8, level);
    INFO("level " << level);
    const std::vector<int>& quads = r.RefinedFaceIndices();
    const std::vector<int>& parents = r.RefinedFaceParents();
    // An n-gon becomes n quads at level 1, each of which becomes 4 per further level.
    const int perLevel = 1 << (2 * (level - 1));
    REQUIRE(quads.size() == 4 * parents.size());
    CHECK(parents.size() == size_t((3 + 4 + 5) * perLevel));
    std::map<int, int> children;
    for (int p : parents) ++children[p];
    for (int f = 0; f < 3; ++f) CHECK(children[f] == counts[f] * perLevel);

    // Every quad has four distinct refined points.
    for (size_t q = 0; q < parents.size(); ++q) {
      std::vector<int> v(quads.begin() + 4 * q, quads.begin() + 4 * q + 4);
      for (int i : v) REQUIRE((i >= 0 && i < r.RefinedPointCount()));
      std::sort(v.begin(), v.end());
      CHECK(std::adjacent_find(v.begin(), v.end()) == v.end());
    }
  }

  // At level 1 every child quad has its parent's face point (the centroid of the parent's corners).
  const SubdivRefiner r(mesh.topology, 8, 1);
  const std::vector<glm::vec3> refined = Refined(r, mesh.points);
  const std::vector<int>& idx = mesh.topology.faceVertexIndices;
  std::vector<glm::vec3> centroids;
  for (int f = 0, start = 0; f < 3; start += counts[f++]) {
    glm::vec3 c(0.0f);
    for (int k = 0; k < counts[f]; ++k) c += mesh.points[idx[start + k]];
    centroids.push_back(c / float(counts[f]));
  }
  for (size_t q = 0; q < r.RefinedFaceParents().size(); ++q) {
    const glm::vec3 centroid = centroids[r.RefinedFaceParents()[q]];
    float nearest = 1e30f;
    for (int k = 0; k < 4; ++k)
      nearest = std::min(nearest, glm::length(refined[r.RefinedFaceIndices()[4 * q + k]] - centroid));
    INFO("refined face " << q << " (parent " << r.RefinedFaceParents()[q] << "): nearest corner is " << nearest
                         << " from the parent's face point");
    CHECK(nearest < 1e-6f);
  }
}

TEST_CASE("boundary corners are interpolated and a flat mesh stays flat (edge-and-corner)", "[subdiv]") {
  const Mesh mesh = TriQuadPentagon();
  const SubdivRefiner r(mesh.topology, 8, 3);
  std::vector<glm::vec3> limit, normals;
  r.EvaluateLimit(mesh.points, &limit, &normals);
  // Points 0, 3, 4, 5, 7 belong to one face only: corners, which edge-and-corner keeps in place.
  for (int corner : {0, 3, 4, 5, 7}) {
    const float d = NearestDistance(mesh.points[corner], limit);
    INFO("coarse corner " << corner << ": nearest limit point at " << d);
    CHECK(d < 1e-6f);
  }
  float maxZ = 0, worstNormal = 0;
  for (size_t i = 0; i < limit.size(); ++i) {
    maxZ = std::max(maxZ, std::abs(limit[i].z));
    worstNormal = std::max(worstNormal, glm::length(normals[i] - glm::vec3(0, 0, 1)));
  }
  INFO("max |z| = " << maxZ << ", max |normal - (0,0,1)| = " << worstNormal);
  CHECK(maxZ < 1e-6f);
  CHECK(worstNormal < 1e-5f);
}

TEST_CASE("limit normals on the cube are unit and point outward", "[subdiv]") {
  const Mesh cube = Cube();
  for (int level = 1; level <= 3; ++level) {
    const SubdivRefiner r(cube.topology, 8, level);
    std::vector<glm::vec3> limit, normals;
    r.EvaluateLimit(cube.points, &limit, &normals);
    REQUIRE(normals.size() == size_t(r.RefinedPointCount()));
    float worstLength = 0, leastOutward = 1, worstOnAxis = 0;
    for (size_t i = 0; i < normals.size(); ++i) {
      const glm::vec3 radial = glm::normalize(limit[i]);
      worstLength = std::max(worstLength, std::abs(glm::length(normals[i]) - 1.0f));
      leastOutward = std::min(leastOutward, glm::dot(normals[i], radial));
      // At the symmetry points (face centres, corners) the normal is the radial direction.
      const glm::vec3 a = glm::abs(limit[i]);
      const bool faceCentre = (a.x < 1e-6f) + (a.y < 1e-6f) + (a.z < 1e-6f) == 2;
      const bool corner = std::abs(a.x - a.y) < 1e-6f && std::abs(a.y - a.z) < 1e-6f;
      if (faceCentre || corner) worstOnAxis = std::max(worstOnAxis, glm::length(normals[i] - radial));
    }
    INFO("level " << level << ": max ||n| - 1| = " << worstLength << ", min n . radial = " << leastOutward
                  << ", max |n - radial| at face centres and corners = " << worstOnAxis);
    CHECK(worstLength < 1e-5f);
    CHECK(leastOutward > 0.99f);
    CHECK(worstOnAxis < 1e-5f);
  }
}

TEST_CASE("bad topology throws a one-line message naming the problem", "[subdiv]") {
  const MeshTopology cube = Cube().topology;
  struct Case {
    const char* what;
    MeshTopology topology;
    int points, level;
    const char* expected;
  };
  MeshTopology twoVertexFace = cube, shortIndices = cube, negative = cube, tooLarge = cube;
  twoVertexFace.faceVertexCounts = {4, 2, 4, 4, 4, 4, 2};
  shortIndices.faceVertexIndices.pop_back();
  negative.faceVertexIndices[5] = -1;
  tooLarge.faceVertexIndices[9] = 8;
  const std::vector<Case> cases = {
      {"no faces", MeshTopology{}, 8, 1, "topology has no faces"},
      {"a face with 2 vertices", twoVertexFace, 8, 1, "face 1 has 2 vertices, need at least 3"},
      {"counts and indices disagree", shortIndices, 8, 1,
       "faceVertexCounts add up to 24 but faceVertexIndices has 23 entries"},
      {"a negative index", negative, 8, 1, "faceVertexIndices[5] = -1 is outside [0, 8)"},
      {"an index past the points", tooLarge, 8, 1, "faceVertexIndices[9] = 8 is outside [0, 8)"},
      {"no points", cube, 0, 1, "coarsePointCount is 0"},
      {"level 0", cube, 8, 0, "level 0 is outside [1, 10]"},
      {"level too deep", cube, 8, 11, "level 11 is outside [1, 10]"},
  };
  for (const Case& c : cases) {
    const std::string message = ConstructionError(c.topology, c.points, c.level);
    INFO(c.what << ": message \"" << message << "\"");
    CHECK_THAT(message, Catch::Contains(c.expected));
    CHECK(message.find('\n') == std::string::npos);
  }

  const SubdivRefiner r(cube, 8, 1);
  std::vector<glm::vec3> out, normals;
  CHECK_THROWS_WITH(r.EvaluatePoints(std::vector<glm::vec3>(7), &out), Catch::Contains("got 7 coarse points"));
  CHECK_THROWS_WITH(r.EvaluateLimit(std::vector<glm::vec3>(9), &out, &normals), Catch::Contains("got 9 coarse points"));
  float buffer[64] = {};
  CHECK_THROWS_WITH(r.EvaluatePrimvar(buffer, 0, buffer), Catch::Contains("primvar width is 0"));
}

TEST_CASE("refinement commutes with translation, rotation and scaling (affine invariance)", "[subdiv]") {
  const Mesh mesh = [] {
    Mesh m = Torus(12, 8);
    m.points = Jittered(m.points, 0.1f, 3);
    return m;
  }();
  const SubdivRefiner r(mesh.topology, static_cast<int>(mesh.points.size()), 2);
  const float angle = 0.7f, scale = 2.5f;
  const glm::mat3 rotation(glm::vec3(std::cos(angle), std::sin(angle), 0),
                           glm::vec3(-std::sin(angle), std::cos(angle), 0), glm::vec3(0, 0, 1));
  const glm::mat3 linear = glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0.3f, 1, 0), glm::vec3(0, 0, 0.5f)) * scale;
  const glm::vec3 offset(10, -4, 2.5f);

  SECTION("refined and limit points of a general affine map are the mapped points") {
    auto map = [&](std::vector<glm::vec3> p) {
      for (glm::vec3& x : p) x = linear * x + offset;
      return p;
    };
    std::vector<glm::vec3> limit, mappedLimit, normals;
    r.EvaluateLimit(mesh.points, &limit, &normals);
    r.EvaluateLimit(map(mesh.points), &mappedLimit, &normals);
    const float refinedError = MaxDistance(Refined(r, map(mesh.points)), map(Refined(r, mesh.points)));
    const float limitError = MaxDistance(mappedLimit, map(limit));
    INFO("max error: refined " << refinedError << ", limit " << limitError << " (coordinates up to ~15)");
    CHECK(refinedError < 1e-5f);
    CHECK(limitError < 1e-5f);
  }

  SECTION("normals of a similarity map are the rotated normals") {
    std::vector<glm::vec3> moved = mesh.points, limit, normals, movedLimit, movedNormals;
    for (glm::vec3& x : moved) x = scale * (rotation * x) + offset;
    r.EvaluateLimit(mesh.points, &limit, &normals);
    r.EvaluateLimit(moved, &movedLimit, &movedNormals);
    for (glm::vec3& n : normals) n = rotation * n;
    const float normalError = MaxDistance(movedNormals, normals);
    // Float tangents lose digits to cancellation at |p| ~ 12 (the offset): about 1e-5 is expected.
    INFO("max |normal(similarity(p)) - rotation * normal(p)| = " << normalError);
    CHECK(normalError < 5e-5f);
  }

  SECTION("a constant primvar of any width stays constant (stencil weights sum to one)") {
    const int width = 5, n = static_cast<int>(mesh.points.size());
    std::vector<float> coarse(size_t(n) * width), refined(size_t(r.RefinedPointCount()) * width);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < width; ++k) coarse[size_t(i) * width + k] = 0.25f * (k + 1);
    r.EvaluatePrimvar(coarse.data(), width, refined.data());
    float worst = 0;
    for (size_t i = 0; i < refined.size(); ++i) worst = std::max(worst, std::abs(refined[i] - 0.25f * (i % width + 1)));
    INFO("max deviation from the constant: " << worst);
    CHECK(worst < 1e-6f);
  }
}

TEST_CASE("a primvar refines component by component like points", "[subdiv]") {
  const Mesh mesh = TriQuadPentagon();
  const SubdivRefiner r(mesh.topology, 8, 2);
  // Width 4: the point in the first three floats, a ramp in the fourth.
  std::vector<float> coarse, refined(size_t(r.RefinedPointCount()) * 4);
  for (int i = 0; i < 8; ++i)
    coarse.insert(coarse.end(), {mesh.points[i].x, mesh.points[i].y, mesh.points[i].z, float(i)});
  r.EvaluatePrimvar(coarse.data(), 4, refined.data());
  const std::vector<glm::vec3> points = Refined(r, mesh.points);
  float worst = 0;
  for (int i = 0; i < r.RefinedPointCount(); ++i)
    worst = std::max(worst, glm::length(glm::vec3(refined[4 * i], refined[4 * i + 1], refined[4 * i + 2]) - points[i]));
  INFO("max |primvar xyz - refined point| = " << worst);
  CHECK(worst == 0.0f);
}
