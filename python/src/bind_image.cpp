// Image files: EXR (named float planes, string header attributes) and tone-mapped PNG previews, written atomically;
// any format OpenImageIO reads or writes, at any bit depth, for tools and tests.
#include "bindings.h"

#include "hdeye/image/imageWriter.h"

#include <OpenImageIO/imageio.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <cstring>
#include <stdexcept>
#include <tuple>

namespace hdeye::python {
namespace {

OIIO::TypeDesc PixelType(const std::string& name) {
  if (name == "uint8") return OIIO::TypeDesc::UINT8;
  if (name == "uint16") return OIIO::TypeDesc::UINT16;
  if (name == "half") return OIIO::TypeDesc::HALF;
  if (name == "float") return OIIO::TypeDesc::FLOAT;
  throw std::invalid_argument("pixel type '" + name + "' is not one of uint8, uint16, half, float");
}

ChannelType ChannelTypeOf(const std::string& name) {
  if (name == "float") return ChannelType::kFloat;
  if (name == "half") return ChannelType::kHalf;
  throw std::invalid_argument("channel type '" + name + "' is not one of float, half");
}

using PlaneArg = std::tuple<std::string, InArray<float, nb::ndim<2>>, std::string>;

/// The planes of one part, each (height, width) of the data window.
ImagePart PartOf(const std::string& name, const std::vector<PlaneArg>& planes, int w, int h) {
  ImagePart part{name, {}};
  for (const auto& [channel, a, type] : planes) {
    if (int(a.shape(0)) != h || int(a.shape(1)) != w)
      throw std::invalid_argument("write_exr_parts: plane " + channel + " is not " + std::to_string(h) + " x " +
                                  std::to_string(w));
    part.planes.push_back({channel, std::vector<float>(a.data(), a.data() + a.size()), ChannelTypeOf(type)});
  }
  return part;
}

/// The renderer's own EXR and PNG files (imageWriter.h): writing them atomically, reading them back.
void BindExr(nb::module_& m) {
  m.def(
      "write_exr",
      [](const std::string& path, const std::vector<std::pair<std::string, InArray<float, nb::ndim<2>>>>& planes,
         const std::vector<std::pair<std::string, std::string>>& attributes) {
        if (planes.empty()) throw std::invalid_argument("write_exr: no planes");
        const int h = int(planes[0].second.shape(0)), w = int(planes[0].second.shape(1));
        std::vector<ImagePlane> out;
        for (const auto& [name, a] : planes) {
          if (int(a.shape(0)) != h || int(a.shape(1)) != w)
            throw std::invalid_argument("write_exr: plane " + name + " differs in size");
          out.push_back({name, std::vector<float>(a.data(), a.data() + a.size())});
        }
        nb::gil_scoped_release release;
        WriteExr(path, w, h, out, attributes);
      },
      nb::arg("path"), nb::arg("planes"), nb::arg("attributes") = std::vector<std::pair<std::string, std::string>>{},
      "Writes named float planes (each (height, width)) as one EXR, atomically; attributes: [(name, value)] "
      "string attributes for the header (e.g. ('eyerender:plan', json)).");
  m.def(
      "write_exr_parts",
      [](const std::string& path, int width, int height,
         const std::vector<std::pair<std::string, std::vector<PlaneArg>>>& parts,
         const std::vector<std::pair<std::string, std::string>>& attributes,
         const std::tuple<int, int, int, int>& dataWindow, bool multiPart) {
        const auto [x0, y0, x1, y1] = dataWindow;
        const bool whole = x1 < x0 || y1 < y0;
        const int w = whole ? width : x1 - x0 + 1, h = whole ? height : y1 - y0 + 1;
        std::vector<ImagePart> out;
        for (const auto& [name, planes] : parts) out.push_back(PartOf(name, planes, w, h));
        nb::gil_scoped_release release;
        WriteExrParts(path, width, height, out, attributes, PixelWindow{x0, y0, x1, y1}, multiPart);
      },
      nb::arg("path"), nb::arg("width"), nb::arg("height"), nb::arg("parts"),
      nb::arg("attributes") = std::vector<std::pair<std::string, std::string>>{},
      nb::arg("data_window") = std::make_tuple(0, 0, -1, -1), nb::arg("multi_part") = false,
      "Writes an EXR of display size width x height, atomically: parts [(part name, [(channel, float32 "
      "(rows, columns) of the data window, 'float' | 'half')])]; data_window (x0, y0, x1, y1) inclusive, rows top "
      "down ((0, 0, -1, -1): the whole image); several parts, or multi_part, make a multi-part EXR whose parts "
      "are named as given; attributes: string header attributes of every part.");
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
          out[p.name.c_str()] =
              nb::ndarray<nb::numpy, float, nb::ndim<2>>(data, {std::size_t(h), std::size_t(w)}, owner);
        }
        return out;
      },
      nb::arg("path"), "Every channel of an EXR as {name: float32 (height, width)}.");
}

/// Any image OpenImageIO handles, as stored (for tools and tests).
void BindOiioImages(nb::module_& m) {
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
        return nb::ndarray<nb::numpy, float, nb::ndim<3>>(copy, {std::size_t(h), std::size_t(w), std::size_t(c)},
                                                          owner);
      },
      nb::arg("path"), "An image's pixels as float32 (height, width, channels), as stored (no colour transform).");
}

}  // namespace

void BindImage(nb::module_& m) {
  BindExr(m);
  BindOiioImages(m);
}

}  // namespace hdeye::python
