#pragma once
// What the binding files of eyerender._hdeye share: the array types that cross without copies, the conversions
// from them, and one Bind* function per subject (module.cpp calls them in dependency order).
#include "hdeye/hd/types.h"

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <glm/gtc/type_ptr.hpp>

#include <array>
#include <cstring>

namespace hdeye::python {

namespace nb = nanobind;

template <class T, class... Shape> using InArray = nb::ndarray<const T, nb::c_contig, nb::device::cpu, Shape...>;
using Points = InArray<float, nb::shape<-1, 3>>;
using Indices = InArray<int, nb::ndim<1>>;
/// 4x4 float64 in USD's layout (row vectors, row-major): glm's column-major layout of the same transform.
using Matrix = InArray<double, nb::shape<4, 4>>;

inline Matrix4d ToMatrix(const Matrix& m) { return glm::make_mat4(m.data()); }

/// A transform as 16 float64 in USD's layout (the inverse of ToMatrix).
inline std::array<double, 16> FromMatrix(const Matrix4d& m) {
  std::array<double, 16> a;
  std::memcpy(a.data(), glm::value_ptr(m), sizeof a);
  return a;
}

void BindTextures(nb::module_& m);  ///< bind_textures.cpp: texture parameters, textured inputs, texture checks
void BindParams(nb::module_& m);    ///< bind_params.cpp: camera, light, material and eye parameters
void BindScene(nb::module_& m);     ///< bind_scene.cpp: the render index, its buffers, the scene store
void BindPlan(nb::module_& m);      ///< bind_plan.cpp: overrides, rules, the plan and its parts
void BindRender(nb::module_& m);    ///< bind_render.cpp: settings, the render delegate, the render pass, stats
void BindImage(nb::module_& m);     ///< bind_image.cpp: EXR and PNG files, any image OpenImageIO handles

}  // namespace hdeye::python
