#pragma once
// The render delegate (HdRenderDelegate's role): owns the Embree device and root scene, creates and
// destroys prims by type name, and holds the render settings.
#include "hdeye/hd/renderDelegateInterface.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/renderSettings.h"

#include <embree3/rtcore.h>

#include <memory>
#include <string>
#include <vector>

namespace hdeye {

/// Type names, as Hydra's tokens.
namespace primTypes {
inline const std::string kMesh = "mesh";
inline const std::string kAnalyticEye = "analyticEye";  ///< the anterior segment alone, no mesh
inline const std::string kEyeMesh = "eyeMesh";  ///< a mesh eyeball whose cornea continues against the analytic model
inline const std::string kBasisCurves = "basisCurves";
inline const std::string kPoints = "points";
inline const std::string kCamera = "camera";
inline const std::string kSphereLight = "sphereLight";
inline const std::string kDistantLight = "distantLight";
inline const std::string kRectLight = "rectLight";
inline const std::string kDiskLight = "diskLight";
inline const std::string kDomeLight = "domeLight";
inline const std::string kCylinderLight = "cylinderLight";
inline const std::string kMaterial = "material";
inline const std::string kRenderBuffer = "renderBuffer";
}  // namespace primTypes

class RenderDelegate final : public RenderDelegateInterface {
 public:
  RenderDelegate();
  ~RenderDelegate();
  RenderDelegate(const RenderDelegate&) = delete;
  RenderDelegate& operator=(const RenderDelegate&) = delete;

  static const std::vector<std::string>& SupportedRprimTypes();
  static const std::vector<std::string>& SupportedSprimTypes();
  static const std::vector<std::string>& SupportedBprimTypes();

  std::unique_ptr<Rprim> CreateRprim(const std::string& type, const PrimId& id) override;
  std::unique_ptr<Sprim> CreateSprim(const std::string& type, const PrimId& id) override;
  std::unique_ptr<Bprim> CreateBprim(const std::string& type, const PrimId& id) override;

  RenderParam* GetRenderParam() override { return renderParam_.get(); }
  RTCScene RootScene() const { return scene_; }
  RenderSettings& Settings() { return settings_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::unique_ptr<RenderParam> renderParam_;
  RenderSettings settings_;
};

}  // namespace hdeye
