#pragma once
// Base classes of the three prim families (HdRprim, HdSprim, HdBprim): each pulls what its dirty
// bits name from the scene delegate in Sync, and releases what it holds in Finalize.
#include "hdeye/hd/changeTracker.h"
#include "hdeye/hd/sceneDelegate.h"
#include "hdeye/hd/types.h"

namespace hdeye {

class RenderParam;

class Prim {
 public:
  explicit Prim(PrimId id) : id_(std::move(id)) {}
  virtual ~Prim() = default;
  Prim(const Prim&) = delete;
  Prim& operator=(const Prim&) = delete;

  const PrimId& Id() const { return id_; }
  /// The bits this prim reacts to; the render index marks them all dirty when the prim is inserted.
  virtual DirtyBits GetInitialDirtyBitsMask() const = 0;
  /// Pulls the data named by *dirtyBits and clears the bits it handled. Throws std::runtime_error
  /// with a one-line message (naming the prim) on bad data.
  virtual void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) = 0;
  /// Releases renderer resources before destruction.
  virtual void Finalize(RenderParam*) {}

 private:
  PrimId id_;
};

struct GeometryContext;

class Rprim : public Prim {
 public:
  using Prim::Prim;
  /// The renderer's view of this prim (Embree user data), which the render pass completes.
  virtual GeometryContext* Context() { return nullptr; }
  /// The bound material's id, or empty.
  virtual PrimId MaterialId() const { return {}; }
};
class Sprim : public Prim {
  using Prim::Prim;
};
class Bprim : public Prim {
  using Prim::Prim;
};

}  // namespace hdeye
