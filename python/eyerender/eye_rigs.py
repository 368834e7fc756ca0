"""Eye rigs as studios build them: which prims of an eye rig the renderer leaves out, and which it warns about.

A studio eye is several meshes: the eyeball (sclera and iris), a separate transparent cornea shell over it, often a
tear-line strip along the lid margin and an occlusion shell that darkens the corners. EyeAPI goes on the eyeball
mesh; its `eye:corneaShell` relationship names the shell (meshes, or Xforms/Scopes holding them). The analytic
anterior segment refracts the light once, so the shells are not rendered at all: rendered, a clear shell would
refract a second time and, closed, block the iris's MNEE shadow rays. The tear line and occlusion shell are ordinary
meshes and render as authored (open meshes with opacity < 1 are thin walls in the renderer: light passes them
straight, shadow rays by (1 - opacity)).

An un-targeted mesh that looks like a shell (a clear material, opacity <= CLEAR_OPACITY, whose world bounds contain
an eye's corneal apex; or one named like a cornea whose bounds contain it) still renders as authored, with one
warning naming it and the eye, so a lighter learns why the iris looks doubly refracted and shadowed.
"""
from pxr import Sdf, Usd, UsdGeom, UsdShade

from . import eyes
from .errors import EyeRenderError
from .materials import bound_material
from .validation import reading

# A shell is clear glass; occlusion shells and tear lines are partly opaque (and a dark occlusion shell over the
# cornea must not be mistaken for one).
CLEAR_OPACITY = 0.2
SHELL_NAME_WORDS = ("cornea", "corneal")


def _forwarded_targets(prim, name):
    rel = prim.GetRelationship(name)
    return rel.GetForwardedTargets() if rel else []


def _meshes_under(prim):
    return [p for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate))
            if p.IsA(UsdGeom.Mesh)]


def _surface_opacity(prim):
    """The constant opacity input of prim's bound UsdPreviewSurface (1 without one, or when it is connected)."""
    material = bound_material(prim)
    shader = material.ComputeSurfaceSource()[0] if material else None
    if not shader or shader.GetIdAttr().Get() != "UsdPreviewSurface":
        return 1.0
    opacity = shader.GetInput("opacity")
    attrs = opacity.GetValueProducingAttributes() if opacity else []
    value = attrs[0].Get() if attrs and UsdShade.Utils.GetType(attrs[0].GetName()) != \
        UsdShade.AttributeType.Output else None
    try:
        return float(value) if value is not None else 1.0
    except (TypeError, ValueError):
        return 1.0


class EyeRigs:
    """The cornea shells of a stage's eyes (eye:corneaShell), found once before the scene delegate populates."""

    def __init__(self, stage, warnings, time=Usd.TimeCode.Default()):
        self.stage, self.warnings, self.time = stage, warnings, Usd.TimeCode(time)
        self.shell_of = {}   # shell mesh path -> the eye prim path whose analytic cornea replaces it
        self.eye_paths = []  # every prim with EyeAPI, for the look-alike warning
        for prim in Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)):
            if eyes.is_eye(prim):
                self.eye_paths.append(prim.GetPath())
                try:
                    with reading(prim.GetPath()):
                        self._add_shells(prim)
                except EyeRenderError as e:  # the eye still renders (its shell then refracts twice)
                    self.warnings.append(f"{e}: eye:corneaShell ignored")

    def _add_shells(self, eye):
        for target in _forwarded_targets(eye, "eye:corneaShell"):
            prim = self.stage.GetPrimAtPath(target)
            if not prim or not prim.IsValid():
                self.warnings.append(f"{eye.GetPath()}: eye:corneaShell target {target} does not exist (ignored)")
                continue
            meshes = [m for m in _meshes_under(prim) if m.GetPath() != eye.GetPath()]
            if not meshes:
                self.warnings.append(f"{eye.GetPath()}: eye:corneaShell target {target} holds no mesh other than "
                                     f"the eye (ignored)")
            for mesh in meshes:
                self.shell_of.setdefault(mesh.GetPath(), eye.GetPath())

    def is_shell(self, prim):
        """Whether prim is a targeted cornea shell (the scene delegate then leaves it, and its subtree, out)."""
        return prim.GetPath() in self.shell_of

    def warn_look_alikes(self, mesh_paths):
        """One warning per rendered mesh in `mesh_paths` that looks like an eye's cornea shell (module doc)."""
        if not self.eye_paths:
            return
        bboxes = UsdGeom.BBoxCache(self.time, [UsdGeom.Tokens.default_, UsdGeom.Tokens.render,
                                               UsdGeom.Tokens.proxy], useExtentsHint=False)
        xforms = UsdGeom.XformCache(self.time)
        apexes = []
        for path in self.eye_paths:
            eye = self.stage.GetPrimAtPath(path)
            try:  # an unreadable eye is the scene delegate's to report (and skip): no look-alike of it
                with reading(path):
                    model = eye.GetAttribute("eye:modelTransform").Get(self.time) if eye.HasAttribute(
                        "eye:modelTransform") else None
                    model = model if model is not None else eyes.FALLBACKS["eye:modelTransform"]
                    apexes.append((path, (model * xforms.GetLocalToWorldTransform(eye)).Transform((0.0, 0.0, 0.0))))
            except EyeRenderError:
                continue
        eye_set = set(self.eye_paths)
        for path in mesh_paths:
            path = Sdf.Path(path)
            prim = self.stage.GetPrimAtPath(path)
            if not prim or path in eye_set or path in self.shell_of:
                continue
            named = any(word in path.name.lower() for word in SHELL_NAME_WORDS)
            if not named and _surface_opacity(prim) > CLEAR_OPACITY:
                continue
            box = bboxes.ComputeWorldBound(prim).ComputeAlignedRange()
            if box.IsEmpty():
                continue
            for eye_path, apex in apexes:
                if box.Contains(apex):
                    self.warnings.append(f"{path}: looks like a cornea shell of {eye_path}, not in its "
                                         f"eye:corneaShell: refracts twice, shadows the iris")
                    break
