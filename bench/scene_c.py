#!/usr/bin/env python3
"""Scene C: scene B's analytic eye and camera under a shot's lighting, with a reference made without the renderer.

    python3 bench/scene_c.py OUT_DIR [--scene-b DIR] [--quick] [--check]

Writes OUT_DIR/sceneC.usda, its dome OUT_DIR/dome.exr and the reference OUT_DIR/reference.npy (256 x 256, rows top
to bottom, each pixel the mean over its square footprint), with scene B's mask beside it (mask.npy). The lights:
- Fill: scene B's sphere light (radius 1 mm, 100 mm away, 62 degrees off the gaze) at a quarter of its radiance
  (FILL_RADIANCE);
- Key: a RectLight KEY_SIZE mm square, KEY_DISTANCE mm from the apex, KEY_OFF_GAZE_DEG off the gaze on the side
  away from the camera, facing the apex, radiance KEY_RADIANCE;
- Dome: a lat-long DomeLight whose HDR image this script makes (dome_image: a sky brightening to the horizon, a dim
  floor and a bright soft window WINDOW_GAIN times the sky, up and in front of the eye), hidden from the camera.
The reference is the sum of two estimators, neither of them the renderer's: scene B's own reference times
FILL_RADIANCE / 1000 for the fill (its caustic, chamber light and glint, computed independently of this project),
and build/bench/scene_c_reference for the key and the dome (eyelib's surface and optics with deterministic
quadrature: see that file). --check prints the quadrature's and interpolation's own errors; --quick is a coarse
reference for trying the script (minutes less, not for measuring).
"""
import argparse
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SCENE_B = os.environ.get("EYERENDER_SCENE_B", "/work/shared/bench/sceneB")
DEFAULT_REFERENCE_PROGRAM = os.path.join(HERE, "..", "build", "bench", "scene_c_reference")
SCENE_B_RADIANCE = 1000.0
FILL_RADIANCE = 250.0
KEY_SIZE, KEY_DISTANCE, KEY_OFF_GAZE_DEG, KEY_AZIMUTH_DEG, KEY_RADIANCE = 40.0, 120.0, 35.0, 20.0, 3.0
DOME_SIZE = (512, 256)
DOME_INTENSITY = 0.02
WINDOW_GAIN = 20.0
WINDOW_ELEVATION_DEG, WINDOW_AZIMUTH_DEG, WINDOW_WIDTH_DEG = 45.0, 15.0, 12.0
# The reference's resolution (scene_c_reference's keys): the full one and --quick's.
FULL = {"grid_nodes": 257, "base_cells": 40, "sub_cells": 12, "refine_tolerance": 0.01, "chamber_nodes": 65,
        "chamber_directions": 48, "chamber_sub_cells": 4, "chamber_iterations": 8, "subpixels": 16}
QUICK = {"grid_nodes": 65, "base_cells": 20, "sub_cells": 6, "refine_tolerance": 0.05, "chamber_nodes": 33,
         "chamber_directions": 16, "chamber_sub_cells": 2, "chamber_iterations": 4, "subpixels": 4}


def dome_image(width, height, gain=WINDOW_GAIN):
    """Grey lat-long radiance (rows top to bottom; OpenEXR's convention: row 0 at latitude +90 degrees, column 0 at
    longitude +180, longitude 0 along +z, +90 along +x): a sky from 1 at the zenith to 1.6 at the horizon, a floor of
    0.3, and a window `gain` x the sky, WINDOW_WIDTH_DEG wide with soft edges (a smooth bump a few texels
    across: the texture's filtering cannot matter)."""
    lat = (0.5 - (np.arange(height) + 0.5) / height)[:, None] * math.pi
    lon = (1 - 2 * (np.arange(width) + 0.5) / width)[None, :] * math.pi
    sky = np.where(lat > 0, 1.0 + 0.6 * (1 - np.sin(np.maximum(lat, 0))), 0.3)
    d = np.stack(np.broadcast_arrays(np.cos(lat) * np.sin(lon), np.sin(lat), np.cos(lat) * np.cos(lon)), -1)
    we, wa = math.radians(WINDOW_ELEVATION_DEG), math.radians(WINDOW_AZIMUTH_DEG)
    centre = np.array([math.cos(we) * math.sin(wa), math.sin(we), math.cos(we) * math.cos(wa)])
    angle = np.degrees(np.arccos(np.clip(d @ centre, -1, 1)))
    window = 1 / (1 + np.exp((angle - WINDOW_WIDTH_DEG / 2) / 1.5))
    return (sky * (1 + (gain - 1) * window)).astype(np.float32)


def write_exr(path, grey):
    import OpenEXR
    channels = {c: np.ascontiguousarray(grey) for c in "RGB"}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(path)


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    from pxr import Gf
    eye, target, up = (np.asarray(a, np.float64) for a in (eye, target, up))
    back = (eye - target) / np.linalg.norm(eye - target)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    rows = [list(right) + [0.0], list(np.cross(back, right)) + [0.0], list(back) + [0.0], list(eye) + [1.0]]
    return Gf.Matrix4d(*[float(v) for row in rows for v in row])


def write_stage(out_dir, scene_b):
    """sceneC.usda: scene B's eye and camera, its light turned into the fill, the rect key and the dome."""
    from pxr import Sdf, Usd, UsdLux
    write_exr(os.path.join(out_dir, "dome.exr"), dome_image(*DOME_SIZE))
    source = Sdf.Layer.FindOrOpen(os.path.join(scene_b, "sceneB.usda"))
    path = os.path.join(out_dir, "sceneC.usda")
    layer = Sdf.Layer.CreateNew(path)
    layer.TransferContent(source)
    stage = Usd.Stage.Open(layer)
    stage.GetRootLayer().documentation = "Scene C (bench/scene_c.py): scene B's eye and camera, a fill, a rect, a dome"
    fill = UsdLux.SphereLight(stage.GetPrimAtPath("/World/Key"))
    fill.GetIntensityAttr().Set(FILL_RADIANCE)
    edit = Sdf.BatchNamespaceEdit()
    edit.Add("/World/Key", "/World/Fill")
    layer.Apply(edit)
    key = UsdLux.RectLight.Define(stage, "/World/Key")
    key.CreateWidthAttr(KEY_SIZE)
    key.CreateHeightAttr(KEY_SIZE)
    key.CreateIntensityAttr(KEY_RADIANCE)
    key.CreateNormalizeAttr(False)
    t, a = math.radians(KEY_OFF_GAZE_DEG), math.radians(KEY_AZIMUTH_DEG)
    position = KEY_DISTANCE * np.array([math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)])
    key.AddTransformOp().Set(look_at(position, (0.0, 0.0, 0.0)))
    dome = UsdLux.DomeLight.Define(stage, "/World/Dome")
    dome.CreateIntensityAttr(DOME_INTENSITY)
    dome.CreateTextureFileAttr(Sdf.AssetPath("./dome.exr"))
    dome.CreateTextureFormatAttr(UsdLux.Tokens.latlong)
    stage.GetRootLayer().Save()
    return path


def reference_scene_lines(stage_path, resolution, threads):
    """scene_c_reference's scene file, read from the stage with UsdGeom and UsdLux (not the renderer's readers)."""
    from pxr import Gf, Usd, UsdGeom, UsdLux
    stage = Usd.Stage.Open(stage_path)
    eye = stage.GetPrimAtPath("/World/Eye")
    if UsdGeom.Xformable(eye).ComputeLocalToWorldTransform(0) != Gf.Matrix4d(1.0):
        sys.exit("scene_c: the eye must sit in the world frame (its canonical frame)")
    cam_prim = stage.GetPrimAtPath("/World/main_cam")
    cam = UsdGeom.Camera(cam_prim)
    m = UsdGeom.Xformable(cam_prim).ComputeLocalToWorldTransform(0)
    focal = cam.GetFocalLengthAttr().Get()
    key = UsdLux.RectLight(stage.GetPrimAtPath("/World/Key"))
    km = UsdGeom.Xformable(key.GetPrim()).ComputeLocalToWorldTransform(0)
    w, h = key.GetWidthAttr().Get(), key.GetHeightAttr().Get()
    dome = UsdLux.DomeLight(stage.GetPrimAtPath("/World/Dome"))

    def vec(v):
        return " ".join(repr(float(x)) for x in v)

    lines = {
        "iris_depth": eye.GetAttribute("eye:irisDepth").Get(),
        "pupil_diameter": eye.GetAttribute("eye:pupilDiameter").Get(),
        "cornea_ior": eye.GetAttribute("eye:corneaIor").Get(),
        "iris_albedo": float(np.mean(eye.GetAttribute("eye:irisColor").Get())),
        "camera_to_world": " ".join(repr(float(m[i][j])) for i in range(4) for j in range(4)),
        "tan_half_x": cam.GetHorizontalApertureAttr().Get() / 2 / focal,
        "tan_half_y": cam.GetVerticalApertureAttr().Get() / 2 / focal,
        "width": resolution, "height": resolution, "threads": threads,
        "rect_center": vec(km.Transform(Gf.Vec3d(0, 0, 0))),
        "rect_half_u": vec(km.TransformDir(Gf.Vec3d(w / 2, 0, 0))),
        "rect_half_v": vec(km.TransformDir(Gf.Vec3d(0, h / 2, 0))),
        "rect_emit": vec(km.TransformDir(Gf.Vec3d(0, 0, -1))),
        "rect_radiance": key.GetIntensityAttr().Get() * 2 ** key.GetExposureAttr().Get(),
        "dome_size_width": DOME_SIZE[0], "dome_size_height": DOME_SIZE[1],
        "dome_scale": dome.GetIntensityAttr().Get() * 2 ** dome.GetExposureAttr().Get(),
    }
    return lines


def make_reference(out_dir, stage_path, scene_b, program, quick, check, threads=2):
    import OpenEXR
    settings = QUICK if quick else FULL
    scene_file = os.path.join(out_dir, "reference_scene.txt")
    lines = {**reference_scene_lines(stage_path, 256, threads), **settings}
    with open(scene_file, "w") as f:
        f.writelines(f"{k} {v}\n" for k, v in lines.items())
    with OpenEXR.File(os.path.join(out_dir, "dome.exr")) as f:  # the texels the renderer reads, as written
        np.asarray(f.channels()["RGB"].pixels, np.float32)[..., 0].tofile(scene_file + ".dome.f32")
    out = os.path.join(out_dir, "key_and_dome.f32")
    cmd = [program, scene_file, out] + (["--check"] if check else [])
    if subprocess.run(cmd, check=False).returncode != 0:
        sys.exit("scene_c: scene_c_reference failed")
    key_and_dome = np.fromfile(out, np.float32).reshape(256, 256).astype(np.float64)
    fill = np.load(os.path.join(scene_b, "reference.npy")).astype(np.float64) * (FILL_RADIANCE / SCENE_B_RADIANCE)
    np.save(os.path.join(out_dir, "reference_key_and_dome.npy"), key_and_dome)
    np.save(os.path.join(out_dir, "reference.npy"), key_and_dome + fill)
    np.save(os.path.join(out_dir, "mask.npy"), np.load(os.path.join(scene_b, "mask.npy")))
    return key_and_dome, fill


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir")
    parser.add_argument("--scene-b", default=DEFAULT_SCENE_B)
    parser.add_argument("--reference-program", default=DEFAULT_REFERENCE_PROGRAM)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args(argv)
    os.makedirs(args.out_dir, exist_ok=True)
    stage = write_stage(args.out_dir, args.scene_b)
    key_and_dome, fill = make_reference(args.out_dir, stage, args.scene_b, args.reference_program, args.quick,
                                        args.check)
    iris = np.load(os.path.join(args.scene_b, "mask.npy"))[..., 2] == 1
    share = key_and_dome[iris].sum() / (key_and_dome[iris].sum() + fill[iris].sum())
    print(f"scene C in {args.out_dir}: key and dome {share:.1%} of the iris light, the fill the rest")
    return 0


if __name__ == "__main__":
    sys.exit(main())
