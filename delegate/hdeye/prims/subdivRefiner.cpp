#include "hdeye/prims/subdivRefiner.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

namespace hdeye {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

[[noreturn]] void Fail(const std::string& what) { throw std::invalid_argument("SubdivRefiner: " + what); }

/// Throws, naming the first thing wrong, unless the creases and corners of `tags` are well formed over
/// `pointCount` points (lengths that add up, indices in range, one finite sharpness per crease, edge or corner).
void ValidateTags(const SubdivTags& tags, int pointCount) {
  auto checkIndex = [&](const char* name, size_t i, int v) {
    if (v < 0 || v >= pointCount)
      Fail(std::string(name) + "[" + std::to_string(i) + "] = " + std::to_string(v) + " is outside [0, " +
           std::to_string(pointCount) + ")");
  };
  long long vertices = 0, edges = 0;
  for (size_t c = 0; c < tags.creaseLengths.size(); ++c) {
    if (tags.creaseLengths[c] < 2)
      Fail("creaseLengths[" + std::to_string(c) + "] = " + std::to_string(tags.creaseLengths[c]) + ", need at least 2");
    vertices += tags.creaseLengths[c];
    edges += tags.creaseLengths[c] - 1;
  }
  if (vertices != static_cast<long long>(tags.creaseIndices.size()))
    Fail("creaseLengths add up to " + std::to_string(vertices) + " but creaseIndices has " +
         std::to_string(tags.creaseIndices.size()) + " entries");
  for (size_t i = 0; i < tags.creaseIndices.size(); ++i) checkIndex("creaseIndices", i, tags.creaseIndices[i]);
  const size_t sharpnesses = tags.creaseSharpnesses.size();
  if (!tags.creaseLengths.empty() && sharpnesses != tags.creaseLengths.size() &&
      sharpnesses != static_cast<size_t>(edges))
    Fail("creaseSharpnesses has " + std::to_string(sharpnesses) + " values, need one per crease (" +
         std::to_string(tags.creaseLengths.size()) + ") or per crease edge (" + std::to_string(edges) + ")");
  if (tags.cornerIndices.size() != tags.cornerSharpnesses.size())
    Fail("cornerIndices has " + std::to_string(tags.cornerIndices.size()) + " entries but cornerSharpnesses " +
         std::to_string(tags.cornerSharpnesses.size()));
  for (size_t i = 0; i < tags.cornerIndices.size(); ++i) checkIndex("cornerIndices", i, tags.cornerIndices[i]);
  for (float w : tags.creaseSharpnesses)
    if (!std::isfinite(w)) Fail("creaseSharpnesses holds a value that is not finite");
  for (float w : tags.cornerSharpnesses)
    if (!std::isfinite(w)) Fail("cornerSharpnesses holds a value that is not finite");
}

/// Throws, naming the first thing wrong, unless `topology` is a polygon mesh over `pointCount` points.
void ValidateTopology(const MeshTopology& topology, int pointCount) {
  if (topology.faceVertexCounts.empty()) Fail("topology has no faces");
  if (pointCount < 1) Fail("coarsePointCount is " + std::to_string(pointCount) + ", need at least 1");
  long long total = 0;
  for (size_t f = 0; f < topology.faceVertexCounts.size(); ++f) {
    const int n = topology.faceVertexCounts[f];
    if (n < 3) Fail("face " + std::to_string(f) + " has " + std::to_string(n) + " vertices, need at least 3");
    total += n;
  }
  if (total != static_cast<long long>(topology.faceVertexIndices.size()))
    Fail("faceVertexCounts add up to " + std::to_string(total) + " but faceVertexIndices has " +
         std::to_string(topology.faceVertexIndices.size()) + " entries");
  for (size_t i = 0; i < topology.faceVertexIndices.size(); ++i) {
    const int v = topology.faceVertexIndices[i];
    if (v < 0 || v >= pointCount)
      Fail("faceVertexIndices[" + std::to_string(i) + "] = " + std::to_string(v) + " is outside [0, " +
           std::to_string(pointCount) + ")");
  }
  const int faces = static_cast<int>(topology.faceVertexCounts.size());
  for (size_t i = 0; i < topology.holeIndices.size(); ++i) {
    const int h = topology.holeIndices[i];
    if (h < 0 || h >= faces)
      Fail("holeIndices[" + std::to_string(i) + "] = " + std::to_string(h) + " is outside the " +
           std::to_string(faces) + " faces");
  }
  if (topology.scheme == SubdivScheme::Loop)
    for (size_t f = 0; f < topology.faceVertexCounts.size(); ++f)
      if (topology.faceVertexCounts[f] != 3)
        Fail("the loop scheme needs triangles, face " + std::to_string(f) + " has " +
             std::to_string(topology.faceVertexCounts[f]) + " vertices");
  ValidateTags(topology.subdivTags, pointCount);
}

/// The sharp edges of `tags` as vertex pairs with one sharpness each (USD's creases: chains of creaseLengths[i]
/// vertices, sharpness per crease or per edge), keeping only pairs that are edges of `topology`: USD assets
/// carry creases over edges a modelling edit removed, and Hydra ignores them too.
void CreaseEdges(const MeshTopology& topology, std::vector<Far::Index>* pairs, std::vector<float>* weights) {
  const SubdivTags& tags = topology.subdivTags;
  std::set<std::pair<int, int>> edges;
  size_t base = 0;
  for (int n : topology.faceVertexCounts) {
    for (int k = 0; k < n; ++k) {
      const int a = topology.faceVertexIndices[base + k], b = topology.faceVertexIndices[base + (k + 1) % n];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
    base += static_cast<size_t>(n);
  }
  const bool perCrease = tags.creaseSharpnesses.size() == tags.creaseLengths.size();
  size_t vertex = 0, edge = 0;
  for (size_t c = 0; c < tags.creaseLengths.size(); ++c) {
    for (int k = 0; k + 1 < tags.creaseLengths[c]; ++k, ++edge) {
      const int a = tags.creaseIndices[vertex + k], b = tags.creaseIndices[vertex + k + 1];
      if (!edges.count({std::min(a, b), std::max(a, b)})) continue;
      pairs->push_back(a);
      pairs->push_back(b);
      weights->push_back(tags.creaseSharpnesses[perCrease ? c : edge]);
    }
    vertex += static_cast<size_t>(tags.creaseLengths[c]);
  }
}

Sdc::Options ToSdcOptions(const SubdivTags& tags) {
  Sdc::Options options;
  using B = SubdivTags::Boundary;
  options.SetVtxBoundaryInterpolation(tags.interpolateBoundary == B::None ? Sdc::Options::VTX_BOUNDARY_NONE
                                      : tags.interpolateBoundary == B::EdgeOnly
                                          ? Sdc::Options::VTX_BOUNDARY_EDGE_ONLY
                                          : Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using F = SubdivTags::FaceVaryingLinear;
  switch (tags.faceVaryingLinearInterpolation) {
    case F::None: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_NONE); break;
    case F::CornersOnly: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_ONLY); break;
    case F::CornersPlus1: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1); break;
    case F::CornersPlus2: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_PLUS2); break;
    case F::Boundaries: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_BOUNDARIES); break;
    case F::All: options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL); break;
  }
  options.SetTriangleSubdivision(tags.triangleSubdivisionRule == SubdivTags::TriangleRule::Smooth
                                     ? Sdc::Options::TRI_SUB_SMOOTH
                                     : Sdc::Options::TRI_SUB_CATMARK);
  return options;
}

Sdc::SchemeType ToSdcScheme(SubdivScheme scheme) {
  switch (scheme) {
    case SubdivScheme::Loop: return Sdc::SCHEME_LOOP;
    case SubdivScheme::Bilinear: return Sdc::SCHEME_BILINEAR;
    case SubdivScheme::CatmullClark: break;
  }
  return Sdc::SCHEME_CATMARK;
}

/// The validated topology under its scheme and tags (creases, corners, holes, boundary and face-varying rules),
/// refined uniformly to `level` with the full topology of the last level kept (PrimvarRefiner::Limit needs its
/// vertex neighbourhoods). With `fvar` set, the topology also carries that face-varying channel (channel 0).
std::unique_ptr<const Far::TopologyRefiner> RefineUniformly(const MeshTopology& topology, int pointCount, int level,
                                                            const Far::TopologyDescriptor::FVarChannel* fvar) {
  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = pointCount;
  descriptor.numFaces = static_cast<int>(topology.faceVertexCounts.size());
  descriptor.numVertsPerFace = topology.faceVertexCounts.data();
  descriptor.vertIndicesPerFace = topology.faceVertexIndices.data();
  std::vector<Far::Index> creasePairs;
  std::vector<float> creaseWeights;
  CreaseEdges(topology, &creasePairs, &creaseWeights);
  descriptor.numCreases = static_cast<int>(creaseWeights.size());
  descriptor.creaseVertexIndexPairs = creasePairs.data();
  descriptor.creaseWeights = creaseWeights.data();
  const SubdivTags& tags = topology.subdivTags;
  descriptor.numCorners = static_cast<int>(tags.cornerIndices.size());
  descriptor.cornerVertexIndices = tags.cornerIndices.data();
  descriptor.cornerWeights = tags.cornerSharpnesses.data();
  descriptor.numHoles = static_cast<int>(topology.holeIndices.size());
  descriptor.holeIndices = topology.holeIndices.data();
  if (fvar) {
    descriptor.numFVarChannels = 1;
    descriptor.fvarChannels = fvar;
  }

  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(descriptor, Factory::Options(ToSdcScheme(topology.scheme), ToSdcOptions(topology.subdivTags))));
  if (!refiner) Fail("OpenSubdiv rejected the topology");

  Far::TopologyRefiner::UniformOptions options(level);
  options.fullTopologyInLastLevel = true;
  refiner->RefineUniform(options);
  return refiner;
}

/// Stencils from the coarse points to the points of the last level only.
std::unique_ptr<const Far::StencilTable> LastLevelStencils(const Far::TopologyRefiner& refiner) {
  Far::StencilTableFactory::Options options;
  options.generateIntermediateLevels = false;
  options.generateControlVerts = false;
  options.generateOffsets = true;
  options.maxLevel = refiner.GetMaxLevel();
  return std::unique_ptr<const Far::StencilTable>(Far::StencilTableFactory::Create(refiner, options));
}

/// Write-through view of a glm::vec3 array in the shape PrimvarRefiner::Limit writes to: element i is
/// a proxy with Clear() and AddWithWeight(point, weight).
class Vec3Sink {
 public:
  struct Element {
    glm::vec3& value;
    void Clear() { value = glm::vec3(0.0f); }
    void AddWithWeight(const glm::vec3& point, float weight) { value += weight * point; }
  };
  explicit Vec3Sink(std::vector<glm::vec3>& values) : _values(values.data()) {}
  Element operator[](int i) const { return Element{_values[i]}; }

 private:
  glm::vec3* _values;
};

/// A run-time-width view of a float array in the shape PrimvarRefiner reads and writes: element i is
/// a proxy over floats [i * width, (i + 1) * width).
class FloatsView {
 public:
  struct Element {
    float* value;
    int width;
    void Clear() { std::fill(value, value + width, 0.0f); }
    void AddWithWeight(const Element& src, float weight) {
      for (int k = 0; k < width; ++k) value[k] += weight * src.value[k];
    }
  };
  FloatsView(float* data, int width) : _data(data), _width(width) {}
  Element operator[](int i) const { return Element{_data + static_cast<size_t>(i) * _width, _width}; }

 private:
  float* _data;
  int _width;
};

void CheckCoarseSize(size_t got, int expected) {
  if (got != static_cast<size_t>(expected))
    Fail("got " + std::to_string(got) + " coarse points, the topology has " + std::to_string(expected));
}

}  // namespace

SubdivRefiner::SubdivRefiner(const MeshTopology& coarse, int coarsePointCount, int level)
    : _level(level), _coarse(coarse), _coarsePointCount(coarsePointCount) {
  if (level < 1 || level > kMaxLevel)
    Fail("level " + std::to_string(level) + " is outside [1, " + std::to_string(kMaxLevel) + "]");
  ValidateTopology(coarse, coarsePointCount);
  _refiner = RefineUniformly(coarse, coarsePointCount, level, nullptr);
  _stencils = LastLevelStencils(*_refiner);
  _refinedPointCount = _refiner->GetLevel(level).GetNumVertices();
  BuildRefinedFaces();
}

SubdivRefiner::~SubdivRefiner() = default;
SubdivRefiner::SubdivRefiner(SubdivRefiner&&) noexcept = default;
SubdivRefiner& SubdivRefiner::operator=(SubdivRefiner&&) noexcept = default;

void SubdivRefiner::BuildRefinedFaces() {
  // Parents are composed level by level: a face of level l lies in face parents[l-1][its parent].
  std::vector<int> parents;
  for (int l = 1; l <= _level; ++l) {
    const Far::TopologyLevel& fine = _refiner->GetLevel(l);
    std::vector<int> next(fine.GetNumFaces());
    for (int f = 0; f < fine.GetNumFaces(); ++f) {
      const int parent = fine.GetFaceParentFace(f);
      next[f] = l == 1 ? parent : parents[parent];
    }
    parents.swap(next);
  }
  _faceParents = std::move(parents);

  // Holes (authored, or the boundary faces interpolateBoundary "none" drops) are refined but not rendered.
  const Far::TopologyLevel& last = _refiner->GetLevel(_level);
  _faceSize = _coarse.scheme == SubdivScheme::Loop ? 3 : 4;
  std::vector<int> kept;
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    if (last.IsFaceHole(f)) continue;
    const Far::ConstIndexArray verts = last.GetFaceVertices(f);
    assert(verts.size() == _faceSize && "uniform refinement makes every face a quad (a triangle for loop)");
    _renderedFaces.push_back(f);
    kept.push_back(_faceParents[static_cast<size_t>(f)]);
    for (int k = 0; k < _faceSize; ++k) _faceIndices.push_back(verts[k]);
  }
  _faceParents = std::move(kept);
}

void SubdivRefiner::EvaluatePoints(const std::vector<glm::vec3>& coarse, std::vector<glm::vec3>* refined) const {
  CheckCoarseSize(coarse.size(), _coarsePointCount);
  refined->resize(_refinedPointCount);
  EvaluatePrimvar(&coarse.data()->x, 3, &refined->data()->x);
}

void SubdivRefiner::EvaluatePrimvar(const float* coarse, int width, float* refined) const {
  if (width < 1) Fail("primvar width is " + std::to_string(width) + ", need at least 1");
  if (!coarse || !refined) Fail("null primvar buffer");
  // The loop StencilTable::UpdateValues runs, but over `width` floats chosen at run time.
  const std::vector<int>& sizes = _stencils->GetSizes();
  const std::vector<Far::Index>& indices = _stencils->GetControlIndices();
  const std::vector<float>& weights = _stencils->GetWeights();
  size_t entry = 0;
  for (size_t s = 0; s < sizes.size(); ++s) {
    float* out = refined + s * width;
    std::fill(out, out + width, 0.0f);
    for (int j = 0; j < sizes[s]; ++j, ++entry) {
      const float* in = coarse + static_cast<size_t>(indices[entry]) * width;
      for (int k = 0; k < width; ++k) out[k] += weights[entry] * in[k];
    }
  }
}

void SubdivRefiner::EvaluateLimit(const std::vector<glm::vec3>& coarse, std::vector<glm::vec3>* positions,
                                  std::vector<glm::vec3>* normals) const {
  std::vector<glm::vec3> refined, tangentU(_refinedPointCount), tangentV(_refinedPointCount);
  EvaluatePoints(coarse, &refined);
  positions->resize(_refinedPointCount);
  Vec3Sink positionSink(*positions), uSink(tangentU), vSink(tangentV);
  Far::PrimvarRefiner(*_refiner).Limit(refined, positionSink, uSink, vSink);

  normals->resize(_refinedPointCount);
  for (int i = 0; i < _refinedPointCount; ++i) {
    const glm::vec3 n = glm::cross(tangentU[i], tangentV[i]);
    const float length = glm::length(n);
    (*normals)[i] = length > 0.0f ? n / length : glm::vec3(0.0f);
  }
}

std::vector<float> SubdivRefiner::EvaluateFaceVarying(const std::vector<float>& coarseCornerValues, int width) const {
  if (width < 1) Fail("face-varying width is " + std::to_string(width) + ", need at least 1");
  const size_t corners = _coarse.faceVertexIndices.size();
  if (coarseCornerValues.size() != corners * static_cast<size_t>(width))
    Fail("got " + std::to_string(coarseCornerValues.size()) + " face-varying floats, need " + std::to_string(corners) +
         " corners x " + std::to_string(width));

  // Rebuild the value indices the scene delegate expanded: per point, equal values share an index.
  std::vector<float> values;
  std::vector<Far::Index> valueIndices(corners);
  std::vector<std::vector<int>> valuesAtPoint(static_cast<size_t>(_coarsePointCount));
  for (size_t c = 0; c < corners; ++c) {
    const float* value = &coarseCornerValues[c * width];
    std::vector<int>& candidates = valuesAtPoint[static_cast<size_t>(_coarse.faceVertexIndices[c])];
    int found = -1;
    for (int candidate : candidates)
      if (std::equal(value, value + width, &values[static_cast<size_t>(candidate) * width])) found = candidate;
    if (found < 0) {
      found = static_cast<int>(values.size() / width);
      values.insert(values.end(), value, value + width);
      candidates.push_back(found);
    }
    valueIndices[c] = found;
  }

  Far::TopologyDescriptor::FVarChannel channel;
  channel.numValues = static_cast<int>(values.size() / width);
  channel.valueIndices = valueIndices.data();
  const std::unique_ptr<const Far::TopologyRefiner> refiner =
      RefineUniformly(_coarse, _coarsePointCount, _level, &channel);

  // Level by level (each level's values from the previous one), then the last level to the limit.
  std::vector<float> current = std::move(values);
  const Far::PrimvarRefiner primvarRefiner(*refiner);
  for (int l = 1; l <= _level; ++l) {
    std::vector<float> next(static_cast<size_t>(refiner->GetLevel(l).GetNumFVarValues(0)) * width);
    FloatsView src(current.data(), width), dst(next.data(), width);
    primvarRefiner.InterpolateFaceVarying(l, src, dst, 0);
    current.swap(next);
  }
  std::vector<float> limit(current.size());
  {
    FloatsView src(current.data(), width), dst(limit.data(), width);
    primvarRefiner.LimitFaceVarying(src, dst, 0);
  }

  const Far::TopologyLevel& last = refiner->GetLevel(_level);
  if (last.GetNumFaces() != _refiner->GetLevel(_level).GetNumFaces())
    Fail("face-varying refinement produced a different face count");  // same topology: cannot happen
  std::vector<float> out(_faceIndices.size() * width);
  for (size_t r = 0; r < _renderedFaces.size(); ++r) {
    const Far::ConstIndexArray fv = last.GetFaceFVarValues(_renderedFaces[r], 0);
    for (int k = 0; k < _faceSize; ++k)
      std::copy_n(&limit[static_cast<size_t>(fv[k]) * width], width, &out[(r * _faceSize + k) * width]);
  }
  return out;
}

}  // namespace hdeye
