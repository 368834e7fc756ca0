// eyerender._hdeye: the hdeye render delegate for Python (nanobind), one binding file per subject (bindings.h).
// Python's USD scene delegate pushes a stage into a SceneStore (the scene store whose Set* calls mark dirty bits),
// then drives render passes with the GIL released.
#include "bindings.h"

NB_MODULE(_hdeye, m) {
  using namespace hdeye::python;
  m.doc() =
      "The hdeye render delegate: render index, scene store, render pass, render buffers, textures, image output.";
  // Types before the signatures that use them as defaults (RenderPass.plan's PlanRules()).
  BindTextures(m);
  BindParams(m);
  BindScene(m);
  BindPlan(m);
  BindRender(m);
  BindImage(m);
}
