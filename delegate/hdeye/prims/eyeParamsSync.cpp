#include "hdeye/prims/eyeParamsSync.h"

#include <eyelib/anterior_chamber.h>
#include <eyelib/random_walk_sss.h>

#include <stdexcept>

namespace hdeye {

void SyncEyeParams(SceneDelegate* sceneDelegate, RenderParam* renderParam, const std::string& kind, const PrimId& id,
                   EyeParams* params, std::shared_ptr<const Texture>* irisTexture) {
  *params = sceneDelegate->GetEyeParams(id);
  const std::string problem = eyelib::ValidateChamberParams(params->chamber);
  if (!problem.empty()) throw std::runtime_error(kind + " " + id + ": " + problem);
  // The sclera walk would quietly return nothing for these: say so once, at sync.
  const std::string sclera = eyelib::ValidateSssArtistParams(params->scleraColor, params->scleraMeanFreePath);
  if (!sclera.empty()) throw std::runtime_error(kind + " " + id + ": sclera " + sclera);
  if (params->irisTexture.empty()) {
    *irisTexture = nullptr;
    return;
  }
  *irisTexture = renderParam->Textures().Get(params->irisTexture);
  if (!(*irisTexture)->Valid())
    renderParam->Warn(kind + " " + id + ": iris texture: " + (*irisTexture)->Error() + "; the iris is magenta");
}

}  // namespace hdeye
