// The parameters a scene delegate hands the render delegate: camera, light, material, eye (mm in the canonical frame).
#include "bindings.h"

#include "hdeye/params/primParams.h"

#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>
#include <utility>

namespace hdeye::python {

namespace {

/// A glm vector exposed as a Python 3-tuple property.
template <class C, glm::vec3 C::*Member> void Vec3Property(nb::class_<C>& cls, const char* name) {
  cls.def_prop_rw(
      name,
      [](const C& c) {
        return std::array<float, 3>{(c.*Member).x, (c.*Member).y, (c.*Member).z};
      },
      [](C& c, std::array<float, 3> v) { c.*Member = glm::vec3(v[0], v[1], v[2]); });
}

/// A read-write property `name` on the flat Python EyeParams for one field of EyeParams::chamber.
template <class T, T eyelib::ChamberParams::*Field>
void ChamberProperty(nb::class_<EyeParams>& cls, const char* name, const char* doc = nullptr) {
  auto get = [](const EyeParams& e) { return e.chamber.*Field; };
  auto set = [](EyeParams& e, T v) { e.chamber.*Field = v; };
  if (doc)
    cls.def_prop_rw(name, get, set, doc);
  else
    cls.def_prop_rw(name, get, set);
}

/// The MaterialInput of a UsdPreviewSurface input name; throws std::invalid_argument for one no texture drives.
MaterialInput MaterialInputNamed(const std::string& name) {
  static const std::pair<const char*, MaterialInput> kNames[] = {
      {"diffuseColor", MaterialInput::DiffuseColor},
      {"emissiveColor", MaterialInput::EmissiveColor},
      {"roughness", MaterialInput::Roughness},
      {"metallic", MaterialInput::Metallic},
      {"opacity", MaterialInput::Opacity},
      {"ior", MaterialInput::Ior},
      {"normal", MaterialInput::Normal},
      {"specularColor", MaterialInput::SpecularColor},
      {"clearcoat", MaterialInput::Clearcoat},
      {"clearcoatRoughness", MaterialInput::ClearcoatRoughness}};
  for (const auto& [n, input] : kNames)
    if (name == n) return input;
  throw std::invalid_argument("'" + name + "' is not a texturable UsdPreviewSurface input");
}

/// CameraParams and the lens aperture it gives.
void BindCameraParams(nb::module_& m) {
  nb::enum_<eyelib::CorneaModel>(m, "CorneaModel")
      .value("ellipsoidCone", eyelib::CorneaModel::EllipsoidCone)
      .value("paraboloid", eyelib::CorneaModel::Paraboloid);

  nb::class_<CameraParams>(m, "CameraParams")
      .def(nb::init<>())
      .def_rw("orthographic", &CameraParams::orthographic)
      .def_rw("focal_length", &CameraParams::focalLength, "mm (perspective)")
      .def_rw("horizontal_aperture", &CameraParams::horizontalAperture, "mm, or scene units (orthographic)")
      .def_rw("vertical_aperture", &CameraParams::verticalAperture, "mm, or scene units (orthographic)")
      .def_rw("near_clip", &CameraParams::nearClip, "scene units")
      .def_rw("far_clip", &CameraParams::farClip, "scene units")
      .def_rw("f_stop", &CameraParams::fStop, "f-number; 0: pinhole")
      .def_rw("focus_distance", &CameraParams::focusDistance, "scene units")
      .def_rw("focal_length_unit", &CameraParams::focalLengthUnit, "scene units per focal-length unit (USD: 0.1)")
      .def_rw("shutter_open", &CameraParams::shutterOpen, "frames relative to the frame")
      .def_rw("shutter_close", &CameraParams::shutterClose, "frames relative to the frame (== open: sharp)");
  m.def("lens_aperture_diameter", &LensApertureDiameter, "scene units (0: pinhole)");
}

/// LightParams with its shaping (UsdLuxShapingAPI) and IES profiles.
void BindLightParams(nb::module_& m) {
  nb::class_<LightShaping> shaping(m, "LightShaping");
  shaping.def(nb::init<>())
      .def_rw("enabled", &LightShaping::enabled)
      .def_rw("cone_angle", &LightShaping::coneAngle, "degrees off the axis")
      .def_rw("cone_softness", &LightShaping::coneSoftness, "[0, 1]")
      .def_rw("focus", &LightShaping::focus, "exponent of |cos|")
      .def_rw("ies", &LightShaping::ies, "the parsed shaping:ies:file (parse_ies); empty: none")
      .def_rw("ies_angle_scale", &LightShaping::iesAngleScale)
      .def_rw("ies_normalize", &LightShaping::iesNormalize);
  Vec3Property<LightShaping, &LightShaping::focusTint>(shaping, "focus_tint");

  nb::class_<IesProfile>(m, "IesProfile", "An IES LM-63 type C photometric web (candela).")
      .def(nb::init<>())
      .def_ro("vertical", &IesProfile::vertical, "degrees")
      .def_ro("horizontal", &IesProfile::horizontal, "degrees")
      .def_prop_ro("empty", &IesProfile::Empty)
      .def("intensity", &IesProfile::Intensity, nb::arg("vertical"), nb::arg("horizontal"),
           "candela towards (vertical, horizontal) degrees")
      .def("mean_intensity", &IesProfile::MeanIntensity, "candela, over the sphere (hemisphere)");
  m.def("parse_ies", &ParseIes, nb::arg("text"),
        "Parses an IES LM-63 file's text; ValueError with a short reason if it cannot be used.");

  nb::class_<LightParams> light(m, "LightParams");
  light.def(nb::init<>())
      .def_rw("intensity", &LightParams::intensity)
      .def_rw("exposure", &LightParams::exposure, "stops")
      .def_rw("radius", &LightParams::radius, "scene units (sphere, disk, cylinder)")
      .def_rw("length", &LightParams::length, "scene units (cylinder, along its local x)")
      .def_rw("treat_as_line", &LightParams::treatAsLine)
      .def_rw("width", &LightParams::width, "scene units (rect)")
      .def_rw("height", &LightParams::height, "scene units (rect)")
      .def_rw("angle", &LightParams::angle, "degrees, angular diameter (distant)")
      .def_rw("texture_file", &LightParams::textureFile, "lat-long image (dome)")
      .def_rw("normalize", &LightParams::normalize)
      .def_rw("enable_color_temperature", &LightParams::enableColorTemperature)
      .def_rw("color_temperature", &LightParams::colorTemperature, "kelvin")
      .def_rw("treat_as_point", &LightParams::treatAsPoint)
      .def_rw("shaping", &LightParams::shaping)
      .def_rw("dome_pole_z", &LightParams::domePoleZ, "dome: image's top pole on local +z")
      .def_rw("light_link_excludes", &LightParams::lightLinkExcludes, "rprim ids this light does not illuminate")
      .def_rw("shadow_link_excludes", &LightParams::shadowLinkExcludes, "rprim ids casting no shadow for it");
  Vec3Property<LightParams, &LightParams::color>(light, "color");
}

/// MaterialParams (UsdPreviewSurface) with its textured inputs by name.
void BindMaterialParams(nb::module_& m) {
  nb::class_<MaterialParams> material(m, "MaterialParams");
  material.def(nb::init<>())
      .def(
          "set_texture",
          [](MaterialParams& p, const std::string& input, const TextureInput& t) {
            p.Texture(MaterialInputNamed(input)) = t;
          },
          nb::arg("input"), nb::arg("texture"), "Drives a UsdPreviewSurface input (by its name) by a texture.")
      .def(
          "texture",
          [](const MaterialParams& p, const std::string& input) { return p.Texture(MaterialInputNamed(input)); },
          nb::arg("input"), "The texture driving an input (its texture.file is '' when none does).")
      .def_rw("opacity_threshold", &MaterialParams::opacityThreshold)
      .def_rw("diffuse_from_display_color", &MaterialParams::diffuseFromDisplayColor)
      .def_rw("use_specular_workflow", &MaterialParams::useSpecularWorkflow)
      .def_rw("clearcoat", &MaterialParams::clearcoat)
      .def_rw("clearcoat_roughness", &MaterialParams::clearcoatRoughness)
      .def_rw("roughness", &MaterialParams::roughness)
      .def_rw("metallic", &MaterialParams::metallic)
      .def_rw("opacity", &MaterialParams::opacity)
      .def_rw("ior", &MaterialParams::ior);
  Vec3Property<MaterialParams, &MaterialParams::diffuseColor>(material, "diffuse_color");
  Vec3Property<MaterialParams, &MaterialParams::emissiveColor>(material, "emissive_color");
  Vec3Property<MaterialParams, &MaterialParams::specularColor>(material, "specular_color");
}

/// EyeParams (the EyeAPI schema's attributes), the chamber's through ChamberProperty.
void BindEyeParams(nb::module_& m) {
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
          "model_transform", [](const EyeParams& e) { return FromMatrix(e.modelTransform); },
          [](EyeParams& e, const Matrix& mtx) { e.modelTransform = ToMatrix(mtx); },
          "canonical frame (mm) to the prim's local space, 4x4 in USD's layout")
      .def(
          "validate", [](const EyeParams& e) { return eyelib::ValidateChamberParams(e.chamber); },
          "An empty string if the chamber parameters are valid, else a one-line message.");
  Vec3Property<EyeParams, &EyeParams::irisColor>(eye, "iris_color");
  Vec3Property<EyeParams, &EyeParams::scleraColor>(eye, "sclera_color");
  eye.def_rw("limbal_arc", &EyeParams::limbalArc, "the limbal-arc teleportation cylinder in the sclera walk");
  Vec3Property<EyeParams, &EyeParams::scleraMeanFreePath>(eye, "sclera_mean_free_path");  // mm per RGB channel
  eye.def_prop_rw(
         "iris_projection", [](const EyeParams& e) { return FromMatrix(e.irisProjection); },
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
}

}  // namespace

void BindParams(nb::module_& m) {
  BindCameraParams(m);
  BindLightParams(m);
  BindMaterialParams(m);
  BindEyeParams(m);
}

}  // namespace hdeye::python
