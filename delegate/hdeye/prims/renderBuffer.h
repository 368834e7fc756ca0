#pragma once
// A render buffer bprim (HdRenderBuffer's role): an AccumulationBuffer (sums and sample counts per pixel) the
// scene names by prim id and the render pass binds to an AOV.
#include "hdeye/hd/prim.h"
#include "hdeye/render/accumulationBuffer.h"

namespace hdeye {

class RenderBuffer final : public Bprim, public AccumulationBuffer {
 public:
  RenderBuffer(PrimId id = "", int width = 0, int height = 0, int components = 4)
      : Bprim(id), AccumulationBuffer(id, width, height, components) {}
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::Clean; }
  void Sync(SceneDelegate*, RenderParam*, DirtyBits* dirtyBits) override { *dirtyBits = dirty::Clean; }
};

}  // namespace hdeye
