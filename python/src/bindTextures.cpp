// eyerender._hdeye, textures: UsdUVTexture's parameters (TextureParams), a textured material input
// (TextureInput), the check a scene delegate runs before binding a file (texture_problem), and
// OpenImageIO image reading and writing for tools and tests (any format OIIO writes, any bit depth).
#include "bindTextures.h"

#include "hdeye/sceneDelegate.h"
#include "hdeye/texture.h"

#include <OpenImageIO/imageio.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/string.h>

#include <cstring>
#include <map>
#include <stdexcept>

namespace nb = nanobind;
using namespace hdeye;

namespace {

std::array<float, 4> ToArray(const glm::vec4& v) { return {v.x, v.y, v.z, v.w}; }
glm::vec4 ToVec4(const std::array<float, 4>& a) { return {a[0], a[1], a[2], a[3]}; }

template <glm::vec4 TextureParams::*Member> void Vec4Property(nb::class_<TextureParams>& cls, const char* name, const char* doc) {
  cls.def_prop_rw(
      name, [](const TextureParams& p) { return ToArray(p.*Member); },
      [](TextureParams& p, const std::array<float, 4>& v) { p.*Member = ToVec4(v); }, doc);
}

OIIO::TypeDesc PixelType(const std::string& name) {
  if (name == "uint8") return OIIO::TypeDesc::UINT8;
  if (name == "uint16") return OIIO::TypeDesc::UINT16;
  if (name == "half") return OIIO::TypeDesc::HALF;
  if (name == "float") return OIIO::TypeDesc::FLOAT;
  throw std::invalid_argument("pixel type '" + name + "' is not one of uint8, uint16, half, float");
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
          "scale", [](const TextureInput& t) { return std::array<float, 2>{t.scale.x, t.scale.y}; },
          [](TextureInput& t, const std::array<float, 2>& v) { t.scale = {v[0], v[1]}; }, "UsdTransform2d scale")
      .def_rw("rotation", &TextureInput::rotation, "UsdTransform2d rotation, degrees counter-clockwise")
      .def_prop_rw(
          "translation", [](const TextureInput& t) { return std::array<float, 2>{t.translation.x, t.translation.y}; },
          [](TextureInput& t, const std::array<float, 2>& v) { t.translation = {v[0], v[1]}; },
          "UsdTransform2d translation");

  m.def("texture_problem", &TextureProblem, nb::arg("file"), nb::call_guard<nb::gil_scoped_release>(),
        "Why the file cannot be used as a texture (one line naming it), or '' if it can.");

  m.def(
      "write_image",
      [](const std::string& path, const nb::ndarray<const float, nb::c_contig, nb::device::cpu, nb::ndim<3>>& pixels,
         const std::string& type, const std::map<std::string, std::string>& attributes) {
        const int h = int(pixels.shape(0)), w = int(pixels.shape(1)), c = int(pixels.shape(2));
        OIIO::ImageSpec spec(w, h, c, PixelType(type));
        for (const auto& [name, value] : attributes) spec.attribute(name, value);
        std::vector<float> data(pixels.data(), pixels.data() + pixels.size());
        nb::gil_scoped_release release;
        auto out = OIIO::ImageOutput::create(path);
        if (!out) throw std::runtime_error("cannot write " + path + ": " + OIIO::geterror());
        if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data.data()) || !out->close())
          throw std::runtime_error("cannot write " + path + ": " + out->geterror());
      },
      nb::arg("path"), nb::arg("pixels"), nb::arg("type") = "uint8",
      nb::arg("attributes") = std::map<std::string, std::string>{},
      "Writes float pixels (height, width, channels; row 0 at the top, values as stored: no colour transform) "
      "in the format the extension names, quantised to `type` (uint8, uint16, half, float). Not atomic: for "
      "tools and tests.");
  m.def(
      "read_image",
      [](const std::string& path) {
        std::vector<float> data;
        int w = 0, h = 0, c = 0;
        {
          nb::gil_scoped_release release;
          auto in = OIIO::ImageInput::open(path);
          if (!in) throw std::runtime_error("cannot read " + path + ": " + OIIO::geterror());
          const OIIO::ImageSpec& spec = in->spec();
          w = spec.width, h = spec.height, c = spec.nchannels;
          data.resize(std::size_t(w) * h * c);
          if (!in->read_image(0, 0, 0, c, OIIO::TypeDesc::FLOAT, data.data()))
            throw std::runtime_error("cannot read " + path + ": " + in->geterror());
        }
        auto* copy = new float[data.size()];
        std::memcpy(copy, data.data(), data.size() * sizeof(float));
        nb::capsule owner(copy, [](void* d) noexcept { delete[] static_cast<float*>(d); });
        return nb::ndarray<nb::numpy, float, nb::ndim<3>>(copy, {std::size_t(h), std::size_t(w), std::size_t(c)}, owner);
      },
      nb::arg("path"), "An image's pixels as float32 (height, width, channels), as stored (no colour transform).");
}
