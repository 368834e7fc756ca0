#pragma once
// The render index (HdRenderIndex's role): the prims of one scene, by id, with their scene delegate
// and dirty bits. SyncAll brings every dirty prim up to date: sprims first (cameras, lights,
// materials), then bprims, then instancers, then rprims (which read their instancer's instances).
#include "hdeye/hd/changeTracker.h"
#include "hdeye/hd/instancer.h"
#include "hdeye/hd/prim.h"

#include <map>
#include <memory>
#include <string>

namespace hdeye {

class RenderDelegateInterface;

class RenderIndex {
 public:
  explicit RenderIndex(RenderDelegateInterface* renderDelegate);
  ~RenderIndex();
  RenderIndex(const RenderIndex&) = delete;
  RenderIndex& operator=(const RenderIndex&) = delete;

  /// Inserts a prim of a supported type; throws std::invalid_argument for an unsupported type or an
  /// id already in use. The prim starts with all the dirty bits it declares.
  void InsertRprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id);
  void InsertSprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id);
  void InsertBprim(const std::string& type, SceneDelegate* sceneDelegate, const PrimId& id);
  /// Inserts an instancer (HdRenderIndex::InsertInstancer); its rprims name it through GetInstancerId.
  void InsertInstancer(SceneDelegate* sceneDelegate, const PrimId& id);
  /// Removes (and finalizes) a prim; unknown ids are ignored.
  void RemovePrim(const PrimId& id);

  ChangeTracker& GetChangeTracker() { return tracker_; }
  RenderDelegateInterface* GetRenderDelegate() { return delegate_; }

  /// Syncs every prim that has dirty bits. On bad data a prim's Sync throws; the error propagates
  /// with the prim's id in its message, and the prim keeps its dirty bits.
  void SyncAll();

  Rprim* GetRprim(const PrimId& id) const { return Find(rprims_, id); }
  Sprim* GetSprim(const PrimId& id) const { return Find(sprims_, id); }
  Bprim* GetBprim(const PrimId& id) const { return Find(bprims_, id); }
  const Instancer* GetInstancer(const PrimId& id) const { return Find(instancers_, id); }

  template <class T> struct Entry {
    std::string type;
    SceneDelegate* sceneDelegate;
    std::unique_ptr<T> prim;
  };
  const std::map<PrimId, Entry<Rprim>>& Rprims() const { return rprims_; }
  const std::map<PrimId, Entry<Sprim>>& Sprims() const { return sprims_; }

 private:
  template <class T> static T* Find(const std::map<PrimId, Entry<T>>& m, const PrimId& id) {
    auto it = m.find(id);
    return it == m.end() ? nullptr : it->second.prim.get();
  }
  template <class T> void Insert(std::map<PrimId, Entry<T>>& m, std::unique_ptr<T> prim, const std::string& type,
                                 SceneDelegate* sceneDelegate, const PrimId& id);
  template <class T> void SyncMap(std::map<PrimId, Entry<T>>& m);

  RenderDelegateInterface* delegate_;
  ChangeTracker tracker_;
  std::map<PrimId, Entry<Rprim>> rprims_;
  std::map<PrimId, Entry<Sprim>> sprims_;
  std::map<PrimId, Entry<Bprim>> bprims_;
  std::map<PrimId, Entry<Instancer>> instancers_;
};

}  // namespace hdeye
