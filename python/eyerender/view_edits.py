"""eyeview's controls as edits of the stage, each authored in the stage's session layer (so the stage's own layers
are never touched, RenderSession follows the edit as it follows any stage edit, and "save" exports the layer as a
.usda to sublayer). An edit that is not a finite number in its control's range, or that leaves the eye's EyeAPI
values unreadable (eyes.read_eye_params, the renderer's own check), is refused with one line and undone: the last
good state stays.

Directions are azimuth and elevation in degrees about the stage's up axis, around a pivot: the eye's corneal apex
(or the stage's centre without an eye). Gaze is yaw and pitch in degrees about the eye's centre of rotation,
ROTATION_CENTRE_MM behind the apex in the canonical frame (millimetres, gaze +z)."""
import dataclasses
import math

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

from .errors import EyeRenderError
from .eyes import IRIS_DIAMETER_MM, is_eye, read_eye_params
from .validation import check_transform

ROTATION_CENTRE_MM = 13.0  # the eye's centre of rotation behind the corneal apex (about 13 mm in adults)
OP_NAME = "xformOp:transform:eyeview"  # the one op an edited prim's session-layer transform is
EYE_ATTRIBUTES = {"pupil": "eye:pupilDiameter", "limbusInner": "eye:limbusInnerRatio",
                  "limbusOuter": "eye:limbusOuterRatio", "irisDepth": "eye:irisDepth"}


@dataclasses.dataclass
class Control:
    name: str
    label: str
    unit: str
    low: float
    high: float
    value: float

    def check(self, value):
        """value as a float in [low, high]; EyeRenderError otherwise."""
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise EyeRenderError(f"{self.label}: '{value}' is not a number") from None
        if not math.isfinite(number):
            raise EyeRenderError(f"{self.label}: {value} is not a finite number")
        if not self.low <= number <= self.high:
            raise EyeRenderError(f"{self.label}: {number:g} {self.unit} is outside [{self.low:g}, {self.high:g}]")
        return number

    def as_dict(self):
        return dataclasses.asdict(self)


def _world(prim, time):
    return UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time)


def _direction(vector, up):
    """(azimuth, elevation) in degrees of `vector` about the `up` axis (a Gf.Vec3d of length 1)."""
    forward = Gf.Vec3d(0, 0, 1) if abs(up[2]) < 0.5 else Gf.Vec3d(0, -1, 0)  # azimuth 0
    side = Gf.Cross(up, forward)
    length = vector.GetLength() or 1.0
    elevation = math.degrees(math.asin(max(-1.0, min(1.0, Gf.Dot(vector, up) / length))))
    return math.degrees(math.atan2(Gf.Dot(vector, side), Gf.Dot(vector, forward))), elevation


def _orbit(azimuth_from, elevation_from, azimuth_to, elevation_to, up, vector):
    """The rotation (a Gf.Matrix4d) that carries a direction at (azimuth_from, elevation_from) to (azimuth_to,
    elevation_to): elevation about the horizontal axis across the direction, then azimuth about `up`."""
    across = Gf.Cross(vector, up)
    rotation = Gf.Matrix4d(1.0)
    if across.GetLength() > 1e-12:
        rotation.SetRotate(Gf.Rotation(across.GetNormalized(), elevation_to - elevation_from))
    return rotation * Gf.Matrix4d(1.0).SetRotate(Gf.Rotation(up, azimuth_to - azimuth_from))


def _about(pivot, rotation):
    """`rotation` about the point `pivot` (row vectors, as USD's matrices: p' = p * M)."""
    return Gf.Matrix4d(1.0).SetTranslate(-pivot) * rotation * Gf.Matrix4d(1.0).SetTranslate(pivot)


class StageEditor:
    """The controls of one stage's key light, render camera and first eye, edited through its session layer."""

    def __init__(self, stage, camera_path, time=Usd.TimeCode.Default()):
        self.stage, self.time, self.layer = stage, time, stage.GetSessionLayer()
        self.up = Gf.Vec3d(0, 0, 1) if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z else Gf.Vec3d(0, 1, 0)
        prims = list(stage.Traverse())
        self.eye = next((p for p in prims if is_eye(p)), None)
        self.light = self._key_light(prims)
        camera = stage.GetPrimAtPath(camera_path) if camera_path else None
        self.camera = camera if camera and camera.IsA(UsdGeom.Camera) else None
        self.pivot = self._pivot()
        self.worlds = {p.GetPath(): _world(p, time) for p in (self.eye, self.light, self.camera) if p}
        self.controls = {}
        self._add_light_controls()
        self._add_camera_controls()
        self._add_eye_controls()

    def _key_light(self, prims):
        """The brightest light that is not a dome (a dome has no direction): the key."""
        lights = [p for p in prims if p.HasAPI(UsdLux.LightAPI) and not p.IsA(UsdLux.DomeLight)]
        return max(lights, key=lambda p: UsdLux.LightAPI(p).GetIntensityAttr().Get(self.time) or 0.0, default=None)

    def _pivot(self):
        if self.eye:
            model = self.eye.GetAttribute("eye:modelTransform").Get(self.time) or Gf.Matrix4d(1.0)
            return (model * _world(self.eye, self.time)).ExtractTranslation()
        box = UsdGeom.BBoxCache(self.time, [UsdGeom.Tokens.default_]).ComputeWorldBound(self.stage.GetPseudoRoot())
        return box.ComputeCentroid() if not box.GetRange().IsEmpty() else Gf.Vec3d(0)

    def _add(self, name, label, unit, low, high, value):
        self.controls[name] = Control(name, label, unit, low, high, float(value))

    def _add_light_controls(self):
        if not self.light:
            return
        azimuth, elevation = _direction(self._offset(self.light), self.up)
        if self.light.IsA(UsdLux.DistantLight):  # a distant light shines along its -z: it comes from +z
            azimuth, elevation = _direction(Gf.Vec3d(_world(self.light, self.time).TransformDir((0, 0, 1))), self.up)
        self._add("keyAzimuth", "key azimuth", "deg", -180, 180, round(azimuth, 3))
        self._add("keyElevation", "key elevation", "deg", -89, 89, round(elevation, 3))
        intensity = UsdLux.LightAPI(self.light).GetIntensityAttr().Get(self.time) or 0.0
        self._add("keyIntensity", "key intensity", "", 0, max(1e6, 10 * intensity), intensity)

    def _add_camera_controls(self):
        if not self.camera:
            return
        offset = self._offset(self.camera)
        azimuth, elevation = _direction(offset, self.up)
        self._add("cameraAzimuth", "camera azimuth", "deg", -180, 180, round(azimuth, 3))
        self._add("cameraElevation", "camera elevation", "deg", -89, 89, round(elevation, 3))
        self._add("cameraDistance", "camera distance", "units", offset.GetLength() / 20, offset.GetLength() * 20,
                  offset.GetLength())

    def _add_eye_controls(self):
        if not self.eye:
            return
        params = read_eye_params(self.eye, self.time)
        self._add("pupil", "pupil diameter", "mm", 0, IRIS_DIAMETER_MM - 0.01, params.pupil_diameter)
        self._add("limbusInner", "limbus inner ratio", "", 0.01, 1, params.limbus_inner_ratio)
        self._add("limbusOuter", "limbus outer ratio", "", 0.01, 1, params.limbus_outer_ratio)
        self._add("irisDepth", "iris depth", "mm", 0.5, 6, params.iris_depth)
        self._add("gazeYaw", "gaze yaw", "deg", -45, 45, 0.0)
        self._add("gazePitch", "gaze pitch", "deg", -45, 45, 0.0)

    def _offset(self, prim):
        return self.worlds[prim.GetPath()].ExtractTranslation() - self.pivot if prim.GetPath() in self.worlds \
            else _world(prim, self.time).ExtractTranslation() - self.pivot

    def describe(self):
        """The controls for the page: [{name, label, unit, low, high, value}], and the prims they edit."""
        return {"controls": [c.as_dict() for c in self.controls.values()],
                "prims": {k: str(p.GetPath()) for k, p in (("light", self.light), ("camera", self.camera),
                                                           ("eye", self.eye)) if p}}

    def apply(self, name, value):
        """Sets control `name` to `value` through the session layer. EyeRenderError (one line) if the control is
        unknown or the value bad; the stage is then as before."""
        control = self.controls.get(name)
        if control is None:
            raise EyeRenderError(f"no control '{name}' (controls: {', '.join(self.controls)})")
        number = control.check(value)
        previous = control.value
        control.value = number
        with Sdf.ChangeBlock():
            undo = self._author(name)
        try:
            self._check(name)
        except EyeRenderError:
            control.value = previous
            with Sdf.ChangeBlock():
                undo()
            raise

    def _author(self, name):
        """Authors the control's current value; returns a function that restores what the layer held before."""
        with Usd.EditContext(self.stage, self.layer):
            if name in EYE_ATTRIBUTES:
                attribute = self.eye.GetAttribute(EYE_ATTRIBUTES[name])
                spec = self.layer.GetAttributeAtPath(attribute.GetPath())
                old = spec.default if spec else None
                attribute.Set(float(self.controls[name].value))
                return lambda: self._restore(attribute, old)
            if name == "keyIntensity":
                attribute = UsdLux.LightAPI(self.light).GetIntensityAttr()
                spec = self.layer.GetAttributeAtPath(attribute.GetPath())
                old = spec.default if spec else None
                attribute.Set(float(self.controls[name].value))
                return lambda: self._restore(attribute, old)
            prim = self.light if name.startswith("key") else self.camera if name.startswith("camera") else self.eye
            old = self._session_transform(prim)
            self._set_world(prim, self._moved_world(prim))
            return lambda: self._restore_transform(prim, old)

    def _restore(self, attribute, old):
        """Puts back what the session layer held of `attribute`: `old`, or no opinion at all (None)."""
        if old is not None:
            with Usd.EditContext(self.stage, self.layer):
                attribute.Set(old)
            return
        spec = self.layer.GetPropertyAtPath(attribute.GetPath())
        if spec:
            spec.owner.RemoveProperty(spec)

    def _check(self, name):
        if name in EYE_ATTRIBUTES or name.startswith("gaze"):
            read_eye_params(self.eye, self.time)  # the renderer's own check of the eye's values
        for prim in (self.eye, self.light, self.camera):
            if prim and prim.GetPath() in self.worlds:
                check_transform(prim.GetPath(), _world(prim, self.time))

    def _moved_world(self, prim):
        """The world transform the prim's controls ask for, from its authored one."""
        world, c = self.worlds[prim.GetPath()], self.controls
        if prim == self.light:
            return self._orbited(world, "key", None)
        if prim == self.camera:
            return self._orbited(world, "camera", c["cameraDistance"].value)
        model = self.eye.GetAttribute("eye:modelTransform").Get(self.time) or Gf.Matrix4d(1.0)
        gaze = Gf.Matrix4d(1.0).SetRotate(Gf.Rotation(Gf.Vec3d(1, 0, 0), -c["gazePitch"].value)) * \
            Gf.Matrix4d(1.0).SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), c["gazeYaw"].value))
        rotate = _about(Gf.Vec3d(0, 0, -ROTATION_CENTRE_MM), gaze)  # in the canonical frame
        return model.GetInverse() * rotate * model * world

    def _orbited(self, world, prefix, distance):
        """`world` carried about the pivot from its authored direction to the controls' (and to `distance`)."""
        offset = world.ExtractTranslation() - self.pivot
        if prefix == "key" and self.light.IsA(UsdLux.DistantLight):
            offset = Gf.Vec3d(world.TransformDir((0, 0, 1)))
        azimuth, elevation = _direction(offset, self.up)
        rotation = _orbit(azimuth, elevation, self.controls[f"{prefix}Azimuth"].value,
                          self.controls[f"{prefix}Elevation"].value, self.up, offset)
        moved = world * _about(self.pivot, rotation)
        if distance is not None and offset.GetLength() > 0:
            position = moved.ExtractTranslation()
            moved = moved * Gf.Matrix4d(1.0).SetTranslate((position - self.pivot) * (distance / offset.GetLength()
                                                                                      - 1.0))
        return moved

    def _session_transform(self, prim):
        """What the session layer holds of the prim's transform: (op value or None, op order or None)."""
        op = self.layer.GetAttributeAtPath(prim.GetPath().AppendProperty(OP_NAME))
        order = self.layer.GetAttributeAtPath(prim.GetPath().AppendProperty("xformOpOrder"))
        return (op.default if op else None), (order.default if order else None)

    def _set_world(self, prim, world):
        parent = UsdGeom.Xformable(prim.GetParent()).ComputeLocalToWorldTransform(self.time) \
            if prim.GetParent().IsA(UsdGeom.Xformable) else Gf.Matrix4d(1.0)
        local = world * parent.GetInverse()
        prim.CreateAttribute(OP_NAME, Sdf.ValueTypeNames.Matrix4d).Set(local)
        prim.CreateAttribute("xformOpOrder", Sdf.ValueTypeNames.TokenArray, variability=Sdf.VariabilityUniform) \
            .Set([OP_NAME])

    def _restore_transform(self, prim, old):
        value, order = old
        for name, held in ((OP_NAME, value), ("xformOpOrder", order)):
            self._restore(prim.GetAttribute(name), held)

    def save(self, path):
        """Writes the session layer (every edit) as a .usda file to sublayer over the stage."""
        if not str(path).endswith(".usda"):
            raise EyeRenderError(f"save: {path} must be a .usda file")
        if not self.layer.Export(str(path)):
            raise EyeRenderError(f"save: could not write {path}")
        return str(path)


__all__ = ["StageEditor", "Control", "EYE_ATTRIBUTES", "ROTATION_CENTRE_MM"]
