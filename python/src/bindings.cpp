// eyerender._hdeye: the hdeye render delegate for Python (nanobind). Python's USD scene delegate
// pushes a stage into an InMemorySceneDelegate (the scene store whose Set* calls mark dirty bits),
// then drives render passes with the GIL released.
//
// Arrays cross without copies where the layout allows: points, indices and primvars are taken as
// C-contiguous buffers (numpy arrays, or pxr Vt arrays directly through the buffer protocol) and
// copied once, into the scene store. Matrices are 4x4 float64 buffers in USD's layout (row vectors,
// row-major), which is glm's column-major layout of the same transform: no transpose.
#include "hdeye/imageWriter.h"
#include "hdeye/inMemorySceneDelegate.h"
#include "hdeye/mesh.h"
#include "hdeye/renderBuffer.h"
#include "hdeye/renderDelegate.h"
#include "hdeye/renderIndex.h"
#include "hdeye/renderPass.h"
#include "hdeye/renderPlan.h"

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <glm/gtc/type_ptr.hpp>

#include <array>
#include <cstring>
#include <stdexcept>

namespace nb = nanobind;
using namespace hdeye;

namespace {

template <class T, class... Shape>
using InArray = nb::ndarray<const T, nb::c_contig, nb::device::cpu, Shape...>;
using Points = InArray<float, nb::shape<-1, 3>>;
using Indices = InArray<int, nb::ndim<1>>;
using Matrix = InArray<double, nb::shape<4, 4>>;

std::vector<Vec3f> ToPoints(const Points& a) {
  const auto* p = reinterpret_cast<const Vec3f*>(a.data());
  return {p, p + a.shape(0)};
}

std::vector<int> ToInts(const Indices& a) { return {a.data(), a.data() + a.shape(0)}; }

Matrix4d ToMatrix(const Matrix& m) { return glm::make_mat4(m.data()); }

MeshTopology ToTopology(const Indices& counts, const Indices& indices, int refineLevel, bool leftHanded) {
  MeshTopology t;
  t.faceVertexCounts = ToInts(counts);
  t.faceVertexIndices = ToInts(indices);
  t.refineLevel = refineLevel;
  t.leftHanded = leftHanded;
  return t;
}

Interpolation ToInterpolation(const std::string& name) {
  if (name == "constant") return Interpolation::Constant;
  if (name == "uniform") return Interpolation::Uniform;
  if (name == "vertex") return Interpolation::Vertex;
  if (name == "varying") return Interpolation::Varying;
  if (name == "faceVarying") return Interpolation::FaceVarying;
  throw std::invalid_argument("unknown primvar interpolation '" + name + "'");
}

/// A glm vector exposed as a Python 3-tuple property.
template <class C, glm::vec3 C::*Member> void Vec3Property(nb::class_<C>& cls, const char* name) {
  cls.def_prop_rw(
      name, [](const C& c) { return std::array<float, 3>{(c.*Member).x, (c.*Member).y, (c.*Member).z}; },
      [](C& c, std::array<float, 3> v) { c.*Member = glm::vec3(v[0], v[1], v[2]); });
}

/// A read-write property `name` on the flat Python EyeParams for one field of EyeParams::chamber.
template <class T, T eyelib::ChamberParams::*Field>
void ChamberProperty(nb::class_<EyeParams>& cls, const char* name, const char* doc = nullptr) {
  auto get = [](const EyeParams& e) { return e.chamber.*Field; };
  auto set = [](EyeParams& e, T v) { e.chamber.*Field = v; };
  if (doc) cls.def_prop_rw(name, get, set, doc);
  else cls.def_prop_rw(name, get, set);
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
template <class T> nb::ndarray<nb::numpy, T> CopyToNumpy(const std::vector<T>& values, std::initializer_list<std::size_t> shape) {
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

}  // namespace

NB_MODULE(_hdeye, m) {
  m.doc() = "The hdeye render delegate: render index, scene store, render pass, render buffers, image output.";

  nb::enum_<eyelib::CorneaModel>(m, "CorneaModel")
      .value("ellipsoidCone", eyelib::CorneaModel::EllipsoidCone)
      .value("paraboloid", eyelib::CorneaModel::Paraboloid);

  nb::class_<RenderSettings>(m, "RenderSettings")
      .def(nb::init<>())
      .def_rw("samples_per_pixel", &RenderSettings::samplesPerPixel)
      .def_rw("time_limit_seconds", &RenderSettings::timeLimitSeconds)
      .def_rw("seed", &RenderSettings::seed)
      .def_rw("threads", &RenderSettings::threads)
      .def_rw("max_depth", &RenderSettings::maxDepth)
      .def_rw("first_sample", &RenderSettings::firstSample)
      .def_rw("mis", &RenderSettings::mis)
      .def_rw("mnee", &RenderSettings::mnee)
      .def_rw("mnee_all_solutions", &RenderSettings::mneeAllSolutions)
      .def_rw("dome_light_camera_visibility", &RenderSettings::domeLightCameraVisibility,
              "camera rays see dome lights (eyerecord: --enableDomeLightVisibility)")
      .def_rw("sclera_scattering", &RenderSettings::scleraScattering,
              "eye meshes: random-walk sclera subsurface scattering (off: Lambertian sclera)");

  nb::class_<CameraParams>(m, "CameraParams")
      .def(nb::init<>())
      .def_rw("orthographic", &CameraParams::orthographic)
      .def_rw("focal_length", &CameraParams::focalLength, "mm (perspective)")
      .def_rw("horizontal_aperture", &CameraParams::horizontalAperture, "mm, or scene units (orthographic)")
      .def_rw("vertical_aperture", &CameraParams::verticalAperture, "mm, or scene units (orthographic)")
      .def_rw("near_clip", &CameraParams::nearClip, "scene units")
      .def_rw("far_clip", &CameraParams::farClip, "scene units");

  nb::class_<LightParams> light(m, "LightParams");
  light.def(nb::init<>())
      .def_rw("intensity", &LightParams::intensity)
      .def_rw("exposure", &LightParams::exposure, "stops")
      .def_rw("radius", &LightParams::radius, "scene units (sphere, disk)")
      .def_rw("width", &LightParams::width, "scene units (rect)")
      .def_rw("height", &LightParams::height, "scene units (rect)")
      .def_rw("angle", &LightParams::angle, "degrees, angular diameter (distant)")
      .def_rw("texture_file", &LightParams::textureFile, "lat-long image (dome)");
  Vec3Property<LightParams, &LightParams::color>(light, "color");

  nb::class_<MaterialParams> material(m, "MaterialParams");
  material.def(nb::init<>())
      .def_rw("diffuse_texture", &MaterialParams::diffuseTexture)
      .def_rw("roughness", &MaterialParams::roughness)
      .def_rw("metallic", &MaterialParams::metallic)
      .def_rw("opacity", &MaterialParams::opacity)
      .def_rw("ior", &MaterialParams::ior);
  Vec3Property<MaterialParams, &MaterialParams::diffuseColor>(material, "diffuse_color");
  Vec3Property<MaterialParams, &MaterialParams::emissiveColor>(material, "emissive_color");

  nb::class_<EyeParams> eye(m, "EyeParams");
  ChamberProperty<eyelib::CorneaModel, &eyelib::ChamberParams::model>(eye, "cornea_model");
  ChamberProperty<double, &eyelib::ChamberParams::irisDepth>(eye, "iris_depth", "mm below the corneal apex");
  ChamberProperty<double, &eyelib::ChamberParams::pupilDiameter>(eye, "pupil_diameter", "mm");
  ChamberProperty<double, &eyelib::ChamberParams::limbusInnerRatio>(eye, "limbus_inner_ratio",
                                                                    "over the 15.08 mm iris diameter");
  ChamberProperty<double, &eyelib::ChamberParams::limbusOuterRatio>(eye, "limbus_outer_ratio",
                                                                    "over the 15.08 mm iris diameter");
  ChamberProperty<double, &eyelib::ChamberParams::corneaIor>(eye, "cornea_ior");
  eye.def(nb::init<>())
      .def_rw("iris_texture", &EyeParams::irisTexture)
      .def_prop_rw(
          "model_transform",
          [](const EyeParams& e) {
            std::array<double, 16> a;
            std::memcpy(a.data(), glm::value_ptr(e.modelTransform), sizeof a);
            return a;
          },
          [](EyeParams& e, const Matrix& mtx) { e.modelTransform = ToMatrix(mtx); },
          "canonical frame (mm) to the prim's local space, 4x4 in USD's layout")
      .def("validate", [](const EyeParams& e) { return eyelib::ValidateChamberParams(e.chamber); },
           "An empty string if the chamber parameters are valid, else a one-line message.");
  Vec3Property<EyeParams, &EyeParams::irisColor>(eye, "iris_color");
  Vec3Property<EyeParams, &EyeParams::scleraColor>(eye, "sclera_color");
  eye.def_rw("limbal_arc", &EyeParams::limbalArc, "the limbal-arc teleportation cylinder in the sclera walk");
  Vec3Property<EyeParams, &EyeParams::scleraMeanFreePath>(eye, "sclera_mean_free_path");  // mm per RGB channel
  eye.def_prop_rw(
         "iris_projection",
         [](const EyeParams& e) {
           std::array<double, 16> a;
           std::memcpy(a.data(), glm::value_ptr(e.irisProjection), sizeof a);
           return a;
         },
         [](EyeParams& e, const Matrix& mtx) {
           e.irisProjection = ToMatrix(mtx);
           e.hasIrisProjection = true;
         },
         "the iris projection frame to the prim's local space, 4x4 in USD's layout; its [-1, 1]^2 xy square "
         "is the iris texture square. Setting it sets has_iris_projection")
      .def_rw("has_iris_projection", &EyeParams::hasIrisProjection,
              "off: the projection is the model frame along the gaze (modelTransform x scale 7.54 mm)")
      .def_rw("reprojection", &EyeParams::reprojection,
              "eye meshes: re-project hits onto the analytic model (off: the affine-frame comparison baseline)");

  nb::class_<RenderStats>(m, "RenderStats")
      .def_ro("samples", &RenderStats::samples)
      .def_ro("rays", &RenderStats::rays)
      .def_ro("seconds", &RenderStats::seconds)
      .def_ro("passes", &RenderStats::passes)
      .def_ro("non_finite_samples", &RenderStats::nonFiniteSamples)
      .def_ro("capped_walks", &RenderStats::cappedWalks, "sclera walks dropped at their step cap")
      .def_ro("time_limit_reached", &RenderStats::timeLimitReached);

  nb::class_<RenderDelegate>(m, "RenderDelegate")
      .def(nb::init<>())
      .def_prop_ro("settings", [](RenderDelegate& d) -> RenderSettings& { return d.Settings(); },
                   nb::rv_policy::reference_internal)
      .def_static("supported_rprim_types", &RenderDelegate::SupportedRprimTypes)
      .def_static("supported_sprim_types", &RenderDelegate::SupportedSprimTypes);

  nb::class_<RenderIndex>(m, "RenderIndex")
      .def(nb::init<RenderDelegate*>(), nb::keep_alive<1, 2>())
      .def("sync_all", &RenderIndex::SyncAll)
      .def("rprim_ids", [](const RenderIndex& index) {
        std::vector<std::string> ids;
        for (const auto& [id, entry] : index.Rprims()) ids.push_back(id);
        return ids;
      })
      .def("sprim_ids", [](const RenderIndex& index) {
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
            return d;
          },
          "What a mesh's syncs did, counted (topology builds, refinements, stencil evaluations, ...).")
      .def("resolved", [](RenderIndex& index, const PrimId& id) { return Resolved(BufferOf(index, id)); },
           "A render buffer's per-pixel means, float32 (height, width, components).")
      .def("clear_buffer", [](RenderIndex& index, const PrimId& id) { BufferOf(index, id).Clear(); })
      .def("merge_buffer", [](RenderIndex& index, const PrimId& into, RenderIndex& other, const PrimId& from) {
        BufferOf(index, into).Merge(BufferOf(other, from));
      })
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

  nb::class_<InMemorySceneDelegate>(m, "SceneStore",
                                    "The scene as the delegate pulls it (InMemorySceneDelegate); Set* mark dirty bits.")
      .def(nb::init<RenderIndex*>(), nb::keep_alive<1, 2>())
      .def(
          "add_mesh",
          [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Indices& indices,
             const Points& points, const Matrix& transform, const PrimId& material, int refineLevel, bool leftHanded) {
            s.AddMesh(id, ToTopology(counts, indices, refineLevel, leftHanded), ToPoints(points), ToMatrix(transform),
                      material);
          },
          nb::arg("id"), nb::arg("face_vertex_counts"), nb::arg("face_vertex_indices"), nb::arg("points"),
          nb::arg("transform"), nb::arg("material_id") = "", nb::arg("refine_level") = 0, nb::arg("left_handed") = false)
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
      .def("add_analytic_eye", [](InMemorySceneDelegate& s, const PrimId& id, const EyeParams& eye,
                                  const Matrix& transform) { s.AddAnalyticEye(id, eye, ToMatrix(transform)); })
      .def("add_camera", [](InMemorySceneDelegate& s, const PrimId& id, const CameraParams& p,
                            const Matrix& transform) { s.AddCamera(id, p, ToMatrix(transform)); })
      .def("add_light", [](InMemorySceneDelegate& s, const PrimId& id, const std::string& type, const LightParams& p,
                           const Matrix& transform) { s.AddLight(id, type, p, ToMatrix(transform)); })
      .def("add_material", &InMemorySceneDelegate::AddMaterial)
      .def("add_render_buffer", &InMemorySceneDelegate::AddRenderBuffer)
      .def("set_points", [](InMemorySceneDelegate& s, const PrimId& id, const Points& p) { s.SetPoints(id, ToPoints(p)); })
      .def("set_topology",
           [](InMemorySceneDelegate& s, const PrimId& id, const Indices& counts, const Indices& indices,
              const Points& points, int refineLevel, bool leftHanded) {
             s.SetTopology(id, ToTopology(counts, indices, refineLevel, leftHanded), ToPoints(points));
           })
      .def("set_transform", [](InMemorySceneDelegate& s, const PrimId& id, const Matrix& m) { s.SetTransform(id, ToMatrix(m)); })
      .def("set_visible", &InMemorySceneDelegate::SetVisible)
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

  nb::class_<PlanOverrides>(m, "PlanOverrides",
                            "What the user set explicitly (flags, render settings, authored schema values): wins over "
                            "the render plan. None: the planner decides.")
      .def(nb::init<>())
      .def_rw("mnee", &PlanOverrides::mnee, nb::arg("value").none())
      .def_rw("mnee_all_solutions", &PlanOverrides::mneeAllSolutions, nb::arg("value").none())
      .def_rw("sclera_scattering", &PlanOverrides::scleraScattering, nb::arg("value").none())
      .def_rw("limbal_arc", &PlanOverrides::limbalArc, nb::arg("value").none())
      .def_rw("chamber_events", &PlanOverrides::chamberEvents, nb::arg("value").none(),
              "events the chamber walk follows per path (>= 1); None: the planner decides")
      .def_rw("refine_level_ceiling", &PlanOverrides::refineLevelCeiling, "the --complexity level")
      .def(
          "set_authored_limbal_arc",
          [](PlanOverrides& o, const PrimId& prim, bool value) { o.authored[prim].limbalArc = value; },
          nb::arg("prim"), nb::arg("value"), "eye:limbalArc authored on the eye prim `prim`.");

  nb::class_<PlanRules>(m, "PlanRules", "The render plan's thresholds (docs/render_plan.md).")
      .def(nb::init<>())
      .def_rw("mnee_min_pixels", &PlanRules::mneeMinPixels, "pixels")
      .def_rw("mnee_max_solid_angle_sr", &PlanRules::mneeMaxSolidAngleSr, "steradians")
      .def_rw("mnee_max_solid_angle_sr_grazing", &PlanRules::mneeMaxSolidAngleSrGrazing, "steradians")
      .def_rw("grazing_angle_deg", &PlanRules::grazingAngleDeg, "degrees")
      .def_rw("all_solutions_min_angle_deg", &PlanRules::allSolutionsMinAngleDeg, "degrees")
      .def_rw("all_solutions_min_pixels", &PlanRules::allSolutionsMinPixels, "pixels")
      .def_rw("chamber_events", &PlanRules::chamberEvents, "events per path")
      .def_rw("sss_min_pixels", &PlanRules::sssMinPixels, "pixels")
      .def_rw("sss_min_limbus_pixels", &PlanRules::sssMinLimbusPixels, "pixels")
      .def_rw("limbal_arc_min_light_angle_deg", &PlanRules::limbalArcMinLightAngleDeg, "degrees")
      .def_rw("refine_pixels_level1", &PlanRules::refinePixelsLevel1, "pixels")
      .def_rw("refine_max_level", &PlanRules::refineMaxLevel, "Catmull-Clark level")
      .def_rw("float_hit_error_mm", &PlanRules::floatHitErrorMm, "mm")
      .def_rw("float_max_error_pixels", &PlanRules::floatMaxErrorPixels, "pixels");

  nb::class_<RenderPlan>(m, "RenderPlan", "What the render plan decided, per eye, with reasons.")
      .def("to_json", &RenderPlan::ToJson, "The plan as a JSON object string (docs/render_plan.md).")
      .def("summary_lines", &RenderPlan::SummaryLines, "One line per eye, for printing at render start.")
      .def(
          "apply",
          [](const RenderPlan& p, RenderSettings& s, RenderIndex* index) {
            if (index) ApplyRenderPlan(p, index, &s);
            else ApplyRenderPlan(p, &s);
          },
          nb::arg("settings"), nb::arg("index").none() = nb::none(),
          "Applies the plan: with the render index, each eye rprim gets its own switches (MNEE per light, all "
          "solutions, chamber bound, sclera walk, limbal arc); the settings' global switches (mnee, "
          "mnee_all_solutions, sclera_scattering) become the defaults for eyes without a plan. Without the index, "
          "only the global switches.")
      .def_ro("mnee", &RenderPlan::mnee)
      .def_ro("mnee_all_solutions", &RenderPlan::mneeAllSolutions)
      .def_ro("sclera_scattering", &RenderPlan::scleraScattering);

  m.def("clear_render_plan", [](RenderIndex& index) { ClearRenderPlan(&index); }, nb::arg("index"),
        "Resets every eye of the index to unplanned: renders use the settings' global switches.");

  nb::class_<RenderPass>(m, "RenderPass")
      .def(nb::init<RenderIndex*>(), nb::keep_alive<1, 2>())
      .def(
          "execute",
          [](RenderPass& pass, const PrimId& camera, const std::vector<std::pair<std::string, PrimId>>& bindings) {
            std::vector<AovBinding> b;
            for (const auto& [aov, buffer] : bindings) b.push_back({aov, buffer});
            return pass.Execute(camera, b);
          },
          nb::arg("camera_id"), nb::arg("bindings"), nb::call_guard<nb::gil_scoped_release>(),
          "Syncs the index and renders settings.samples_per_pixel samples from settings.first_sample into the "
          "bound buffers (which accumulate). bindings: [(aov name, render buffer id)].")
      .def("plan", &RenderPass::Plan, nb::arg("camera_id"), nb::arg("width"), nb::arg("height"),
           nb::arg("overrides"), nb::arg("rules") = PlanRules{}, nb::call_guard<nb::gil_scoped_release>(),
           "Syncs the index and returns the render plan for the camera and image size, without rendering.");

  m.def(
      "write_exr",
      [](const std::string& path, const std::vector<std::pair<std::string, InArray<float, nb::ndim<2>>>>& planes,
         const std::vector<std::pair<std::string, std::string>>& attributes) {
        if (planes.empty()) throw std::invalid_argument("write_exr: no planes");
        const int h = int(planes[0].second.shape(0)), w = int(planes[0].second.shape(1));
        std::vector<ImagePlane> out;
        for (const auto& [name, a] : planes) {
          if (int(a.shape(0)) != h || int(a.shape(1)) != w) throw std::invalid_argument("write_exr: plane " + name + " differs in size");
          out.push_back({name, std::vector<float>(a.data(), a.data() + a.size())});
        }
        nb::gil_scoped_release release;
        WriteExr(path, w, h, out, attributes);
      },
      nb::arg("path"), nb::arg("planes"), nb::arg("attributes") = std::vector<std::pair<std::string, std::string>>{},
      "Writes named float planes (each (height, width)) as one EXR, atomically; attributes: [(name, value)] "
      "string attributes for the header (e.g. ('eyerender:plan', json)).");
  m.def("read_exr_attributes", &ReadExrStringAttributes, nb::arg("path"),
        "Every string attribute of an EXR's header, {name: value}.");
  m.def(
      "write_png_preview",
      [](const std::string& path, const InArray<float, nb::shape<-1, -1, 3>>& rgb, float exposure) {
        std::vector<float> data(rgb.data(), rgb.data() + rgb.size());
        nb::gil_scoped_release release;
        WritePngPreview(path, int(rgb.shape(1)), int(rgb.shape(0)), data, exposure);
      },
      nb::arg("path"), nb::arg("rgb"), nb::arg("exposure") = 0.0f,
      "Writes linear RGB (height, width, 3) as a tone-mapped (clamped) sRGB PNG, atomically.");
  m.def(
      "read_exr",
      [](const std::string& path) {
        int w = 0, h = 0;
        const auto planes = ReadExr(path, &w, &h);
        nb::dict out;
        for (const auto& p : planes) {
          auto* data = new float[p.pixels.size()];
          std::memcpy(data, p.pixels.data(), p.pixels.size() * sizeof(float));
          nb::capsule owner(data, [](void* d) noexcept { delete[] static_cast<float*>(d); });
          out[p.name.c_str()] = nb::ndarray<nb::numpy, float, nb::ndim<2>>(data, {std::size_t(h), std::size_t(w)}, owner);
        }
        return out;
      },
      nb::arg("path"), "Every channel of an EXR as {name: float32 (height, width)}.");
}
