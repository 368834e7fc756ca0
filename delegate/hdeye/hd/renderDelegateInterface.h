#pragma once
// What the render index asks of a render delegate (HdRenderDelegate's abstract interface): prims by type
// name, and the render param every Sync receives. prims/renderDelegate.h implements it.
#include "hdeye/hd/prim.h"

#include <memory>
#include <string>

namespace hdeye {

class RenderDelegateInterface {
 public:
  virtual ~RenderDelegateInterface() = default;
  /// A new prim of the named type, or nullptr (and no throw) for a type this delegate does not render.
  virtual std::unique_ptr<Rprim> CreateRprim(const std::string& type, const PrimId& id) = 0;
  virtual std::unique_ptr<Sprim> CreateSprim(const std::string& type, const PrimId& id) = 0;
  virtual std::unique_ptr<Bprim> CreateBprim(const std::string& type, const PrimId& id) = 0;
  virtual RenderParam* GetRenderParam() = 0;
};

}  // namespace hdeye
