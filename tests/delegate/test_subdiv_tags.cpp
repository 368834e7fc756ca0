// Specification of SubdivRefiner's schemes and subdivision tags (creases, corners, holes, interpolateBoundary,
// faceVaryingLinearInterpolation, triangleSubdivisionRule, loop and bilinear): shapes that can be checked in
// closed form, and agreement with OpenSubdiv's refiner driven directly with the same descriptor and options.
#include "hdeye/prims/subdivRefiner.h"
#include "test_support.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace {

using hdeye::MeshTopology;
using hdeye::SubdivRefiner;
using hdeye::SubdivScheme;
using hdeye::SubdivTags;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

constexpr float kInfinitelySharp = 10.0f;  // USD's (and OpenSubdiv's) infinite sharpness

struct TestMesh {
  MeshTopology topology;
  std::vector<glm::vec3> points;
};

/// The cube [-1, 1]^3, faces counter-clockwise seen from outside.
TestMesh Cube() {
  TestMesh m;
  m.points = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  m.topology.faceVertexCounts = {4, 4, 4, 4, 4, 4};
  m.topology.faceVertexIndices = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 0, 4, 7, 3, 1, 2, 6, 5};
  return m;
}

/// Every edge of the cube as its own crease (two vertices each) of one sharpness.
void CreaseAllEdges(TestMesh* m, float sharpness) {
  const int edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                            {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  SubdivTags& tags = m->topology.subdivTags;
  for (const auto& e : edges) {
    tags.creaseIndices.insert(tags.creaseIndices.end(), {e[0], e[1]});
    tags.creaseLengths.push_back(2);
    tags.creaseSharpnesses.push_back(sharpness);
  }
}

/// The octahedron of unit radius: 8 outward triangles.
TestMesh Octahedron() {
  TestMesh m;
  m.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.topology.faceVertexCounts.assign(8, 3);
  m.topology.faceVertexIndices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return m;
}

/// An open n x n grid of unit quads in z = 0 over [0, n]^2, counter-clockwise seen from +z.
TestMesh Grid(int n) {
  TestMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.points.push_back({float(i), float(j), 0});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      m.topology.faceVertexCounts.push_back(4);
      m.topology.faceVertexIndices.insert(m.topology.faceVertexIndices.end(), {a, a + 1, a + n + 2, a + n + 1});
    }
  return m;
}

std::vector<glm::vec3> Limit(const TestMesh& m, int level) {
  const SubdivRefiner r(m.topology, int(m.points.size()), level);
  std::vector<glm::vec3> positions, normals;
  r.EvaluateLimit(m.points, &positions, &normals);
  return positions;
}

double Linf(const glm::vec3& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

/// The distance from the edge x in [-1, 1], y = z = -1 of the limit point nearest the middle of that edge
/// (the points over x = 0 on the diagonal y = z, the one furthest out).
double EdgeMidpointGap(const std::vector<glm::vec3>& limit) {
  double best = std::numeric_limits<double>::infinity();
  for (const glm::vec3& p : limit)
    if (std::abs(p.x) < 1e-5 && std::abs(p.y - p.z) < 1e-5 && p.y < 0)
      best = std::min(best, std::hypot(double(p.y) + 1, double(p.z) + 1));
  return best;
}

/// Limit positions computed with OpenSubdiv directly: the topology's descriptor built by hand (creases as
/// edge pairs), refined uniformly, interpolated level by level, pushed to the limit.
std::vector<glm::vec3> OpenSubdivLimit(const TestMesh& m, Sdc::SchemeType scheme, const Sdc::Options& options,
                                       const std::vector<int>& creasePairs, const std::vector<float>& creaseWeights,
                                       int level) {
  Far::TopologyDescriptor d;
  d.numVertices = int(m.points.size());
  d.numFaces = int(m.topology.faceVertexCounts.size());
  d.numVertsPerFace = m.topology.faceVertexCounts.data();
  d.vertIndicesPerFace = m.topology.faceVertexIndices.data();
  d.numCreases = int(creaseWeights.size());
  d.creaseVertexIndexPairs = creasePairs.data();
  d.creaseWeights = creaseWeights.data();
  d.numCorners = int(m.topology.subdivTags.cornerIndices.size());
  d.cornerVertexIndices = m.topology.subdivTags.cornerIndices.data();
  d.cornerWeights = m.topology.subdivTags.cornerSharpnesses.data();
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(d, Factory::Options(scheme, options)));
  Far::TopologyRefiner::UniformOptions uniform(level);
  uniform.fullTopologyInLastLevel = true;
  refiner->RefineUniform(uniform);

  struct V {
    glm::vec3 p{0};
    void Clear() { p = glm::vec3(0); }
    void AddWithWeight(const V& v, float w) { p += w * v.p; }
  };
  std::vector<V> current(m.points.size());
  for (std::size_t i = 0; i < m.points.size(); ++i) current[i].p = m.points[i];
  const Far::PrimvarRefiner primvar(*refiner);
  for (int l = 1; l <= level; ++l) {
    std::vector<V> next(std::size_t(refiner->GetLevel(l).GetNumVertices()));
    primvar.Interpolate(l, current, next);
    current.swap(next);
  }
  std::vector<V> limit(current.size());
  primvar.Limit(current, limit);
  std::vector<glm::vec3> out;
  for (const V& v : limit) out.push_back(v.p);
  return out;
}

double MaxDifference(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  REQUIRE(a.size() == b.size());
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, double(glm::length(a[i] - b[i])));
  return worst;
}

std::string ErrorOf(const TestMesh& m, int level) {
  try {
    SubdivRefiner(m.topology, int(m.points.size()), level);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("an infinitely creased cube stays the cube: every limit point on its faces, edge points on its edges") {
  TestMesh m = Cube();
  CreaseAllEdges(&m, kInfinitelySharp);
  const std::vector<glm::vec3> limit = Limit(m, 3);
  double worstOffSurface = 0;
  for (const glm::vec3& p : limit) worstOffSurface = std::max(worstOffSurface, std::abs(Linf(p) - 1));
  const double gap = EdgeMidpointGap(limit);
  INFO("worst |max|coord| - 1| = " << worstOffSurface << ", edge midpoint's distance from the edge " << gap);
  CHECK(worstOffSurface < 1e-6);
  CHECK(gap < 1e-6);
}

TEST_CASE("crease sharpness orders the edges: uncreased rounder than sharpness 2, sharper still at 10") {
  TestMesh smooth = Cube(), sharp2 = Cube(), sharp10 = Cube();
  CreaseAllEdges(&sharp2, 2.0f);
  CreaseAllEdges(&sharp10, kInfinitelySharp);
  const double g0 = EdgeMidpointGap(Limit(smooth, 3)), g2 = EdgeMidpointGap(Limit(sharp2, 3)),
               g10 = EdgeMidpointGap(Limit(sharp10, 3));
  INFO("edge midpoint's distance from the cube's edge: smooth " << g0 << ", sharpness 2 " << g2 << ", 10 " << g10);
  CHECK(g0 > 0.3);
  CHECK(g2 < 0.5 * g0);
  CHECK(g10 < 1e-6);
}

TEST_CASE("a sharp corner keeps its control point, and without the tag the cube's corner is rounded away") {
  TestMesh m = Cube();
  auto nearestToCorner = [](const std::vector<glm::vec3>& limit) {
    double best = std::numeric_limits<double>::infinity();
    for (const glm::vec3& p : limit) best = std::min(best, double(glm::length(p - glm::vec3(1, 1, 1))));
    return best;
  };
  const double without = nearestToCorner(Limit(m, 2));
  m.topology.subdivTags.cornerIndices = {6};
  m.topology.subdivTags.cornerSharpnesses = {kInfinitelySharp};
  const double with = nearestToCorner(Limit(m, 2));
  INFO("nearest limit point to the corner (1, 1, 1): " << without << " untagged, " << with << " tagged");
  CHECK(without > 0.5);
  CHECK(with < 1e-6);
}

TEST_CASE("holes: refined faces of a hole face are not rendered, the others keep their parents") {
  TestMesh m = Cube();
  m.topology.holeIndices = {0, 3};
  const SubdivRefiner r(m.topology, int(m.points.size()), 2);
  CHECK(r.RefinedFaceIndices().size() == 4u * 4 * 16);
  REQUIRE(r.RefinedFaceParents().size() == 4u * 16);
  for (int parent : r.RefinedFaceParents()) CHECK((parent != 0 && parent != 3));
  CHECK(std::count(r.RefinedFaceParents().begin(), r.RefinedFaceParents().end(), 5) == 16);
}

TEST_CASE("interpolateBoundary: edgeAndCorner pins grid corners, edgeOnly rounds them, none drops boundary faces") {
  TestMesh m = Grid(3);
  auto cornerGap = [](const std::vector<glm::vec3>& limit) {
    double best = std::numeric_limits<double>::infinity();
    for (const glm::vec3& p : limit) best = std::min(best, double(glm::length(p)));  // the grid's corner (0, 0, 0)
    return best;
  };
  const SubdivRefiner corner(m.topology, int(m.points.size()), 2);
  std::vector<glm::vec3> pos, nrm;
  corner.EvaluateLimit(m.points, &pos, &nrm);
  const double gapCorner = cornerGap(pos);
  CHECK(corner.RefinedFaceParents().size() == 9u * 16);

  m.topology.subdivTags.interpolateBoundary = SubdivTags::Boundary::EdgeOnly;
  const SubdivRefiner edge(m.topology, int(m.points.size()), 2);
  edge.EvaluateLimit(m.points, &pos, &nrm);
  const double gapEdge = cornerGap(pos);

  m.topology.subdivTags.interpolateBoundary = SubdivTags::Boundary::None;
  const SubdivRefiner none(m.topology, int(m.points.size()), 2);
  INFO("nearest limit point to the grid corner: edgeAndCorner "
       << gapCorner << ", edgeOnly " << gapEdge << "; faces rendered with none " << none.RefinedFaceParents().size());
  CHECK(gapCorner < 1e-6);
  CHECK(gapEdge > 0.1);
  CHECK(none.RefinedFaceParents().size() == 16u);  // only the centre face has no boundary vertex
  for (int parent : none.RefinedFaceParents()) CHECK(parent == 4);
}

TEST_CASE("creases (per crease and per edge), corners and boundary rules match OpenSubdiv driven directly") {
  TestMesh m = Grid(3);
  m.points[5].z = 0.7f, m.points[10].z = -0.4f, m.points[6].z = 0.3f;  // not flat, so creases move points
  SubdivTags& tags = m.topology.subdivTags;
  // A chain 4-5-6-7 (per-edge sharpnesses 0.5, 2, 10) and a crease 1-5 (one sharpness); edge 0-15 is no edge.
  tags.creaseIndices = {4, 5, 6, 7, 1, 5, 0, 15};
  tags.creaseLengths = {4, 2, 2};
  tags.creaseSharpnesses = {0.5f, 2.0f, kInfinitelySharp, 1.5f, 3.0f};
  tags.cornerIndices = {10};
  tags.cornerSharpnesses = {2.5f};
  tags.interpolateBoundary = SubdivTags::Boundary::EdgeOnly;
  Sdc::Options options;
  options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
  const std::vector<int> pairs = {4, 5, 5, 6, 6, 7, 1, 5};
  const std::vector<float> weights = {0.5f, 2.0f, kInfinitelySharp, 1.5f};
  const double worst = MaxDifference(Limit(m, 3), OpenSubdivLimit(m, Sdc::SCHEME_CATMARK, options, pairs, weights, 3));
  INFO("largest difference from OpenSubdiv's own limit points " << worst);
  CHECK(worst < 1e-6);

  // One sharpness per crease: the chain's three edges all at 2.
  tags.creaseSharpnesses = {2.0f, 1.5f, 3.0f};
  const std::vector<float> perCrease = {2.0f, 2.0f, 2.0f, 1.5f};
  CHECK(MaxDifference(Limit(m, 2), OpenSubdivLimit(m, Sdc::SCHEME_CATMARK, options, pairs, perCrease, 2)) < 1e-6);
}

TEST_CASE("triangleSubdivisionRule smooth and the loop scheme match OpenSubdiv driven directly") {
  TestMesh m = Octahedron();
  m.points[4].z = 1.5f;
  Sdc::Options smooth;
  smooth.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
  const double catmark = MaxDifference(Limit(m, 2), OpenSubdivLimit(m, Sdc::SCHEME_CATMARK, Sdc::Options(), {}, {}, 2));
  m.topology.subdivTags.triangleSubdivisionRule = SubdivTags::TriangleRule::Smooth;
  const std::vector<glm::vec3> smoothLimit = Limit(m, 2);
  const double smoothDiff = MaxDifference(smoothLimit, OpenSubdivLimit(m, Sdc::SCHEME_CATMARK, smooth, {}, {}, 2));
  m.topology.subdivTags.triangleSubdivisionRule = SubdivTags::TriangleRule::CatmullClark;
  const double ruleEffect = MaxDifference(smoothLimit, Limit(m, 2));
  m.topology.scheme = SubdivScheme::Loop;
  const double loop = MaxDifference(Limit(m, 2), OpenSubdivLimit(m, Sdc::SCHEME_LOOP, Sdc::Options(), {}, {}, 2));
  INFO("differences from OpenSubdiv: catmark " << catmark << ", smooth rule " << smoothDiff << ", loop " << loop
                                               << "; the smooth rule moves points by " << ruleEffect);
  CHECK(catmark < 1e-6);
  CHECK(smoothDiff < 1e-6);
  CHECK(loop < 1e-6);
  CHECK(ruleEffect > 1e-3);
}

TEST_CASE("the loop scheme refines triangles into triangles (4 per level) with outward limit normals") {
  TestMesh m = Octahedron();
  m.topology.scheme = SubdivScheme::Loop;
  const SubdivRefiner r(m.topology, int(m.points.size()), 3);
  CHECK(r.RefinedFaceSize() == 3);
  CHECK(r.RefinedFaceIndices().size() == 3u * 8 * 64);
  std::vector<glm::vec3> pos, nrm;
  r.EvaluateLimit(m.points, &pos, &nrm);
  double worstRadial = 1;
  for (std::size_t i = 0; i < pos.size(); ++i)
    worstRadial = std::min(worstRadial, double(glm::dot(nrm[i], glm::normalize(pos[i]))));
  INFO("smallest cosine between a limit normal and the radial direction " << worstRadial);
  CHECK(worstRadial > 0.8);
}

TEST_CASE("the bilinear scheme keeps a cube's faces flat, with the faces' normals inside them") {
  TestMesh m = Cube();
  m.topology.scheme = SubdivScheme::Bilinear;
  const SubdivRefiner r(m.topology, int(m.points.size()), 2);
  CHECK(r.RefinedFaceSize() == 4);
  CHECK(r.RefinedFaceParents().size() == 6u * 16);
  std::vector<glm::vec3> pos, nrm;
  r.EvaluateLimit(m.points, &pos, &nrm);
  double worstOff = 0, worstNormal = 0;
  int interior = 0;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    worstOff = std::max(worstOff, std::abs(Linf(pos[i]) - 1));
    // A point inside a face (one coordinate at +-1, the others inside) has that face's normal.
    int axis = -1, onFace = 0;
    for (int k = 0; k < 3; ++k)
      if (std::abs(std::abs(pos[i][k]) - 1) < 1e-6) axis = k, ++onFace;
    if (onFace != 1) continue;
    glm::vec3 n(0);
    n[axis] = pos[i][axis] > 0 ? 1.0f : -1.0f;
    worstNormal = std::max(worstNormal, double(glm::length(nrm[i] - n)));
    ++interior;
  }
  INFO("worst distance off the cube " << worstOff << ", worst normal error inside faces " << worstNormal << " over "
                                      << interior << " points");
  CHECK(worstOff < 1e-6);
  CHECK(interior == 6 * 9);
  CHECK(worstNormal < 1e-5);
}

TEST_CASE("faceVaryingLinearInterpolation all interpolates face-varying values bilinearly, none smooths them") {
  TestMesh m = Grid(2);
  std::vector<float> corners;  // a value per face corner that no subdivision rule reproduces: x^2 + y^3 / 2
  for (int v : m.topology.faceVertexIndices)
    corners.push_back(m.points[v].x * m.points[v].x + 0.5f * m.points[v].y * m.points[v].y * m.points[v].y);
  auto valuesWith = [&](SubdivScheme scheme, SubdivTags::FaceVaryingLinear rule) {
    m.topology.scheme = scheme;
    m.topology.subdivTags.faceVaryingLinearInterpolation = rule;
    return SubdivRefiner(m.topology, int(m.points.size()), 2).EvaluateFaceVarying(corners, 1);
  };
  // The bilinear scheme interpolates any channel bilinearly: the reference for "all".
  const std::vector<float> bilinear = valuesWith(SubdivScheme::Bilinear, SubdivTags::FaceVaryingLinear::All);
  const std::vector<float> all = valuesWith(SubdivScheme::CatmullClark, SubdivTags::FaceVaryingLinear::All);
  const std::vector<float> none = valuesWith(SubdivScheme::CatmullClark, SubdivTags::FaceVaryingLinear::None);
  REQUIRE(all.size() == bilinear.size());
  double allDiff = 0, noneDiff = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    allDiff = std::max(allDiff, double(std::abs(all[i] - bilinear[i])));
    noneDiff = std::max(noneDiff, double(std::abs(none[i] - bilinear[i])));
  }
  INFO("largest difference from bilinear interpolation: all " << allDiff << ", none " << noneDiff);
  CHECK(allDiff < 1e-5);
  CHECK(noneDiff > 0.05);
}

TEST_CASE("malformed subdivision tags are one-line errors naming the tag") {
  auto error = [](auto edit) {
    TestMesh m = Cube();
    edit(m);
    return ErrorOf(m, 1);
  };
  CHECK_THAT(error([](TestMesh& m) {
               m.topology.subdivTags.creaseIndices = {0, 1, 2};
               m.topology.subdivTags.creaseLengths = {2};
               m.topology.subdivTags.creaseSharpnesses = {1};
             }),
             Catch::Contains("creaseLengths add up to 2"));
  CHECK_THAT(error([](TestMesh& m) {
               m.topology.subdivTags.creaseIndices = {0, 1, 2};
               m.topology.subdivTags.creaseLengths = {3};
               m.topology.subdivTags.creaseSharpnesses = {1, 2, 3};
             }),
             Catch::Contains("creaseSharpnesses has 3 values"));
  CHECK_THAT(error([](TestMesh& m) {
               m.topology.subdivTags.creaseIndices = {0, 9};
               m.topology.subdivTags.creaseLengths = {2};
               m.topology.subdivTags.creaseSharpnesses = {1};
             }),
             Catch::Contains("creaseIndices[1] = 9"));
  CHECK_THAT(error([](TestMesh& m) {
               m.topology.subdivTags.creaseIndices = {0, 1};
               m.topology.subdivTags.creaseLengths = {2};
               m.topology.subdivTags.creaseSharpnesses = {std::nanf("")};
             }),
             Catch::Contains("not finite"));
  CHECK_THAT(error([](TestMesh& m) {
               m.topology.subdivTags.cornerIndices = {1, 2};
               m.topology.subdivTags.cornerSharpnesses = {1};
             }),
             Catch::Contains("cornerSharpnesses"));
  CHECK_THAT(error([](TestMesh& m) { m.topology.holeIndices = {6}; }), Catch::Contains("holeIndices[0] = 6"));
  CHECK_THAT(error([](TestMesh& m) { m.topology.scheme = SubdivScheme::Loop; }),
             Catch::Contains("loop scheme needs triangles"));
}
