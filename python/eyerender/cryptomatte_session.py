"""Cryptomatte coverage of a render session (cryptomatte.py is the format): the names of what each sample's first
hit was, and their coverage, accumulated pass by pass from the renderer's hitId AOV (one sample per pixel per
pass, the buffer cleared before each)."""
import numpy as np
from pxr import Kind, Sdf, Usd, UsdGeom, UsdShade

from .cryptomatte import TYPES, CoverageTable, id_bits
from .materials import bound_material


def _material_name(material):
    return material.GetPath().pathString if material else None


class HitNames:
    """The object, material and asset names of a hit (rprim id, instance index, materialBind subset), from the
    scene delegate's record of what each rprim was made from; cached."""

    def __init__(self, scene):
        self.scene = scene
        self._cache = {}

    def names(self, rprim, instance, subset):
        key = (rprim, instance, subset)
        if key not in self._cache:
            self._cache[key] = self._resolve(rprim, instance, subset)
        return self._cache[key]

    def _resolve(self, rprim, instance, subset):
        scene = self.scene
        prim, binding = scene.instanced_prims.get(rprim, (None, None))
        if prim is None:
            prim = binding = scene.stage.GetPrimAtPath(rprim) if Sdf.Path.IsValidPathString(rprim) else Usd.Prim()
        names = scene.instance_names.get(rprim)
        obj = names[instance] if names and 0 <= instance < len(names) else rprim
        material = _material_name(bound_material(binding, scene.material_purposes)) if binding else None
        if subset >= 0 and binding:
            subsets = [s for s in UsdShade.MaterialBindingAPI(binding).GetMaterialBindSubsets()
                       if s.GetElementTypeAttr().Get() == UsdGeom.Tokens.face]
            if subset < len(subsets):
                subset_material = bound_material(subsets[subset].GetPrim(), scene.material_purposes)
                material = _material_name(subset_material) or material
        return obj, material, self._asset(binding if binding else prim, obj)

    @staticmethod
    def _asset(prim, obj):
        """The nearest ancestor-or-self that is a component model, else the top-level ancestor of `obj`."""
        p = prim
        while p and p.GetPath() != Sdf.Path.absoluteRootPath:
            # Any authored component kind, whatever the model hierarchy above it (asset roots are often ungrouped).
            if Kind.Registry.IsA(Usd.ModelAPI(p).GetKind() or "", Kind.Tokens.component):
                return p.GetPath().pathString
            p = p.GetParent()
        top = obj.split("/")
        return "/" + top[1] if len(top) > 1 and top[1] else obj


class CryptoCoverage:
    """Coverage tables of the cryptomatte layers a session writes, and the names each id stands for."""

    def __init__(self, scene, layers, height, width):
        self.hit_names = HitNames(scene)
        self.layers = tuple(layers)
        self.height, self.width = height, width
        self.reset()

    def reset(self):
        """Empty tables for a new frame; names are resolved afresh (a stage edit may have rebound a material)."""
        self.hit_names = HitNames(self.hit_names.scene)
        self.tables = {layer: CoverageTable(self.height, self.width) for layer in self.layers}
        self.manifests = {layer: {} for layer in self.layers}

    def add_pass(self, sums, counts, rprims_by_index):
        """Adds one pass (one sample per pixel) of the hitId buffer: sums float64 (h, w, 3) of (primIndex, instance,
        subset), counts (h, w); rprims_by_index: the rprim id of each primIndex."""
        values = np.rint(np.where(counts[..., None] > 0, sums / np.maximum(counts, 1)[..., None], 0)).astype(np.int64)
        prim, instance, subset = values[..., 0], values[..., 1], values[..., 2]
        key = ((prim + 1) << 44) | (instance << 19) | (subset + 1)  # 19, 25 and 19 bits: ids exact to 2^24
        unique, inverse = np.unique(key, return_inverse=True)
        luts = {layer: np.zeros(len(unique), np.uint32) for layer in self.layers}
        for n, k in enumerate(unique.tolist()):
            p = (k >> 44) - 1
            if p < 0 or p >= len(rprims_by_index):
                continue  # no hit: id 0
            names = self.hit_names.names(rprims_by_index[p], (k >> 19) & ((1 << 25) - 1), (k & ((1 << 19) - 1)) - 1)
            for layer in self.layers:
                name = names[TYPES[layer]]
                if name:
                    bits = id_bits(name)
                    luts[layer][n] = bits
                    self.manifests[layer][name] = bits
        for layer in self.layers:
            ids = luts[layer][inverse.reshape(key.shape)]
            self.tables[layer].add(ids, counts, counts)

    def merge(self, tables, manifests):
        """Adds another sample range's tables and manifests (later samples)."""
        for layer in self.layers:
            self.tables[layer].merge(tables[layer])
            self.manifests[layer].update(manifests[layer])


__all__ = ["HitNames", "CryptoCoverage"]
