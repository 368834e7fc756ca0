// Textures: UsdUVTexture's parameters (TextureParams), a textured material input (TextureInput), and the check a
// scene delegate runs before binding a file (texture_problem).
#include "bindings.h"

#include "hdeye/params/primParams.h"
#include "hdeye/render/texture.h"

#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>

namespace hdeye::python {
namespace {

std::array<float, 4> ToArray(const glm::vec4& v) { return {v.x, v.y, v.z, v.w}; }
glm::vec4 ToVec4(const std::array<float, 4>& a) { return {a[0], a[1], a[2], a[3]}; }

template <glm::vec4 TextureParams::*Member>
void Vec4Property(nb::class_<TextureParams>& cls, const char* name, const char* doc) {
  cls.def_prop_rw(
      name, [](const TextureParams& p) { return ToArray(p.*Member); },
      [](TextureParams& p, const std::array<float, 4>& v) { p.*Member = ToVec4(v); }, doc);
}

}  // namespace

void BindTextures(nb::module_& m) {
  nb::enum_<TextureWrap>(m, "TextureWrap")
      .value("useMetadata", TextureWrap::UseMetadata)
      .value("black", TextureWrap::Black)
      .value("clamp", TextureWrap::Clamp)
      .value("repeat", TextureWrap::Repeat)
      .value("mirror", TextureWrap::Mirror);
  nb::enum_<TextureColorSpace>(m, "TextureColorSpace")
      .value("auto", TextureColorSpace::Auto)
      .value("raw", TextureColorSpace::Raw)
      .value("sRGB", TextureColorSpace::Srgb);

  nb::class_<TextureParams> params(m, "TextureParams", "How one texture is read: UsdUVTexture's inputs.");
  params.def(nb::init<>())
      .def_rw("file", &TextureParams::file, "an image path; <UDIM> in it names a UDIM set")
      .def_rw("wrap_s", &TextureParams::wrapS)
      .def_rw("wrap_t", &TextureParams::wrapT)
      .def_rw("color_space", &TextureParams::colorSpace);
  Vec4Property<&TextureParams::scale>(params, "scale", "RGBA multiplier");
  Vec4Property<&TextureParams::bias>(params, "bias", "RGBA offset, after scale");
  Vec4Property<&TextureParams::fallback>(params, "fallback", "RGBA used where the file cannot be read");

  nb::class_<TextureInput>(m, "TextureInput", "A material input driven by a UsdUVTexture.")
      .def(nb::init<>())
      .def_rw("texture", &TextureInput::texture)
      .def_rw("channel", &TextureInput::channel, "-1: rgb; 0..3: r, g, b, a")
      .def_prop_rw(
          "scale",
          [](const TextureInput& t) {
            return std::array<float, 2>{t.scale.x, t.scale.y};
          },
          [](TextureInput& t, const std::array<float, 2>& v) {
            t.scale = {v[0], v[1]};
          },
          "UsdTransform2d scale")
      .def_rw("rotation", &TextureInput::rotation, "UsdTransform2d rotation, degrees counter-clockwise")
      .def_prop_rw(
          "translation",
          [](const TextureInput& t) {
            return std::array<float, 2>{t.translation.x, t.translation.y};
          },
          [](TextureInput& t, const std::array<float, 2>& v) {
            t.translation = {v[0], v[1]};
          },
          "UsdTransform2d translation");

  m.def("texture_problem", &TextureProblem, nb::arg("file"), nb::call_guard<nb::gil_scoped_release>(),
        "Why the file cannot be used as a texture (one line naming it), or '' if it can.");
}

}  // namespace hdeye::python
