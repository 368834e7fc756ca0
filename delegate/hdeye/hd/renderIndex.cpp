#include "hdeye/hd/renderIndex.h"

#include "hdeye/hd/renderDelegateInterface.h"

#include <stdexcept>

namespace hdeye {

RenderIndex::RenderIndex(RenderDelegateInterface* renderDelegate) : delegate_(renderDelegate) {}

RenderIndex::~RenderIndex() {
  for (auto& [id, e] : rprims_) e.prim->Finalize(delegate_->GetRenderParam());
  for (auto& [id, e] : sprims_) e.prim->Finalize(delegate_->GetRenderParam());
  for (auto& [id, e] : bprims_) e.prim->Finalize(delegate_->GetRenderParam());
}

template <class T> void RenderIndex::Insert(std::map<PrimId, Entry<T>>& m, std::unique_ptr<T> prim,
                                            const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id) {
  if (!prim) throw std::invalid_argument("render index: prim type '" + type + "' is not supported (" + id + ")");
  if (GetRprim(id) || GetSprim(id) || GetBprim(id) || GetInstancer(id))
    throw std::invalid_argument("render index: a prim " + id + " already exists");
  tracker_.Track(id, prim->GetInitialDirtyBitsMask());
  m.emplace(id, Entry<T>{type, sceneDelegate, std::move(prim)});
}

void RenderIndex::InsertRprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id) {
  Insert(rprims_, delegate_->CreateRprim(type, id), type, sceneDelegate, id);
}
void RenderIndex::InsertSprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id) {
  Insert(sprims_, delegate_->CreateSprim(type, id), type, sceneDelegate, id);
}
void RenderIndex::InsertBprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id) {
  Insert(bprims_, delegate_->CreateBprim(type, id), type, sceneDelegate, id);
}

void RenderIndex::InsertInstancer(SceneDelegate* sceneDelegate, const PrimId& id) {
  Insert(instancers_, std::make_unique<Instancer>(id), "instancer", sceneDelegate, id);
}

void RenderIndex::RemovePrim(const PrimId& id) {
  auto remove = [&](auto& m) {
    auto it = m.find(id);
    if (it == m.end()) return;
    it->second.prim->Finalize(delegate_->GetRenderParam());
    m.erase(it);
    tracker_.Untrack(id);
  };
  remove(rprims_);
  remove(sprims_);
  remove(bprims_);
  remove(instancers_);
}

template <class T> void RenderIndex::SyncMap(std::map<PrimId, Entry<T>>& m) {
  for (auto& [id, e] : m) {
    DirtyBits bits = tracker_.GetDirtyBits(id);
    if (bits == dirty::Clean) continue;
    e.prim->Sync(e.sceneDelegate, delegate_->GetRenderParam(), &bits);
    tracker_.MarkClean(id, bits);
  }
}

void RenderIndex::SyncAll() {
  SyncMap(sprims_);
  SyncMap(bprims_);
  SyncMap(instancers_);
  SyncMap(rprims_);
}

}  // namespace hdeye
