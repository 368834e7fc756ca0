#pragma once
// The render delegate (HdRenderDelegate's role): owns the Embree device and root scene, creates and
// destroys prims by type name, and holds the render settings.
#include "hdeye/prim.h"
#include "hdeye/renderParam.h"

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
inline const std::string kCamera = "camera";
inline const std::string kSphereLight = "sphereLight";
inline const std::string kDistantLight = "distantLight";
inline const std::string kRectLight = "rectLight";
inline const std::string kDiskLight = "diskLight";
inline const std::string kDomeLight = "domeLight";
inline const std::string kMaterial = "material";
inline const std::string kRenderBuffer = "renderBuffer";
}  // namespace primTypes

/// Render settings (name, default), read by the render pass for each Execute.
struct RenderSettings {
  int samplesPerPixel = 16;
  double timeLimitSeconds = 0;  ///< 0: no limit
  unsigned seed = 0;
  int threads = 0;              ///< 0: all cores
  int maxDepth = 8;             ///< path vertices after the camera
  int firstSample = 0;          ///< sample range [firstSample, firstSample + samplesPerPixel): splits a frame
  bool mis = true;              ///< combine light and BSDF sampling (off: light sampling only, for tests)
  /// Eyes: the iris's direct light through MNEE (off: only by paths that refract out of the cornea and
  /// happen to hit a light: plain path tracing, for A/B comparisons).
  bool mnee = true;
  bool mneeAllSolutions = false;  ///< eyes: search every refraction path to a light (caustic folds)
  /// Eye meshes: the sclera is a path-traced random-walk volume (with the limbal arc where the eye's
  /// EyeParams::limbalArc asks for it). Off: the sclera is a Lambertian surface (for A/B comparisons
  /// and for a render plan that finds no sclera worth scattering). Analytic eyes never walk.
  bool scleraScattering = true;
  /// Whether camera rays see dome lights (off: the dome lights the scene but the background is black, as
  /// usdrecord renders without --enableDomeLightVisibility).
  bool domeLightCameraVisibility = true;
};

class RenderDelegate {
 public:
  RenderDelegate();
  ~RenderDelegate();
  RenderDelegate(const RenderDelegate&) = delete;
  RenderDelegate& operator=(const RenderDelegate&) = delete;

  static const std::vector<std::string>& SupportedRprimTypes();
  static const std::vector<std::string>& SupportedSprimTypes();
  static const std::vector<std::string>& SupportedBprimTypes();

  /// A new prim of the named type, or nullptr (and no throw) for a type this delegate does not render.
  std::unique_ptr<Rprim> CreateRprim(const std::string& type, const PrimId& id);
  std::unique_ptr<Sprim> CreateSprim(const std::string& type, const PrimId& id);
  std::unique_ptr<Bprim> CreateBprim(const std::string& type, const PrimId& id);

  RenderParam* GetRenderParam() { return renderParam_.get(); }
  RTCScene RootScene() const { return scene_; }
  RenderSettings& Settings() { return settings_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::unique_ptr<RenderParam> renderParam_;
  RenderSettings settings_;
};

}  // namespace hdeye
