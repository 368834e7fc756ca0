// The Hydra framework clones as a layer of their own: this executable links hdeye_hd (and below it only the parameter
// values, hdeye_params, and eyelib) and nothing of the renderer, so it builds only while hd/ needs no Embree, TBB or
// OpenImageIO. A render delegate of its own makes the index sync a camera and an instancer.
#include "hdeye/hd/renderDelegateInterface.h"
#include "hdeye/hd/renderIndex.h"

#include <catch2/catch.hpp>

#include <memory>

namespace {

/// A camera sprim that keeps the focal length it pulled and counts its syncs.
class Camera final : public hdeye::Sprim {
 public:
  using Sprim::Sprim;
  hdeye::DirtyBits GetInitialDirtyBitsMask() const override { return hdeye::dirty::DirtyParams; }
  void Sync(hdeye::SceneDelegate* scene, hdeye::RenderParam*, hdeye::DirtyBits* bits) override {
    focalLength = scene->GetCameraParams(Id()).focalLength;
    ++syncs;
    *bits = hdeye::dirty::Clean;
  }
  double focalLength = 0;
  int syncs = 0;
};

class CameraOnlyDelegate final : public hdeye::RenderDelegateInterface {
 public:
  std::unique_ptr<hdeye::Rprim> CreateRprim(const std::string&, const hdeye::PrimId&) override { return nullptr; }
  std::unique_ptr<hdeye::Sprim> CreateSprim(const std::string& type, const hdeye::PrimId& id) override {
    return type == "camera" ? std::make_unique<Camera>(id) : nullptr;
  }
  std::unique_ptr<hdeye::Bprim> CreateBprim(const std::string&, const hdeye::PrimId&) override { return nullptr; }
  hdeye::RenderParam* GetRenderParam() override { return nullptr; }
};

/// A scene of one camera (focal length 35 mm) and one instancer of two instances.
class TinyScene final : public hdeye::SceneDelegate {
 public:
  explicit TinyScene(hdeye::RenderIndex* index) : index_(index) {}
  hdeye::RenderIndex* GetRenderIndex() override { return index_; }
  hdeye::MeshTopology GetMeshTopology(const hdeye::PrimId&) override { return {}; }
  std::vector<hdeye::Vec3f> GetPoints(const hdeye::PrimId&) override { return {}; }
  hdeye::Matrix4d GetTransform(const hdeye::PrimId&) override { return hdeye::Matrix4d(1.0); }
  bool GetVisible(const hdeye::PrimId&) override { return true; }
  hdeye::PrimId GetMaterialId(const hdeye::PrimId&) override { return {}; }
  hdeye::CameraParams GetCameraParams(const hdeye::PrimId&) override {
    hdeye::CameraParams p;
    p.focalLength = 35;
    return p;
  }
  hdeye::LightParams GetLightParams(const hdeye::PrimId&) override { return {}; }
  hdeye::MaterialParams GetMaterialParams(const hdeye::PrimId&) override { return {}; }
  hdeye::EyeParams GetEyeParams(const hdeye::PrimId&) override { return {}; }
  std::vector<hdeye::Matrix4d> GetInstanceTransforms(const hdeye::PrimId&) override {
    return {hdeye::Matrix4d(1.0), hdeye::Matrix4d(2.0)};
  }

 private:
  hdeye::RenderIndex* index_;
};

}  // namespace

TEST_CASE(
    "the Hydra clones sync prims without the renderer: a camera pulls its parameters, an instancer its "
    "instances, and a clean index syncs nothing again",
    "[hd]") {
  CameraOnlyDelegate delegate;
  hdeye::RenderIndex index(&delegate);
  TinyScene scene(&index);
  index.InsertSprim("camera", &scene, "/Camera");
  index.InsertInstancer(&scene, "/Instancer");
  index.SyncAll();
  const auto* camera = dynamic_cast<const Camera*>(index.GetSprim("/Camera"));
  REQUIRE(camera != nullptr);
  CHECK(camera->focalLength == 35);
  CHECK(camera->syncs == 1);
  REQUIRE(index.GetInstancer("/Instancer") != nullptr);
  CHECK(index.GetInstancer("/Instancer")->InstanceTransforms().size() == 2);
  index.SyncAll();
  CHECK(camera->syncs == 1);
  index.GetChangeTracker().MarkDirty("/Camera", hdeye::dirty::DirtyParams);
  index.SyncAll();
  CHECK(camera->syncs == 2);
}
