// Image files: EXR (named float planes, string header attributes) and tone-mapped PNG previews, written atomically.
#include "bindings.h"

#include "hdeye/image/imageWriter.h"

#include <nanobind/stl/map.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>

namespace hdeye::python {

void BindImage(nb::module_& m) {
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

}  // namespace hdeye::python
