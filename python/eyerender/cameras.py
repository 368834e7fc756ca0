"""UsdGeom cameras to the delegate's CameraParams, and usdrecord's default camera for stages without one."""
import math

from pxr import Gf, UsdGeom

from ._hdeye import CameraParams
from .errors import EyeRenderError

# UsdGeomCamera stores apertures and focal length in tenths of a scene unit (Gf.Camera's convention); for a
# perspective camera only their ratio matters, an orthographic camera's apertures are its film size.
APERTURE_UNIT = 0.1


def read_camera(camera, time):
    """CameraParams for a UsdGeom.Camera at `time`; raises EyeRenderError for unusable values."""
    gf = camera.GetCamera(time)
    p = CameraParams()
    p.orthographic = gf.projection == Gf.Camera.Orthographic
    p.focal_length = gf.focalLength
    p.horizontal_aperture, p.vertical_aperture = gf.horizontalAperture, gf.verticalAperture
    if p.orthographic:
        p.horizontal_aperture *= APERTURE_UNIT
        p.vertical_aperture *= APERTURE_UNIT
    p.near_clip, p.far_clip = gf.clippingRange.min, gf.clippingRange.max
    path = camera.GetPath()
    # Depth of field: the f-number and the focus distance (scene units); the lens aperture is
    # focalLength * APERTURE_UNIT / fStop scene units across.
    p.f_stop, p.focus_distance = float(gf.fStop), float(gf.focusDistance)
    p.focal_length_unit = APERTURE_UNIT
    if not (math.isfinite(p.f_stop) and p.f_stop >= 0 and math.isfinite(p.focus_distance) and p.focus_distance >= 0):
        raise EyeRenderError(f"{path}: fStop ({p.f_stop:g}) and focusDistance ({p.focus_distance:g}) must be finite "
                             "and non-negative")
    values = (p.focal_length, p.horizontal_aperture, p.vertical_aperture, p.near_clip, p.far_clip)
    if not all(math.isfinite(v) for v in values) or min(values[:3]) <= 0:
        raise EyeRenderError(f"{path}: focal length and apertures must be positive and finite")
    if not 0 <= p.near_clip < p.far_clip:
        raise EyeRenderError(f"{path}: clipping range ({p.near_clip:g}, {p.far_clip:g}) is empty")
    return p


def depth_of_field_note(camera, time):
    """A warning when the camera asks for depth of field it cannot have (fStop > 0 with focusDistance 0), else
    None."""
    gf = camera.GetCamera(time)
    if gf.fStop > 0 and gf.projection != Gf.Camera.Orthographic and not gf.focusDistance > 0:
        return f"{camera.GetPath()}: fStop {gf.fStop:g} with focusDistance 0: rendered as a pinhole (no depth of field)"
    return None


def default_camera(stage, time, purposes, aspect):
    """(CameraParams, camera-to-world Gf.Matrix4d) framing the stage's bounds like usdrecord: a 50 mm lens
    looking down -z (along +z of the up axis' complement) from in front of the bounding box."""
    bounds = UsdGeom.BBoxCache(time, list(purposes)).ComputeWorldBound(stage.GetPseudoRoot()).ComputeAlignedRange()
    if bounds.IsEmpty():
        raise EyeRenderError("the stage has no camera and no geometry to frame")
    p = CameraParams()
    p.focal_length, p.horizontal_aperture = 50.0, 36.0
    p.vertical_aperture = p.horizontal_aperture / aspect
    center, radius = bounds.GetMidpoint(), bounds.GetSize().GetLength() / 2
    half_fov = math.atan(min(p.horizontal_aperture, p.vertical_aperture) / (2 * p.focal_length))
    distance = radius / math.sin(half_fov)
    eye = Gf.Vec3d(center)
    if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z:
        # Z up: look along +y, the camera's up is +z.
        eye[1] -= distance
        world = Gf.Matrix4d().SetLookAt(eye, center, Gf.Vec3d(0, 0, 1)).GetInverse()
    else:
        eye[2] += distance
        world = Gf.Matrix4d().SetLookAt(eye, center, Gf.Vec3d(0, 1, 0)).GetInverse()
    p.near_clip, p.far_clip = max(distance - radius, distance * 1e-4) * 0.5, (distance + radius) * 2
    return p, world
