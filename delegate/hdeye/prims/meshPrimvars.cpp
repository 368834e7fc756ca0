#include "hdeye/prims/meshPrimvars.h"

#include "hdeye/prims/subdivRefiner.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

namespace {

const char* ToString(Interpolation i) {
  switch (i) {
    case Interpolation::Constant: return "constant";
    case Interpolation::Uniform: return "uniform";
    case Interpolation::Vertex: return "vertex";
    case Interpolation::Varying: return "varying";
    case Interpolation::FaceVarying: return "faceVarying";
  }
  return "unknown";
}

std::size_t ElementCount(Interpolation i, const MeshTopology& topology, int pointCount) {
  switch (i) {
    case Interpolation::Constant: return 1;
    case Interpolation::Uniform: return topology.faceVertexCounts.size();
    case Interpolation::Vertex:
    case Interpolation::Varying: return std::size_t(pointCount);
    case Interpolation::FaceVarying: return topology.faceVertexIndices.size();
  }
  return 0;
}

/// Gathers element `index[k]` of `values` (width floats each) for every k.
std::vector<float> Gather(const float* values, int width, const std::vector<int>& index) {
  std::vector<float> out(index.size() * std::size_t(width));
  for (std::size_t k = 0; k < index.size(); ++k)
    for (int c = 0; c < width; ++c) out[k * width + c] = values[std::size_t(index[k]) * width + c];
  return out;
}

}  // namespace

TriangleLayout TriangulateFaces(const std::vector<int>& counts, const std::vector<int>& indices,
                                const std::vector<int>& parents) {
  TriangleLayout layout;
  int base = 0;
  for (std::size_t f = 0; f < counts.size(); ++f) {
    const int n = counts[f];
    for (int k = 1; k + 1 < n; ++k) {
      for (int corner : {base, base + k, base + k + 1}) {
        layout.corners.push_back(corner);
        layout.vertices.push_back(indices[std::size_t(corner)]);
      }
      layout.faces.push_back(parents.empty() ? int(f) : parents[f]);
    }
    base += n;
  }
  return layout;
}

void ValidatePrimvar(const Primvar& primvar, const std::string& name, int components, const MeshTopology& topology,
                     int pointCount) {
  auto fail = [&](const std::string& what) { throw std::runtime_error("primvar " + name + ": " + what); };
  if (primvar.components != components)
    fail("has " + std::to_string(primvar.components) + " components per element, need " + std::to_string(components));
  const std::size_t expected = ElementCount(primvar.interpolation, topology, pointCount);
  if (primvar.values.size() != expected * std::size_t(components)) {
    const std::size_t n = primvar.values.size();
    fail(std::string(ToString(primvar.interpolation)) + " needs " + std::to_string(expected) + " elements, got " +
         (n % std::size_t(components) ? std::to_string(n) + " values" : std::to_string(n / std::size_t(components))));
  }
  for (std::size_t i = 0; i < primvar.values.size(); ++i)
    if (!std::isfinite(primvar.values[i]))
      fail("element " + std::to_string(i / std::size_t(components)) + " is not finite");
}

std::vector<float> PrimvarAtCorners(const Primvar& primvar, const TriangleLayout& layout,
                                    const SubdivRefiner* refiner) {
  const int width = primvar.components;
  const float* values = primvar.values.data();
  switch (primvar.interpolation) {
    case Interpolation::Constant: return Gather(values, width, std::vector<int>(layout.corners.size(), 0));
    case Interpolation::Uniform: {
      std::vector<int> face(layout.corners.size());
      for (std::size_t k = 0; k < face.size(); ++k) face[k] = layout.faces[k / 3];
      return Gather(values, width, face);
    }
    case Interpolation::Vertex:
    case Interpolation::Varying: {
      if (!refiner) return Gather(values, width, layout.vertices);
      // XXX: varying is refined like vertex (smoothly), not bilinearly as OpenSubdiv's varying would.
      std::vector<float> refined(std::size_t(refiner->RefinedPointCount()) * width);
      refiner->EvaluatePrimvar(values, width, refined.data());
      return Gather(refined.data(), width, layout.vertices);
    }
    case Interpolation::FaceVarying: {
      if (!refiner) return Gather(values, width, layout.corners);
      const std::vector<float> refined = refiner->EvaluateFaceVarying(primvar.values, width);
      return Gather(refined.data(), width, layout.corners);
    }
  }
  return {};
}

}  // namespace hdeye
