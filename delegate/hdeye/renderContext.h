#pragma once
// What the renderer knows of a piece of geometry (HdEmbreePrototypeContext's role), stored as Embree
// geometry user data. The renderer sees these, never prim classes.
#include "hdeye/sceneDelegate.h"

#include <vector>

namespace hdeye {

struct EyeGeometry;

struct GeometryContext {
  int primIndex = -1;                 ///< the primId AOV value
  glm::dmat3 normalToWorld{1.0};      ///< inverse transpose of the instance transform's linear part
  MaterialParams material;            ///< resolved from the bound material (or the fallback)
  const std::vector<Vec3f>* displayColor = nullptr;  ///< per vertex of the rendered triangles, or null
  const std::vector<int>* triangleVertices = nullptr;  ///< 3 per triangle, for interpolating displayColor, normals
  /// Unit shading normals per vertex of the rendered triangles, object space (refined meshes: the limit
  /// normals; polygon meshes: smooth vertex normals), or null: the renderer then shades with the flat
  /// geometric normal. A zero normal (degenerate vertex) is allowed; the renderer falls back there too.
  const std::vector<Vec3f>* vertexNormals = nullptr;
  const EyeGeometry* eye = nullptr;   ///< set for eyes: the renderer shades them through the analytic model
};

}  // namespace hdeye
