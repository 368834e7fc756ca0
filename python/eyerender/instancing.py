"""Instancing for the USD scene delegate, as UsdImaging's instance adapters do it for Hydra: every PointInstancer
prototype and every native-instance prototype becomes one hdeye instancer (per-instance transforms, optional
displayColors) and its prims are added once, as prototype rprims drawn by that instancer, so memory grows with the
unique prototypes, not with the instances.

- PointInstancer: UsdGeom.PointInstancer.ComputeInstanceTransformsAtTime (prototype root transforms included) and
  ComputeMaskAtTime (inactiveIds and invisibleIds); primvars:displayColor with one value per instance colours the
  instances. Prototype prims get their transform relative to the prototype root.
- Nested PointInstancers: Embree on Debian is built with RTC_MAX_INSTANCE_LEVEL_COUNT 1 (one instance level), so a
  nested instancer's instances are flattened into a top-level list: every product of its transforms with its
  outer instances'.
- Native instances (instanceable prims): grouped by prototype and by the material bound at the instance root; the
  prototype's prims are bound as the group's first instance sees them.
- Eyes in a prototype are flattened (one eye prim per instance): MNEE needs each eye's own canonical frame and render
  plan. Cameras and lights in prototypes are skipped with a warning.
- flatten=True adds every instance as its own prims from the same instance lists: the reference instancing is tested
  against, not the default.

XXX: animated visibility of native instances and animated transforms of prims inside a prototype are read once.
"""
import dataclasses

import numpy as np
from pxr import Usd, UsdGeom

from . import curves, eyes, lights, motion
from .errors import EyeRenderError
from .materials import bound_material
from .usd_values import scalar_as_array


@dataclasses.dataclass
class InstanceGroup:
    """One prototype root and the world transforms (Gf.Matrix4d, row vectors: prototype-root space to world) of its
    instances, with optional per-instance colours; instancer_id names the hdeye instancer."""
    instancer_id: str
    root: Usd.Prim
    worlds: list
    colors: list = None
    first_instance: Usd.Prim = None  # native groups: the instance whose proxies bind the prototype's materials
    instance_paths: list = dataclasses.field(default_factory=list)  # native groups: their instance prims' paths
    root_colors: list = dataclasses.field(default_factory=list)  # native groups: each instance root's displayColor
    names: list = None  # each instance's stable name (cryptomatte.py): a native instance's path, `pi[id]` else

    def instance_names(self):
        return self.names if self.names is not None else [str(p) for p in self.instance_paths]


def _instance_colors(instancer, time, count):
    """primvars:displayColor of a PointInstancer with one value per instance, else None."""
    primvar = UsdGeom.PrimvarsAPI(instancer.GetPrim()).GetPrimvar("displayColor")
    if not primvar or not primvar.HasValue():
        return None
    values = primvar.ComputeFlattened(time)
    return [tuple(c) for c in values] if values is not None and len(values) == count else None


FALLBACK_COLOR = (0.18, 0.18, 0.18)  # what a prim without displayColor shows (MaterialParams' diffuseColor)


def _display_color(prim):
    """The displayColor primvar prim has (any interpolation) or inherits (constant), else None."""
    primvar = UsdGeom.PrimvarsAPI(prim).FindPrimvarWithInheritance("displayColor")
    return primvar if primvar and primvar.HasValue() else None


def _constant_color(prim, time):
    """The constant displayColor prim has or inherits (its first value), else None."""
    primvar = _display_color(prim)
    if primvar is None or primvar.GetInterpolation() != UsdGeom.Tokens.constant:
        return None
    values = scalar_as_array(primvar.ComputeFlattened(time))
    return tuple(values[0]) if values is not None and len(values) else None


def _invisible_within(prim, root, time):
    """Whether prim or an ancestor up to the prototype `root` is invisible at `time`. Above the root does not count,
    as in UsdImaging: prototypes are commonly kept under an invisible scope so that they do not render in place."""
    while True:
        attr = UsdGeom.Imageable(prim).GetVisibilityAttr()
        if attr and attr.Get(time) == UsdGeom.Tokens.invisible:
            return True
        if prim == root or not prim.GetParent() or prim.GetParent().IsPseudoRoot():
            return False
        prim = prim.GetParent()


# The prims of a prototype: as the stage's default predicate, except that a prototype may sit under an `over` (its
# own def is what counts, as in UsdImaging); an `over` inside it is not rendered, nor one as the root.
_PROTOTYPE_PRIMS = Usd.TraverseInstanceProxies(Usd.PrimIsActive & Usd.PrimIsLoaded & ~Usd.PrimIsAbstract &
                                               Usd.PrimHasDefiningSpecifier)


def _is_point_instancer(prim):
    return prim.IsA(UsdGeom.PointInstancer)


def _nested_instancers(root):
    """PointInstancers at or under a prototype root (not under one another: each is reached through its parent)."""
    it = iter(Usd.PrimRange(root, _PROTOTYPE_PRIMS))
    for prim in it:
        if _is_point_instancer(prim):
            it.PruneChildren()
            yield prim


def point_instancer_groups(prim, worlds, time, xforms, prefix=None, base_time=None, names=None):
    """The instance groups of PointInstancer `prim` at `time`, whose local space is at each of `worlds`
    (Gf.Matrix4d, row vectors), nested PointInstancers flattened into groups of their own. base_time (default
    `time`): the time whose samples velocities extrapolate from and whose prototype indices and mask say which
    instance is which (the frame's, for samples over a shutter: UsdGeom's baseTime). names: the path each of
    `worlds` names prim by (default its own); an instance is `name[id]`, id its `ids` entry, else its index."""
    base_time = time if base_time is None else base_time
    instancer = UsdGeom.PointInstancer(prim)
    prototypes = instancer.GetPrototypesRel().GetTargets()
    transforms = instancer.ComputeInstanceTransformsAtTime(time, base_time, UsdGeom.PointInstancer.IncludeProtoXform,
                                                           UsdGeom.PointInstancer.IgnoreMask) or []
    proto_indices = instancer.GetProtoIndicesAttr().Get(base_time) or []
    mask = instancer.ComputeMaskAtTime(base_time) or []
    colors = _instance_colors(instancer, base_time, len(proto_indices))
    ids = instancer.GetIdsAttr().Get(base_time)
    ids = list(ids) if ids is not None and len(ids) == len(proto_indices) else range(len(proto_indices))
    names = names or [prim.GetPath().pathString] * len(worlds)
    prefix = prefix or prim.GetPath().pathString
    stage = prim.GetStage()
    for p, target in enumerate(prototypes):
        root = stage.GetPrimAtPath(target)
        if not root or not root.IsValid() or not root.HasDefiningSpecifier():  # an over is not a prototype
            continue
        members = [k for k, index in enumerate(proto_indices[:len(transforms)])
                   if index == p and (not mask or mask[k])]
        group_worlds = [transforms[k] * w for w in worlds for k in members]
        group_colors = [colors[k] for _ in worlds for k in members] if colors else None
        group_names = [f"{name}[{ids[k]}]" for name in names for k in members]
        group_id = f"{prefix}/__prototype{p}"
        yield InstanceGroup(group_id, root, group_worlds, group_colors, names=group_names)
        for nested in _nested_instancers(root):
            relative, _ = xforms.ComputeRelativeTransform(nested, root)
            below = nested.GetPath().MakeRelativePath(root.GetPath().GetParentPath())
            yield from point_instancer_groups(
                nested, [relative * w for w in group_worlds], time, xforms, f"{group_id}/{below}", base_time,
                [f"{name}/{below}" for name in group_names])


def _matrices(worlds):
    """Gf.Matrix4d list as an (n, 4, 4) float64 array in USD's layout (what the delegate's instancer takes)."""
    return np.array([np.array(m, dtype=np.float64).reshape(4, 4) for m in worlds], dtype=np.float64).reshape(-1, 4, 4)


def _colors(colors):
    return None if colors is None else np.ascontiguousarray(np.array(colors, dtype=np.float32).reshape(-1, 3))


class Instancing:
    """Adds instance groups to a UsdSceneDelegate's store (the module doc says how)."""

    def __init__(self, delegate, flatten=False):
        self.delegate, self.flatten = delegate, flatten
        self._native = {}  # (prototype path, material path) -> InstanceGroup, filled during traversal
        self._instancers = set()  # the hdeye instancers added

    # -- point instancers --------------------------------------------------------------------------------------

    def add_point_instancer(self, prim):
        d = self.delegate
        groups = list(point_instancer_groups(prim, [d.world_of(prim)], d.time, d.xform_cache))
        # The PointInstancer owns its instancers, prototype prims and updater; an edit to a prototype re-populates it.
        with d.owning(prim.GetPath(), sources=[group.root.GetPath() for group in groups]):
            for group in groups:
                self._add_group(group, proxy_prefix=None)
            if not self.flatten and self._point_instancer_varies(prim):
                self._track_point_instancer(prim)

    def _track_point_instancer(self, prim):
        d = self.delegate

        def update(t):
            groups = self._groups_at(prim, t, UsdGeom.XformCache(t))
            samples = self._instance_samples(prim, t, groups)
            for instancer_id, (matrices, colors) in groups.items():
                d.store.set_instance_transforms(instancer_id, matrices, colors)
                if instancer_id in samples:
                    d.store.set_instance_transform_samples(instancer_id, samples[instancer_id].times,
                                                           samples[instancer_id].values)
        d.add_updater("instancer", update)

    def _groups_at(self, prim, time, cache, base_time=None):
        """{instancer id: ((m, 4, 4) instance transforms, colours or None)} of a PointInstancer's groups that have
        an instancer (eyes-only prototypes have none: flattened, static) at time code `time`."""
        groups = point_instancer_groups(prim, [cache.GetLocalToWorldTransform(prim)], time, cache,
                                        base_time=base_time)
        return {g.instancer_id: (_matrices(g.worlds), _colors(g.colors)) for g in groups
                if g.instancer_id in self._instancers}

    def _instance_samples(self, prim, frame, groups):
        """{instancer id: motion.Samples} of the groups whose instances move within the shutter (none when it is
        sharp); instance counts that change within it: one warning, sharp."""
        sampler = self.delegate.motion_sampler
        if not sampler.blurred:
            return {}
        authored, curved = motion.instancer_times([prim, *_nested_instancers_deep(prim)], sampler.interval())
        times = sampler.times(authored, prim.GetPath(), uniform=curved)
        try:
            samples = motion.instance_samples(sampler, prim.GetPath(), times, lambda t, cache: {
                k: m for k, (m, _) in self._groups_at(prim, Usd.TimeCode(t), cache, frame).items()})
        except EyeRenderError as e:
            sampler.warn(prim.GetPath(), "instances", f"{e}: rendered without motion blur")
            return {}
        return {k: s for k, s in samples.items()
                if not s.static and k in groups and s.values[0].shape == groups[k][0].shape}

    def _point_instancer_varies(self, prim):
        d = self.delegate
        for p in [prim, *_nested_instancers_deep(prim)]:
            pi = UsdGeom.PointInstancer(p)
            attrs = [pi.GetPositionsAttr(), pi.GetOrientationsAttr(), pi.GetScalesAttr(), pi.GetProtoIndicesAttr(),
                     pi.GetInvisibleIdsAttr(), pi.GetIdsAttr()]
            if any(a and a.ValueMightBeTimeVarying() for a in attrs) or d.transform_varies(p):
                return True
            if pi.GetVelocitiesAttr().HasAuthoredValue() or pi.GetAngularVelocitiesAttr().HasAuthoredValue():
                return True  # moves within a shutter
        return False

    # -- native instances --------------------------------------------------------------------------------------

    def add_native_instance(self, prim):
        """Records an instanceable prim met in traversal; its group is added by finish()."""
        d = self.delegate
        if UsdGeom.Imageable(prim) and UsdGeom.Imageable(prim).ComputeVisibility(d.time) == UsdGeom.Tokens.invisible:
            with d.owning(prim.GetPath(), sources=[prim.GetPath()]):  # made visible: populated as its own group
                return
        material = bound_material(prim, d.material_purposes)
        prototype = prim.GetPrototype()
        key = (prototype.GetPath().pathString, material.GetPath().pathString if material else "")
        group = self._native.get(key)
        if group is None:
            group = self._native[key] = InstanceGroup(f"{prim.GetPath()}/__instances", prototype, [],
                                                      first_instance=prim)
        group.worlds.append(d.world_of(prim))
        group.instance_paths.append(prim.GetPath())
        group.root_colors.append(_constant_color(prim, d.time))

    def finish(self):
        """Adds the native groups met since the last call, each owned by its instances' nearest common ancestor:
        an edit to one instance re-populates the group's every instance (stage_notices.py)."""
        d = self.delegate
        for group in self._native.values():
            # Its prototype is a source too: an instance added later re-populates the group it joins.
            sources = [*group.instance_paths, group.root.GetPath()]
            with d.owning(_common_ancestor(group.instance_paths), sources=sources):
                group.colors = self._native_instance_colors(group)
                self._add_group(group, proxy_prefix=group.first_instance.GetPath())
                self._add_nested_point_instancers(group)
        self._native.clear()

    def _native_instance_colors(self, group):
        """Per-instance colours of a native group from its instance roots' constant displayColor (UsdImaging's
        instance primvars, inherited by the prototype's prims), or None: no root has one, or a prototype prim has its
        own (which it keeps)."""
        if all(c is None for c in group.root_colors):
            return None
        if any(_display_color(leaf) is not None for leaf in self._leaves(group.root, group.first_instance.GetPath())):
            return None
        return [FALLBACK_COLOR if c is None else c for c in group.root_colors]

    def _add_nested_point_instancers(self, group):
        """The PointInstancers inside a native group's prototype, each drawn at every instance of the group (as they
        stand at the frame: their animation inside a native instance is not followed)."""
        d = self.delegate
        for nested in _nested_instancers(group.root):
            relative, _ = d.xform_cache.ComputeRelativeTransform(nested, group.root)
            below = nested.GetPath().MakeRelativePath(group.root.GetPath())
            prefix = f"{group.instancer_id}/{below}"
            names = [f"{name}/{below}" for name in group.instance_names()]
            for nested_group in point_instancer_groups(nested, [relative * w for w in group.worlds], d.time,
                                                       d.xform_cache, prefix, names=names):
                self._add_group(nested_group, proxy_prefix=None)

    # -- groups --------------------------------------------------------------------------------------------------

    def _leaves(self, root, proxy_prefix):
        """The prims under a prototype root the delegate renders, nested PointInstancers pruned (they are groups of
        their own) and cornea shells left out (eye_rigs.py; in a native prototype as the first instance's proxies
        are); lights and cameras are skipped with a warning."""
        d = self.delegate
        it = iter(Usd.PrimRange(root, _PROTOTYPE_PRIMS))
        for prim in it:
            imageable = UsdGeom.Imageable(prim)
            proxy = prim if proxy_prefix is None else \
                d.stage.GetPrimAtPath(proxy_prefix.AppendPath(prim.GetPath().MakeRelativePath(root.GetPath())))
            if _is_point_instancer(prim) or d.is_cornea_shell(proxy):
                it.PruneChildren()
                continue
            if imageable and _invisible_within(prim, root, d.time):
                it.PruneChildren()
                continue
            if imageable and imageable.ComputePurpose() not in d.purposes:
                continue  # not pruned: a child's own purpose overrides the one it inherits
            if prim.IsA(UsdGeom.Camera) or lights.light_type(prim):
                d.warnings.append(f"{prim.GetPath()}: a {prim.GetTypeName()} inside an instance prototype is not "
                                  f"rendered")
            elif prim.IsA(UsdGeom.Gprim) or (eyes.is_eye(prim) and prim.IsA(UsdGeom.Xformable)):
                yield prim

    def _add_group(self, group, proxy_prefix):
        """Adds a group's prototype prims once under its instancer, or (flatten, and eyes always) once per
        instance. proxy_prefix: a native group's first instance, whose proxies give the prims' materials."""
        d = self.delegate
        leaves = list(self._leaves(group.root, proxy_prefix))
        # Eyes, curves and points are copied per instance (the delegate instances meshes only).
        shared = [p for p in leaves if not eyes.is_eye(p) and not curves.is_curves_or_points(p)] \
            if not self.flatten else []
        if shared:
            d.store.add_instancer(group.instancer_id, _matrices(group.worlds), _colors(group.colors))
            d.own_prim(group.instancer_id)
            self._instancers.add(group.instancer_id)
        for prim in leaves:
            relative, _ = d.xform_cache.ComputeRelativeTransform(prim, group.root)
            # Named below the instancer as under the prototype's parent (PointInstancers: the prototype root is a
            # prim of its own) or under the prototype (native: the root stands for the instance prim).
            if proxy_prefix is None:
                relative_path, binding = prim.GetPath().MakeRelativePath(group.root.GetPath().GetParentPath()), prim
            else:
                relative_path = prim.GetPath().MakeRelativePath(group.root.GetPath())
                binding = d.stage.GetPrimAtPath(proxy_prefix.AppendPath(relative_path))
            names = [f"{name}/{relative_path}" for name in group.instance_names()]
            if prim in shared:
                prim_id = f"{group.instancer_id}/{relative_path}"
                d.add_instanced_prim(prim, prim_id, relative, group.instancer_id, binding)
                d.instance_names[prim_id] = names
                continue
            for k, world in enumerate(group.worlds):
                prim_id = f"{group.instancer_id}/instance_{k}/{relative_path}"
                d.add_instanced_prim(prim, prim_id, relative * world, "", binding)
                d.instance_names[prim_id] = [names[k]]
                if group.colors and prim.IsA(UsdGeom.Gprim):  # eyes keep their own colours
                    color = np.array([group.colors[k]], dtype=np.float32)
                    d.store.set_primvar(prim_id, "displayColor", "constant", color)


def _nested_instancers_deep(prim):
    """Every PointInstancer reachable through prim's prototypes (any depth)."""
    stage = prim.GetStage()
    for target in UsdGeom.PointInstancer(prim).GetPrototypesRel().GetTargets():
        root = stage.GetPrimAtPath(target)
        if root and root.IsValid():
            for nested in _nested_instancers(root):
                yield nested
                yield from _nested_instancers_deep(nested)


def _common_ancestor(paths):
    """The nearest prim path at or above every one of `paths` (Sdf.Path)."""
    common = paths[0]
    for path in paths[1:]:
        common = common.GetCommonPrefix(path)
    return common
