"""usdrecord's camera light, for stages with no light of their own: without it such a stage renders black.

usdrecord (UsdAppUtils.FrameRecorder) lights every frame with a light at the camera, which Storm shades as a
headlight. Here it is a distant light along the camera's view: light comes from the camera's position in every
pixel's direction of view, shadows fall behind what the camera sees, and, unlike a point light, its brightness does
not depend on the scene's units or the camera's distance. Irradiance pi makes a white Lambertian surface facing
the camera render at its albedo, as a Storm headlight of diffuse 1 shades it.
"""
import math

import numpy as np

from ._hdeye import LightParams

CAMERA_LIGHT_ID = "/__eyerender_camera_light"
CAMERA_LIGHT_IRRADIANCE = math.pi  # on a surface facing the camera; scene-unit free
CAMERA_LIGHT_ANGLE = 0.53  # degrees of angular diameter, UsdLux's distant-light default

NOTE = "the stage has no lights: added a camera light (a distant light from the camera; --disableCameraLight: none)"


def camera_light_params():
    """LightParams of the camera light: white, CAMERA_LIGHT_IRRADIANCE, CAMERA_LIGHT_ANGLE. Normalized, as UsdLux
    defines it for a distant light: the intensity is then the illuminance (else it is the disc's radiance)."""
    p = LightParams()
    p.color, p.intensity, p.exposure, p.angle = (1.0, 1.0, 1.0), CAMERA_LIGHT_IRRADIANCE, 0.0, CAMERA_LIGHT_ANGLE
    p.normalize = True
    return p


def add_camera_light(store, camera_to_world):
    """Adds the camera light to `store`, oriented by the camera-to-world 4x4 float64 matrix (a distant light emits
    along its -z, the camera looks along its -z)."""
    store.add_light(CAMERA_LIGHT_ID, "distantLight", camera_light_params(), np.asarray(camera_to_world))


def follow_camera(store, camera_to_world):
    """Moves the camera light with an animated camera."""
    store.set_transform(CAMERA_LIGHT_ID, np.asarray(camera_to_world))


__all__ = ["CAMERA_LIGHT_ID", "CAMERA_LIGHT_IRRADIANCE", "NOTE", "camera_light_params", "add_camera_light",
           "follow_camera"]
