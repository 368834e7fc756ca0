#include "hdeye/scene/sampleScenes.h"

#include "hdeye/prims/renderDelegate.h"

#include <cmath>
#include <utility>
#include <vector>

namespace hdeye::sampleScenes {

namespace {

/// Polygons (faceVertexCounts, faceVertexIndices) refined `refineLevel` times by Catmull-Clark, without tags.
MeshTopology Faces(std::vector<int> counts, std::vector<int> indices, int refineLevel) {
  MeshTopology topology;
  topology.faceVertexCounts = std::move(counts), topology.faceVertexIndices = std::move(indices);
  topology.refineLevel = refineLevel;
  return topology;
}

Matrix4d Translate(const glm::dvec3& t) {
  Matrix4d m(1.0);
  m[3] = glm::dvec4(t, 1);
  return m;
}

/// Camera-to-world for a camera at `eye` looking at `target`, z up (the camera looks down its -z).
Matrix4d LookAt(const glm::dvec3& eye, const glm::dvec3& target) {
  const glm::dvec3 up(0, 0, 1);
  const glm::dvec3 back = glm::normalize(eye - target), right = glm::normalize(glm::cross(up, back));
  Matrix4d cam(1.0);
  cam[0] = glm::dvec4(right, 0);
  cam[1] = glm::dvec4(glm::cross(back, right), 0);
  cam[2] = glm::dvec4(back, 0);
  cam[3] = glm::dvec4(eye, 1);
  return cam;
}

}  // namespace

void AddSideLitEye(InMemorySceneDelegate& scene, double keyAngleDegrees, float keyScale) {
  EyeParams eye;
  eye.irisColor = {0.35f, 0.22f, 0.12f};
  scene.AddAnalyticEye("/World/eye", eye);
  LightParams key;
  key.type = LightType::Sphere;
  key.radius = 3;
  key.intensity = 300 * keyScale;
  const double a = keyAngleDegrees * 3.14159265358979323846 / 180;
  scene.AddLight("/World/key", primTypes::kSphereLight, key, Translate({150 * std::sin(a), 0, 150 * std::cos(a)}));
  LightParams sky;
  sky.type = LightType::Dome;
  sky.intensity = 0.05f;
  scene.AddLight("/World/sky", primTypes::kDomeLight, sky);
  CameraParams lens;
  lens.focalLength = 100;
  scene.AddCamera(kCamera, lens, Translate({0, 0, 45}));
}

void AddBallOnFloor(InMemorySceneDelegate& scene, float keyScale) {
  const MeshTopology cube =
      Faces({4, 4, 4, 4, 4, 4}, {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3}, 3);
  const std::vector<Vec3f> corners = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                      {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  MaterialParams red, grey;
  red.diffuseColor = {0.7f, 0.15f, 0.1f};
  grey.diffuseColor = {0.5f, 0.5f, 0.5f};
  scene.AddMaterial("/Looks/red", red);
  scene.AddMaterial("/Looks/grey", grey);
  scene.AddMesh("/World/ball", cube, corners, Translate({0, 0, 1}), "/Looks/red");
  scene.AddMesh("/World/floor", Faces({4}, {0, 1, 2, 3}, 0), {{-8, -8, 0}, {8, -8, 0}, {8, 8, 0}, {-8, 8, 0}},
                Matrix4d(1.0), "/Looks/grey");
  LightParams key;
  key.type = LightType::Sphere;
  key.radius = kBallKeyRadius;
  key.intensity = 30 * keyScale;
  scene.AddLight(kBallKey, primTypes::kSphereLight, key, Translate(kBallKeyPosition));
  LightParams sky;
  sky.type = LightType::Dome;
  sky.color = {0.6f, 0.7f, 0.9f};
  sky.intensity = 0.3f;
  scene.AddLight(kBallSky, primTypes::kDomeLight, sky);
  scene.AddCamera(kCamera, CameraParams{}, LookAt({0, -7, 3}, {0, 0, 1}));
}

}  // namespace hdeye::sampleScenes
