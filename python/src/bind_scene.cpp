// The scene side: the render index (prims, dirty bits, render buffers' pixels and raw state) and the scene store
// (InMemorySceneDelegate) Python's USD scene delegate pushes a stage into. Points, indices and primvars are taken as
// C-contiguous buffers (numpy arrays, or pxr Vt arrays through the buffer protocol) and copied once, into the store.
#include "bindings.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <stdexcept>

namespace hdeye::python {

namespace {

std::vector<Vec3f> ToPoints(const Points& a) {
  const auto* p = reinterpret_cast<const Vec3f*>(a.data());
  return {p, p + a.shape(0)};
}

std::vector<int> ToInts(const Indices& a) { return {a.data(), a.data() + a.shape(0)}; }

using Matrices = InArray<double, nb::shape<-1, 4, 4>>;

/// n 4x4 float64 matrices in USD's layout (as ToMatrix, each).
std::vector<Matrix4d> ToMatrices(const Matrices& a) {
  std::vector<Matrix4d> out(a.shape(0));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::make_mat4(a.data() + 16 * i);
  return out;
}

std::vector<Vec3f> ToColors(const std::optional<Points>& a) { return a ? ToPoints(*a) : std::vector<Vec3f>{}; }

MeshTopology ToTopology(const Indices& counts, const Indices& indices, int refineLevel, bool leftHanded) {
  MeshTopology t;
  t.faceVertexCounts = ToInts(counts);
  t.faceVertexIndices = ToInts(indices);
  t.refineLevel = refineLevel;
  t.leftHanded = leftHanded;
  return t;
}

std::vector<float> ToFloats(const InArray<float, nb::ndim<1>>& a) { return {a.data(), a.data() + a.shape(0)}; }

/// A UsdGeom token as the enumerator at the same position in `names`; std::invalid_argument names the choices.
template <class E, std::size_t N>
E FromToken(const std::string& what, const std::string& token, const char* const (&names)[N]) {
  std::string choices;
  for (std::size_t i = 0; i < N; ++i) {
    if (token == names[i]) return E(i);
    choices += (i ? ", " : "") + std::string(names[i]);
  }
  throw std::invalid_argument(what + " '" + token + "' is not one of " + choices);
}

Interpolation ToInterpolation(const std::string& name) {
  if (name == "constant") return Interpolation::Constant;
  if (name == "uniform") return Interpolation::Uniform;
  if (name == "vertex") return Interpolation::Vertex;
  if (name == "varying") return Interpolation::Varying;
  if (name == "faceVarying") return Interpolation::FaceVarying;
  throw std::invalid_argument("unknown primvar interpolation '" + name + "'");
}

/// A render buffer's resolved pixels as a new float32 array of shape (height, width, components).
nb::ndarray<nb::numpy, float, nb::ndim<3>> Resolved(const RenderBuffer& buffer) {
  const std::size_t w = std::size_t(buffer.Width()), h = std::size_t(buffer.Height()),
                    c = std::size_t(buffer.Components());
  auto* data = new float[w * h * c];
  const auto planes = buffer.ResolvedPlanes();
  for (std::size_t p = 0; p < w * h; ++p)
    for (std::size_t k = 0; k < c; ++k) data[p * c + k] = planes[k][p];
  nb::capsule owner(data, [](void* d) noexcept { delete[] static_cast<float*>(d); });
  return nb::ndarray<nb::numpy, float, nb::ndim<3>>(data, {h, w, c}, owner);
}

/// A copy of `values` as a new numpy array of the given shape.
template <class T>
nb::ndarray<nb::numpy, T> CopyToNumpy(const std::vector<T>& values, std::initializer_list<std::size_t> shape) {
  auto* data = new T[values.size()];
  std::copy(values.begin(), values.end(), data);
  nb::capsule owner(data, [](void* d) noexcept { delete[] static_cast<T*>(d); });
  return nb::ndarray<nb::numpy, T>(data, shape, owner);
}

RenderBuffer& BufferOf(RenderIndex& index, const PrimId& id) {
  auto* buffer = dynamic_cast<RenderBuffer*>(index.GetBprim(id));
  if (!buffer) throw std::invalid_argument("no render buffer " + id);
  return *buffer;
}

using IndexClass = nb::class_<RenderIndex>;
using StoreClass = nb::class_<InMemorySceneDelegate>;

/// The render index's prims: syncing them, their ids and dirty bits, what meshes and instancers did.
void BindIndexPrims(IndexClass& c) {
  c.def(nb::init<RenderDelegate*>(), nb::keep_alive<1, 2>())
      .def("sync_all", &RenderIndex::SyncAll)
      .def("rprim_ids",
           [](const RenderIndex& index) {
             std::vector<std::string> ids;
             for (const auto& [id, entry] : index.Rprims()) ids.push_back(id);
             return ids;
           })
      .def("sprim_ids",
           [](const RenderIndex& index) {
             std::vector<std::string> ids;
             for (const auto& [id, entry] : index.Sprims()) ids.push_back(id);
             return ids;
           })
      .def("dirty_bits", [](RenderIndex& index, const PrimId& id) { return index.GetChangeTracker().GetDirtyBits(id); })
      .def(
          "mesh_stats",
          [](const RenderIndex& index, const PrimId& id) {
            const auto* mesh = dynamic_cast<const Mesh*>(index.GetRprim(id));
            if (!mesh) throw std::invalid_argument("no mesh " + id);
            const MeshSyncStats& s = mesh->Stats();
            nb::dict d;
            d["topology_builds"] = s.topologyBuilds, d["refinements"] = s.refinements;
            d["stencil_evaluations"] = s.stencilEvaluations, d["point_uploads"] = s.pointUploads;
            d["normal_evaluations"] = s.normalEvaluations, d["transform_updates"] = s.transformUpdates;
            d["triangles"] = mesh->TriangleCount();
            d["refine_level"] = mesh->RefineLevel(), d["refine_level_changes"] = s.refineLevelChanges;
            d["instance_syncs"] = s.instanceSyncs, d["instances_drawn"] = s.instancesDrawn;
            return d;
          },
          "What a mesh's syncs did, counted (topology builds, refinements, stencil evaluations, ...).")
      .def(
          "mesh_points",
          [](const RenderIndex& index, const PrimId& id) {
            const auto* mesh = dynamic_cast<const Mesh*>(index.GetRprim(id));
            if (!mesh) throw std::invalid_argument("no mesh " + id);
            std::vector<float> flat;
            for (const Vec3f& p : mesh->Points()) flat.insert(flat.end(), {p.x, p.y, p.z});
            return CopyToNumpy(flat, {mesh->Points().size(), 3});
          },
          "A mesh's rendered points (limit positions if subdivided), object space, float32 (n, 3).")
      .def(
          "instancer_sync_count",
          [](const RenderIndex& index, const PrimId& id) {
            const Instancer* instancer = index.GetInstancer(id);
            if (!instancer) throw std::invalid_argument("no instancer " + id);
            return instancer->SyncCount();
          },
          "How many times an instancer was synced.");
}

/// The render index's buffers: resolved pixels, clearing and merging, and the raw state farm workers exchange.
void BindIndexBuffers(IndexClass& c) {
  c.def(
       "resolved", [](RenderIndex& index, const PrimId& id) { return Resolved(BufferOf(index, id)); },
       "A render buffer's per-pixel means, float32 (height, width, components).")
      .def("clear_buffer", [](RenderIndex& index, const PrimId& id) { BufferOf(index, id).Clear(); })
      .def("merge_buffer", [](RenderIndex& index, const PrimId& into, RenderIndex& other,
                              const PrimId& from) { BufferOf(index, into).Merge(BufferOf(other, from)); })
      .def(
          "buffer_state",
          [](RenderIndex& index, const PrimId& id) {
            const RenderBuffer& b = BufferOf(index, id);
            const std::size_t h = std::size_t(b.Height()), w = std::size_t(b.Width()), c = std::size_t(b.Components());
            return nb::make_tuple(CopyToNumpy(b.Sums(), {h, w, c}), CopyToNumpy(b.Counts(), {h, w}));
          },
          "A render buffer's raw state: (sums float64 (height, width, components), counts float64 (height, width)).")
      .def(
          "add_buffer_state",
          [](RenderIndex& index, const PrimId& id, const InArray<double, nb::ndim<3>>& sums,
             const InArray<double, nb::ndim<2>>& counts) {
            BufferOf(index, id).AddState({sums.data(), sums.data() + sums.size()},
                                         {counts.data(), counts.data() + counts.size()});
          },
          "Adds a state from buffer_state (of a render of other samples of the same frame): exact merging.");
}

/// The scene store's geometry: meshes, instancers, eye meshes, curves and points.
void BindStoreGeometry(StoreClass& c) {
  c.def(nb::init<RenderIndex*>(), nb::keep_alive<1, 2>())
      .def(
          "add_mesh",
          [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Indices& indices,
             const Points& points, const Matrix& transform, const PrimId& material, int refineLevel, bool leftHanded,
             const PrimId& instancer) {
            s.AddMesh(id, ToTopology(counts, indices, refineLevel, leftHanded), ToPoints(points), ToMatrix(transform),
                      material, instancer);
          },
          nb::arg("id"), nb::arg("face_vertex_counts"), nb::arg("face_vertex_indices"), nb::arg("points"),
          nb::arg("transform"), nb::arg("material_id") = "", nb::arg("refine_level") = 0,
          nb::arg("left_handed") = false, nb::arg("instancer_id") = "",
          "A mesh; instancer_id: drawn at every instance of that instancer (add_instancer first).")
      .def(
          "add_instancer",
          [](InMemorySceneDelegate& s, const PrimId& id, const Matrices& transforms,
             const std::optional<Points>& colors) { s.AddInstancer(id, ToMatrices(transforms), ToColors(colors)); },
          nb::arg("id"), nb::arg("transforms"), nb::arg("colors") = nb::none(),
          "An instancer: (n, 4, 4) float64 instance-to-world transforms in USD's layout, optional (n, 3) colours.")
      .def(
          "set_instance_transforms",
          [](InMemorySceneDelegate& s, const PrimId& id, const Matrices& transforms,
             const std::optional<Points>& colors) {
            s.SetInstanceTransforms(id, ToMatrices(transforms), ToColors(colors));
          },
          nb::arg("id"), nb::arg("transforms"), nb::arg("colors") = nb::none(),
          "New instances for an instancer: only it and its meshes' instances re-sync.")
      .def(
          "add_eye_mesh",
          [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Indices& indices,
             const Points& points, const EyeParams& eye, const Matrix& transform, const PrimId& material,
             int refineLevel, bool leftHanded) {
            s.AddEyeMesh(id, ToTopology(counts, indices, refineLevel, leftHanded), ToPoints(points), eye,
                         ToMatrix(transform), material);
          },
          nb::arg("id"), nb::arg("face_vertex_counts"), nb::arg("face_vertex_indices"), nb::arg("points"),
          nb::arg("eye"), nb::arg("transform"), nb::arg("material_id") = "", nb::arg("refine_level") = 0,
          nb::arg("left_handed") = false)
      .def(
          "add_basis_curves",
          [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Points& points,
             const std::string& type, const std::string& basis, const std::string& wrap, const Matrix& transform,
             const PrimId& material) {
            static const char* const types[] = {"linear", "cubic"};
            static const char* const bases[] = {"bezier", "bspline", "catmullRom"};
            static const char* const wraps[] = {"nonperiodic", "periodic", "pinned"};
            BasisCurvesTopology t;
            t.type = FromToken<BasisCurvesTopology::Type>("type", type, types);
            t.basis = FromToken<BasisCurvesTopology::Basis>("basis", basis, bases);
            t.wrap = FromToken<BasisCurvesTopology::Wrap>("wrap", wrap, wraps);
            t.curveVertexCounts = ToInts(counts);
            s.AddBasisCurves(id, t, ToPoints(points), ToMatrix(transform), material);
          },
          nb::arg("id"), nb::arg("curve_vertex_counts"), nb::arg("points"), nb::arg("type"), nb::arg("basis"),
          nb::arg("wrap"), nb::arg("transform"), nb::arg("material_id") = "",
          "BasisCurves with UsdGeom's type, basis and wrap tokens; widths and normals through set_primvar.")
      .def(
          "add_points",
          [](InMemorySceneDelegate& s, const PrimId& id, const Points& points, const Matrix& transform,
             const PrimId& material) { s.AddPoints(id, ToPoints(points), ToMatrix(transform), material); },
          nb::arg("id"), nb::arg("points"), nb::arg("transform"), nb::arg("material_id") = "",
          "Points rendered as spheres; widths (diameters) through set_primvar.");
}

/// The scene store's other prims (analytic eyes, cameras, lights, materials, buffers) and edits of mesh topology.
void BindStorePrimsAndTopology(StoreClass& c) {
  c.def("add_analytic_eye", [](InMemorySceneDelegate& s, const PrimId& id, const EyeParams& eye,
                               const Matrix& transform) { s.AddAnalyticEye(id, eye, ToMatrix(transform)); })
      .def("add_camera", [](InMemorySceneDelegate& s, const PrimId& id, const CameraParams& p,
                            const Matrix& transform) { s.AddCamera(id, p, ToMatrix(transform)); })
      .def("add_light", [](InMemorySceneDelegate& s, const PrimId& id, const std::string& type, const LightParams& p,
                           const Matrix& transform) { s.AddLight(id, type, p, ToMatrix(transform)); })
      .def("add_material", &InMemorySceneDelegate::AddMaterial)
      .def("add_render_buffer", &InMemorySceneDelegate::AddRenderBuffer)
      .def("set_points",
           [](InMemorySceneDelegate& s, const PrimId& id, const Points& p) { s.SetPoints(id, ToPoints(p)); })
      .def("set_topology",
           [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Indices& indices,
              const Points& points, int refineLevel, bool leftHanded) {
             s.SetTopology(id, ToTopology(counts, indices, refineLevel, leftHanded), ToPoints(points));
           })
      .def(
          "set_subdivision",
          [](InMemorySceneDelegate& s, const PrimId& id, const std::string& scheme, const std::string& boundary,
             const std::string& faceVarying, const std::string& triangleRule, const Indices& creaseIndices,
             const Indices& creaseLengths, const InArray<float, nb::ndim<1>>& creaseSharpnesses,
             const Indices& cornerIndices, const InArray<float, nb::ndim<1>>& cornerSharpnesses,
             const Indices& holeIndices) {
            static const char* const schemes[] = {"catmullClark", "loop", "bilinear"};
            static const char* const boundaries[] = {"none", "edgeOnly", "edgeAndCorner"};
            static const char* const faceVaryings[] = {"none",         "cornersOnly", "cornersPlus1",
                                                       "cornersPlus2", "boundaries",  "all"};
            static const char* const triangleRules[] = {"catmullClark", "smooth"};
            SubdivTags tags;
            tags.interpolateBoundary = FromToken<SubdivTags::Boundary>("interpolateBoundary", boundary, boundaries);
            tags.faceVaryingLinearInterpolation =
                FromToken<SubdivTags::FaceVaryingLinear>("faceVaryingLinearInterpolation", faceVarying, faceVaryings);
            tags.triangleSubdivisionRule =
                FromToken<SubdivTags::TriangleRule>("triangleSubdivisionRule", triangleRule, triangleRules);
            tags.creaseIndices = ToInts(creaseIndices), tags.creaseLengths = ToInts(creaseLengths);
            tags.creaseSharpnesses = ToFloats(creaseSharpnesses);
            tags.cornerIndices = ToInts(cornerIndices), tags.cornerSharpnesses = ToFloats(cornerSharpnesses);
            s.SetSubdivision(id, FromToken<SubdivScheme>("subdivisionScheme", scheme, schemes), tags,
                             ToInts(holeIndices));
          },
          nb::arg("id"), nb::arg("scheme"), nb::arg("interpolate_boundary"),
          nb::arg("face_varying_linear_interpolation"), nb::arg("triangle_subdivision_rule"), nb::arg("crease_indices"),
          nb::arg("crease_lengths"), nb::arg("crease_sharpnesses"), nb::arg("corner_indices"),
          nb::arg("corner_sharpnesses"), nb::arg("hole_indices"),
          "A mesh's subdivision scheme, tags (UsdGeom tokens; sharpness 10 is infinitely sharp) and holes.")
      .def(
          "set_geom_subsets",
          [](InMemorySceneDelegate& s, const PrimId& id,
             const std::vector<std::tuple<PrimId, std::vector<int>>>& subsets) {
            std::vector<GeomSubset> out;
            for (const auto& [material, faces] : subsets) out.push_back(GeomSubset{material, faces});
            s.SetGeomSubsets(id, out);
          },
          nb::arg("id"), nb::arg("subsets"),
          "Per-face materials: (material id, face indices) per subset; the first subset naming a face wins.");
}

/// The scene store's transforms and motion samples (transforms, points, instancers over the shutter).
void BindStoreMotion(StoreClass& c) {
  c.def("set_transform",
        [](InMemorySceneDelegate& s, const PrimId& id, const Matrix& m) { s.SetTransform(id, ToMatrix(m)); })
      .def(
          "set_transform_samples",
          [](InMemorySceneDelegate& s, const PrimId& id, const std::vector<float>& times,
             const std::vector<Matrix>& matrices) {
            std::vector<Matrix4d> out;
            for (const Matrix& m : matrices) out.push_back(ToMatrix(m));
            s.SetTransformSamples(id, times, out);
          },
          nb::arg("id"), nb::arg("times"), nb::arg("matrices"),
          "Motion samples of a transform: times (frames relative to the frame, ascending), one 4x4 float64 matrix in "
          "USD's layout per time.")
      .def(
          "set_points_samples",
          [](InMemorySceneDelegate& s, const PrimId& id, const std::vector<float>& times,
             const std::vector<Points>& points) {
            std::vector<std::vector<Vec3f>> out;
            for (const Points& p : points) out.push_back(ToPoints(p));
            s.SetPointsSamples(id, times, out);
          },
          nb::arg("id"), nb::arg("times"), nb::arg("points"),
          "Motion samples of a point-based prim's points: times (frames, ascending), one (n, 3) float32 array each.")
      .def(
          "set_instance_transform_samples",
          [](InMemorySceneDelegate& s, const PrimId& id, const std::vector<float>& times,
             const std::vector<Matrices>& transforms) {
            std::vector<std::vector<Matrix4d>> out;
            for (const Matrices& m : transforms) out.push_back(ToMatrices(m));
            s.SetInstanceTransformSamples(id, times, out);
          },
          nb::arg("id"), nb::arg("times"), nb::arg("transforms"),
          "Motion samples of an instancer's transforms: times (frames, ascending), one (m, 4, 4) float64 array each.");
}

/// The scene store's per-prim values: visibility, primvars, parameters, material bindings, removal.
void BindStoreValues(StoreClass& c) {
  c.def("set_visible", &InMemorySceneDelegate::SetVisible)
      .def("set_primvar",
           [](InMemorySceneDelegate& s, const PrimId& id, const std::string& name, const std::string& interpolation,
              const InArray<float, nb::ndim<2>>& values) {
             Primvar p;
             p.interpolation = ToInterpolation(interpolation);
             p.components = int(values.shape(1));
             p.values.assign(values.data(), values.data() + values.size());
             s.SetPrimvar(id, name, p);
           })
      .def("set_light_params", &InMemorySceneDelegate::SetLightParams)
      .def("set_camera_params", &InMemorySceneDelegate::SetCameraParams)
      .def("set_material_params", &InMemorySceneDelegate::SetMaterialParams)
      .def("set_eye_params", &InMemorySceneDelegate::SetEyeParams)
      .def("set_material_id", &InMemorySceneDelegate::SetMaterialId)
      .def("remove_prim", &InMemorySceneDelegate::RemovePrim);
}

}  // namespace

void BindScene(nb::module_& m) {
  IndexClass index(m, "RenderIndex");
  BindIndexPrims(index);
  BindIndexBuffers(index);
  StoreClass store(m, "SceneStore",
                   "The scene as the delegate pulls it (InMemorySceneDelegate); Set* mark dirty bits.");
  BindStoreGeometry(store);
  BindStorePrimsAndTopology(store);
  BindStoreMotion(store);
  BindStoreValues(store);
}

}  // namespace hdeye::python
