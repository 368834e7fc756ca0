"""The production eye sample: two mesh eyes in a lidded head under a shot's lighting (production_head.usda).

Written by generate_samples.py (its helpers and the eye asset); everything is a pure function of the constants
below, like the other samples. The stage, in centimetres, Y up:
- /World/Head, a SkelRoot: a head Mesh (an ellipsoid, the eyes showing through its front) and four lids, sphere
  patches about each eyeball centre, each rigidly bound to its own joint of /World/Head/Skel; the SkelAnimation turns
  the upper lids down from 0 to LID_DROP_DEG degrees over the frames (frame 12 is the look-dev frame). Eyelashes are
  cubic BasisCurves along each upper lid's margin, bound to that lid's joint, so they shadow the cornea and the iris
  caustic under the key. A tear line (a wet, partly transparent open strip: a thin wall) lies along each lower margin.
- /World/EyeL, /World/EyeR: the eye asset (the EyeAPI eyeball with its iris and veined sclera textures), converging
  on a point 45 cm in front.
- Lights: a DomeLight with a lat-long Radiance HDR this script writes (a sky gradient, a warm floor and a bright
  window), a RectLight key from the upper left and a small SphereLight fill from the right.
- /World/Camera: 16:9 (1920 x 1080 at full size), the eyes about 200 pixels across.
"""
import math

import generate_samples as gs
import numpy as np
from pxr import Gf, Sdf, UsdGeom, UsdLux, UsdSkel, Vt

EYE_CENTERS_CM = {"L": (3.15, 0.0, 7.6), "R": (-3.15, 0.0, 7.6)}  # interpupillary distance 6.3 cm
GAZE_TARGET_CM = (-1.5, 1.0, 52.0)
HEAD_RADIUS_CM, HEAD_SCALE = 9.0, (0.78, 1.15, 1.0)
# Lids: spheres about the eyeball centre clearing the corneal apex (13.03 mm from the centre); margins as elevations
# above the gaze, degrees (the upper covers the top of the iris, the lower sits at the lower limbus).
UPPER_LID = {"radius_mm": 13.6, "elevation_deg": (22.0, 70.0)}
LOWER_LID = {"radius_mm": 13.4, "elevation_deg": (-70.0, -33.0)}
LID_HALF_WIDTH_DEG = 58.0  # each lid spans this azimuth either side of the gaze
LID_DROP_DEG = 8.0         # the upper lids' turn over the shot (degrees about the eyeball centre's x axis)
TEAR_LINE = {"radius_mm": 12.35, "elevation_deg": (-35.5, -32.5), "opacity": 0.3}
LASHES_PER_EYE = 72
LASH_LENGTH_MM, LASH_WIDTH_MM = (7.0, 10.0), (0.09, 0.02)  # length range; width at the root and the tip
DOME_SIZE = (512, 256)
FRAMES = (1, 24)


def direction(elevation_deg, azimuth_deg):
    """Unit direction from an eyeball centre at an elevation above the gaze plane and an azimuth about the y axis
    (gaze +z), both degrees; broadcasts."""
    e, a = np.radians(elevation_deg), np.radians(azimuth_deg)
    return np.stack(np.broadcast_arrays(np.sin(a) * np.cos(e), np.sin(e), np.cos(a) * np.cos(e)), axis=-1)


def grid_faces(rows, cols):
    """Quads of a (rows + 1) x (cols + 1) point grid, counter-clockwise seen from outside the sphere."""
    return [[i * (cols + 1) + j, i * (cols + 1) + j + 1, (i + 1) * (cols + 1) + j + 1, (i + 1) * (cols + 1) + j]
            for i in range(rows) for j in range(cols)]


def sphere_band_mesh(stage, path, center_cm, radius_mm, elevation_deg, divisions, material):
    """An open quad patch of the sphere of radius_mm about center_cm between two elevations, across the lid width."""
    rows, cols = divisions
    e = np.linspace(elevation_deg[0], elevation_deg[1], rows + 1)
    a = np.linspace(-LID_HALF_WIDTH_DEG, LID_HALF_WIDTH_DEG, cols + 1)
    points = np.asarray(center_cm) + radius_mm * gs.MM_TO_CM * direction(e[:, None], a[None, :]).reshape(-1, 3)
    faces = grid_faces(rows, cols)
    return gs.define_quad_mesh(stage, path, points, faces, UsdGeom.Tokens.none, material)


def head_mesh(stage, path, material, rows=48, cols=96):
    """The head: a polygonal ellipsoid (UV sphere scaled by HEAD_SCALE), poles on the y axis, its seam (the open
    meridian where the first and last columns of points meet) at the back: the subdivided surface is pinned along
    it, a crease down the face if it were in front."""
    theta = np.linspace(0, math.pi, rows + 1)[:, None]
    phi = np.linspace(math.pi, 3 * math.pi, cols + 1)[None, :]
    unit = np.stack(np.broadcast_arrays(np.sin(theta) * np.sin(phi), np.cos(theta), np.sin(theta) * np.cos(phi)), -1)
    points = (HEAD_RADIUS_CM * unit * np.asarray(HEAD_SCALE)).reshape(-1, 3)
    faces = [[f[0], f[3], f[2], f[1]] for f in grid_faces(rows, cols)]  # outward from the inside-out UV order
    return gs.define_quad_mesh(stage, path, points, faces, UsdGeom.Tokens.catmullClark, material)


def lash_curves(stage, path, center_cm, seed):
    """Cubic B-spline eyelashes rooted along the upper lid margin: each leaves the lid outwards, curls up, 4 points."""
    rng = np.random.default_rng(seed)
    azimuth = np.linspace(-0.85, 0.85, LASHES_PER_EYE) * LID_HALF_WIDTH_DEG + rng.uniform(-0.6, 0.6, LASHES_PER_EYE)
    margin = UPPER_LID["elevation_deg"][0]
    length = rng.uniform(*LASH_LENGTH_MM, LASHES_PER_EYE) * (1 - 0.45 * (azimuth / LID_HALF_WIDTH_DEG) ** 2)
    root = UPPER_LID["radius_mm"] * direction(margin, azimuth)
    out, up = direction(margin - 10.0, azimuth), np.array([0.0, 1.0, 0.0])
    curl = rng.uniform(0.55, 0.85, LASHES_PER_EYE)[:, None]
    points = [root + (length[:, None] * f) * ((1 - c * curl) * out + c * curl * up)
              for f, c in ((0.0, 0.0), (0.35, 0.15), (0.7, 0.55), (1.0, 1.0))]
    points = np.asarray(center_cm) + gs.MM_TO_CM * np.stack(points, axis=1).reshape(-1, 3)
    curves = UsdGeom.BasisCurves.Define(stage, path)
    pts = gs.rounded_vec3f_array(points, gs.POINT_DECIMALS)
    curves.CreatePointsAttr(pts)
    curves.CreateCurveVertexCountsAttr(Vt.IntArray([4] * LASHES_PER_EYE))
    curves.CreateTypeAttr(UsdGeom.Tokens.cubic)
    curves.CreateBasisAttr(UsdGeom.Tokens.bspline)
    curves.CreateWrapAttr(UsdGeom.Tokens.nonperiodic)
    widths = np.tile(np.interp(np.arange(4), (0, 3), LASH_WIDTH_MM) * gs.MM_TO_CM, LASHES_PER_EYE)
    curves.CreateWidthsAttr(Vt.FloatArray([round(float(w), 6) for w in widths]))
    curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    curves.CreateExtentAttr(UsdGeom.Boundable.ComputeExtentFromPlugins(curves, 0) or gs.extent_of(points))
    return curves


def skeleton(stage, root_path):
    """The head's skeleton: a head joint and one joint per lid at its eyeball centre, and the lids' animation."""
    joints = ["head"] + ["head/%sLid_%s" % (lid, side) for side in EYE_CENTERS_CM for lid in ("upper", "lower")]
    centers = [(0.0, 0.0, 0.0)] + [EYE_CENTERS_CM[side] for side in EYE_CENTERS_CM for _ in range(2)]
    skel = UsdSkel.Skeleton.Define(stage, root_path + "/Skel")
    skel.CreateJointsAttr(joints)
    world = [Gf.Matrix4d(1.0).SetTranslate(Gf.Vec3d(*c)) for c in centers]
    skel.CreateBindTransformsAttr(Vt.Matrix4dArray(world))
    skel.CreateRestTransformsAttr(Vt.Matrix4dArray(world))  # the head joint sits at the origin: local = world
    anim = UsdSkel.Animation.Define(stage, root_path + "/Skel/LidAnim")
    anim.CreateJointsAttr(joints)
    anim.CreateTranslationsAttr(Vt.Vec3fArray([Gf.Vec3f(*c) for c in centers]))
    anim.CreateScalesAttr(Vt.Vec3hArray([Gf.Vec3h(1, 1, 1)] * len(joints)))
    rotations = anim.CreateRotationsAttr()
    for frame in range(FRAMES[0], FRAMES[1] + 1):
        drop = LID_DROP_DEG * gs.smoothstep((frame - FRAMES[0]) / (FRAMES[1] - FRAMES[0]))
        turn = Gf.Rotation(Gf.Vec3d(1, 0, 0), round(float(drop), 6)).GetQuat()
        quats = [Gf.Quatf(1.0)] + [Gf.Quatf(turn) if "upper" in j else Gf.Quatf(1.0) for j in joints[1:]]
        rotations.Set(Vt.QuatfArray(quats), frame)
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    return skel, joints


def bind_rigid(prim, skel, joint_index):
    """Bind every point of `prim` to one joint with weight 1 (constant joint influences)."""
    binding = UsdSkel.BindingAPI.Apply(prim)
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(True, 1).Set(Vt.IntArray([joint_index]))
    binding.CreateJointWeightsPrimvar(True, 1).Set(Vt.FloatArray([1.0]))
    binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))


def dome_image(width, height):
    """Linear RGB lat-long radiance (rows top to bottom, +Y up at the top row): a blue sky brightening towards the
    horizon, a warm dim floor, and a soft window 20 times the sky, 40 degrees up, behind the camera's left."""
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    elevation = (0.5 - v[:, None]) * math.pi
    azimuth = (u[None, :] - 0.5) * 2 * math.pi
    sky = np.array([0.35, 0.5, 0.8]) * (0.6 + 0.4 * (1 - np.sin(np.clip(elevation, 0, None))))[..., None]
    floor = np.array([0.25, 0.18, 0.12]) * np.ones_like(elevation)[..., None]
    image = np.where((elevation > 0)[..., None], sky, floor)
    noise = gs.value_noise(u[None, :] * 64, v[:, None] * 32, gs.SEED + 11, 64)
    image = image * (0.85 + 0.3 * noise)[..., None]
    window = np.exp(-(((azimuth - math.radians(35)) / 0.25) ** 8 + ((elevation - math.radians(40)) / 0.18) ** 8))
    return image + 20.0 * window[..., None] * np.array([1.0, 0.97, 0.9])


def write_hdr(path, rgb):
    """A Radiance RGBE image, flat (uncompressed) scanlines, rows top to bottom."""
    rgb = np.maximum(np.asarray(rgb, np.float64), 0)
    peak = rgb.max(axis=-1)
    mantissa, exponent = np.frexp(peak)
    scale = np.where(peak > 1e-32, mantissa * 256.0 / np.maximum(peak, 1e-300), 0)
    rgbe = np.concatenate([np.floor(rgb * scale[..., None]), np.where(peak > 1e-32, exponent + 128, 0)[..., None]], -1)
    height, width = peak.shape
    header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)
    path.write_bytes(header + np.clip(rgbe, 0, 255).astype(np.uint8).tobytes())


def add_lights(stage, out):
    write_hdr(out / "assets" / "studio_dome.hdr", dome_image(*DOME_SIZE))
    dome = UsdLux.DomeLight.Define(stage, "/World/Lights/Dome")
    gs.set_light_common(dome, 0.25, (1.0, 1.0, 1.0))
    dome.CreateTextureFileAttr(Sdf.AssetPath("./assets/studio_dome.hdr"))
    dome.CreateTextureFormatAttr(UsdLux.Tokens.latlong)
    key = UsdLux.RectLight.Define(stage, "/World/Lights/Key")
    key.CreateWidthAttr(30.0)
    key.CreateHeightAttr(30.0)
    gs.set_light_common(key, 12.0, (1.0, 0.96, 0.9))
    key.AddTransformOp().Set(gs.look_at((-45.0, 50.0, 70.0), (0.0, 0.0, 8.0)))
    gs.add_sphere_light(stage, "/World/Lights/Fill", (55.0, 5.0, 40.0), 1.0, 300.0, (0.85, 0.9, 1.0))


def add_eyes(stage):
    for side, centre in EYE_CENTERS_CM.items():
        d = np.asarray(GAZE_TARGET_CM) - np.asarray(centre)
        eye = gs.reference_eye(stage, "/World/Eye" + side)
        eye.AddTranslateOp().Set(Gf.Vec3d(*centre))
        eye.AddRotateYOp().Set(round(math.degrees(math.atan2(d[0], d[2])), 6))
        eye.AddRotateXOp().Set(round(-math.degrees(math.atan2(d[1], math.hypot(d[0], d[2]))), 6))


def add_camera(stage):
    """16:9, 49 cm in front; a 36 mm film at 120 mm frames about 15 cm across: the eyes show ~200 px wide at 1920."""
    cam = gs.add_camera(stage, "/World/Camera", (4.0, 3.0, 57.0), (0.0, 0.6, 8.0), focal_length=120.0, aperture=36.0)
    cam.CreateVerticalApertureAttr(36.0 * 1080 / 1920)


def write_production_head(out):
    stage = gs.new_stage(out / "production_head.usda", "World", __doc__.split("\n\n")[0].strip(), animated=True)
    looks = "/World/Looks"
    skin = gs.preview_material(stage, looks + "/Skin", diffuse=(0.62, 0.40, 0.31), roughness=0.55)
    lid_skin = gs.preview_material(stage, looks + "/LidSkin", diffuse=(0.66, 0.42, 0.34), roughness=0.5)
    lash = gs.preview_material(stage, looks + "/Lash", diffuse=(0.02, 0.015, 0.012), roughness=0.4)
    tear = gs.preview_material(stage, looks + "/TearLine", diffuse=(0.85, 0.55, 0.5), roughness=0.1,
                               opacity=TEAR_LINE["opacity"], ior=1.33)
    root = UsdSkel.Root.Define(stage, "/World/Head")
    skel, joints = skeleton(stage, str(root.GetPath()))
    bind_rigid(head_mesh(stage, "/World/Head/Skin", skin).GetPrim(), skel, 0)
    for k, (side, centre) in enumerate(EYE_CENTERS_CM.items()):
        upper = sphere_band_mesh(stage, "/World/Head/UpperLid_" + side, centre, UPPER_LID["radius_mm"],
                                 UPPER_LID["elevation_deg"], (8, 24), lid_skin)
        lower = sphere_band_mesh(stage, "/World/Head/LowerLid_" + side, centre, LOWER_LID["radius_mm"],
                                 LOWER_LID["elevation_deg"], (8, 24), lid_skin)
        lashes = lash_curves(stage, "/World/Head/Lashes_" + side, centre, gs.SEED + 20 + k)
        gs.bind(lashes.GetPrim(), lash)
        for prim, joint in ((upper, "upper"), (lower, "lower"), (lashes, "upper")):
            bind_rigid(prim.GetPrim(), skel, joints.index("head/%sLid_%s" % (joint, side)))
        band = sphere_band_mesh(stage, "/World/Head/TearLine_" + side, centre, TEAR_LINE["radius_mm"],
                                TEAR_LINE["elevation_deg"], (1, 24), tear)
        bind_rigid(band.GetPrim(), skel, 0)
    add_eyes(stage)
    add_lights(stage, out)
    add_camera(stage)
    stage.GetRootLayer().Save()
