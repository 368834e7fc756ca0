#!/usr/bin/env python3
"""Generate eyeRender's sample USD stages, the procedural eye asset and its textures.

    python3 usd_samples/generate_samples.py [--out DIR]     (default: this folder)

Everything here is a pure function of the constants in this file: no clock, no unseeded randomness, no paths
written into the files, numbers rounded before they are written. Running it twice gives the same bytes, and
tests/python/test_samples.py checks that the committed files are what this script writes.

Frames and units
- Canonical eye frame: millimetres, corneal apex at the origin, gaze +z. The cornea formulas below
  mirror eyelib/include/eyelib/anterior_surface.h and eye_constants.h exactly (same constants, same root).
- Stages and the asset: centimetres (metersPerUnit 0.01), upAxis Y. The eyeball mesh has the eyeball centre at
  its local origin and gazes along local +z; eye:modelTransform (scale 0.1 plus the apex offset) maps the
  canonical frame into that local space.
"""
import argparse
import math
import pathlib
import random
import struct
import sys
import zlib

import numpy as np
from pxr import Gf, Kind, Plug, Sdf, Usd, UsdGeom, UsdLux, UsdShade, Vt

HERE = pathlib.Path(__file__).resolve().parent
SCHEMAS_DIR = HERE.parent / "schemas"

# --- The analytic anterior surface (mm), as eyelib computes it -------------------------------------------------
ELLIPSOID_Z2 = 0.75               # 0.75 z^2 + 15.6 z + r^2 = 0
ELLIPSOID_Z1 = 15.6
JUNCTION_RADIUS = 10.02 / 2       # ellipsoid inside, 38 degree cone outside
IRIS_DIAMETER = 15.08
RIM_RADIUS = IRIS_DIAMETER / 2
TAN_CONE = math.tan(math.radians(38.0))
IRIS_DEPTH = 3.735
LIMBUS_INNER_RATIO = 11.64 / IRIS_DIAMETER   # 0.772
LIMBUS_OUTER_RATIO = 12.89 / IRIS_DIAMETER   # 0.855
LIMBUS_OUTER_RADIUS = 12.89 / 2              # 6.445 mm: pure cornea inside this radius
CORNEA_IOR = 1.376
PUPIL_DIAMETER = 4.0

# --- The eyeball (mm) -------------------------------------------------------------------------------------------
SCLERA_RADIUS = 12.0              # a typical adult eyeball is ~24 mm across
BLEND_WIDTH = 0.5                 # cornea -> sclera blend, mm of radius from the gaze axis, just outside the limbus
# The sclera sphere meets the cornea in the middle of the blend band, so the blend only smooths the crease (the
# two surfaces differ by < 0.03 mm across the band).
SCLERA_MEET_RADIUS = LIMBUS_OUTER_RADIUS + BLEND_WIDTH / 2
CAGE_DIVISIONS = 16               # quads per cube-face edge: 6 * 16^2 = 1536 faces, 1538 points
FIT_ITERATIONS = 200

MM_TO_CM = 0.1
POINT_DECIMALS = 5                # cm; 0.1 micrometre, far below the fit residual
ANIMATED_POINT_DECIMALS = 4       # cm; 1 micrometre keeps 24 frames of points under ~1.5 MB of text
SEED = 20180812                   # SIGGRAPH 2018 Talks; any fixed value


def ellipsoid_sag(r):
    """Sag of 0.75 z^2 + 15.6 z + r^2 = 0 through the apex, mm; the cancellation-free root eyelib uses."""
    return -r * r / (ELLIPSOID_Z1 / 2 + np.sqrt(np.maximum(0.0, ELLIPSOID_Z1 ** 2 / 4 - ELLIPSOID_Z2 * r * r)))


JUNCTION_SAG = float(ellipsoid_sag(np.float64(JUNCTION_RADIUS)))


def cornea_sag(r):
    """Ellipsoid-cone sag f(r), mm (eyelib AnteriorSurface::Sag): the cone z = f(5.01) - (r - 5.01) tan 38deg
    beyond the junction, extrapolated past the 7.54 mm rim."""
    r = np.asarray(r, dtype=np.float64)
    return np.where(r < JUNCTION_RADIUS, ellipsoid_sag(r), JUNCTION_SAG - (r - JUNCTION_RADIUS) * TAN_CONE)


# Eyeball centre on the gaze axis, mm (canonical z): the sphere passes through the cornea at SCLERA_MEET_RADIUS.
EYEBALL_CENTER_Z = float(cornea_sag(SCLERA_MEET_RADIUS)) - math.sqrt(SCLERA_RADIUS ** 2 - SCLERA_MEET_RADIUS ** 2)


def smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def eyeball_radius(directions):
    """Distance (mm) from the eyeball centre to the target surface along unit directions (eyeball-centred frame,
    gaze +z): the cornea where R sin(theta) <= 6.445 mm, the sclera sphere beyond 6.945 mm, smoothstep between."""
    d = np.asarray(directions, dtype=np.float64)
    sin_t = np.hypot(d[:, 0], d[:, 1])
    cos_t = d[:, 2]
    w = smoothstep((SCLERA_RADIUS * sin_t - LIMBUS_OUTER_RADIUS) / BLEND_WIDTH)
    w = np.where(cos_t > 0, w, 1.0)                          # the back of the eyeball is all sclera
    rho = np.full(len(d), SCLERA_RADIUS)
    front = w < 1.0
    if np.any(front):
        # Cornea along the ray from the centre: EYEBALL_CENTER_Z + rho cos = f(rho sin). g(rho) increases (the
        # sag falls with r), so bisection on a bracket that holds the whole front is exact to rounding.
        s, c = sin_t[front], cos_t[front]
        lo = np.full(s.shape, SCLERA_RADIUS - 3.0)
        hi = np.full(s.shape, SCLERA_RADIUS + 3.0)
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            g = EYEBALL_CENTER_Z + mid * c - cornea_sag(mid * s)
            above = g > 0
            hi = np.where(above, mid, hi)
            lo = np.where(above, lo, mid)
        rho_cornea = 0.5 * (lo + hi)
        rho[front] = (1 - w[front]) * rho_cornea + w[front] * SCLERA_RADIUS
    return rho


# --- Catmull-Clark cage ----------------------------------------------------------------------------------------
def cube_sphere(n):
    """Closed all-quad cube-sphere: (unit directions (P, 3), face vertex indices (F, 4)), outward CCW winding.
    Equiangular (each cube coordinate c in [-1, 1] maps to tan(c pi/4)), so cells are near-uniform in angle and no
    pole degenerates; the +z face is centred on the gaze axis with a valence-4 vertex at the apex (n even)."""
    assert n % 2 == 0
    h = n // 2
    index = {}
    lattice = []
    faces = []

    def vid(key):
        if key not in index:
            index[key] = len(lattice)
            lattice.append(key)
        return index[key]

    # (normal axis, sign) in a fixed order; the front (+z) face first so the cornea points come first.
    for axis, sign in ((2, 1), (0, 1), (1, 1), (0, -1), (1, -1), (2, -1)):
        u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3   # u x v = +axis
        if sign < 0:
            u_axis, v_axis = v_axis, u_axis
        for j in range(-h, h):
            for i in range(-h, h):
                quad = []
                for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    key = [0, 0, 0]
                    key[axis] = sign * h
                    key[u_axis] = i + di
                    key[v_axis] = j + dj
                    quad.append(vid(tuple(key)))
                faces.append(quad)
    cube = np.array(lattice, dtype=np.float64) / h
    dirs = np.tan(cube * (math.pi / 4))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return dirs, np.array(faces, dtype=np.int64)


def limit_stencil(points, faces):
    """Catmull-Clark limit positions of the vertices of a closed all-quad mesh:
    (n^2 v + 4 sum(edge neighbours) + sum(face-diagonal neighbours)) / (n (n + 5)), any valence n. Summing the two
    in-face edge neighbours over a vertex's faces counts each edge neighbour twice, hence the factor 2 below."""
    valence = np.bincount(faces.ravel(), minlength=len(points)).astype(np.float64)
    edge_sum = np.zeros_like(points)
    diag_sum = np.zeros_like(points)
    for k in range(4):
        v = faces[:, k]
        np.add.at(edge_sum, v, points[faces[:, (k + 1) % 4]] + points[faces[:, (k + 3) % 4]])
        np.add.at(diag_sum, v, points[faces[:, (k + 2) % 4]])
    n = valence[:, None]
    return (n * n * points + 2 * edge_sum + diag_sum) / (n * (n + 5))


def catmull_clark_step(points, faces):
    """One Catmull-Clark refinement of a closed all-quad mesh: (points, faces) of the refined mesh."""
    nv = len(points)
    face_pts = points[faces].mean(axis=1)
    edges = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2).reshape(-1, 2)
    key = np.sort(edges, axis=1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    edge_faces = np.repeat(np.arange(len(faces)), 4)
    face_sum_per_edge = np.zeros((len(uniq), 3))
    np.add.at(face_sum_per_edge, inverse, face_pts[edge_faces])
    edge_pts = (points[uniq[:, 0]] + points[uniq[:, 1]] + face_sum_per_edge) / 4   # closed: 2 faces per edge
    valence = np.bincount(faces.ravel(), minlength=nv).astype(np.float64)[:, None]
    f_avg = np.zeros_like(points)
    for k in range(4):
        np.add.at(f_avg, faces[:, k], face_pts)
    f_avg /= valence
    r_avg = np.zeros_like(points)
    np.add.at(r_avg, uniq[:, 0], 0.5 * (points[uniq[:, 0]] + points[uniq[:, 1]]))
    np.add.at(r_avg, uniq[:, 1], 0.5 * (points[uniq[:, 0]] + points[uniq[:, 1]]))
    r_avg /= valence
    n = valence
    vert_pts = (f_avg + 2 * r_avg + (n - 3) * points) / n
    new_points = np.concatenate([vert_pts, edge_pts, face_pts])
    e_of = inverse.reshape(-1, 4) + nv               # edge k runs from corner k to corner k+1
    f_of = np.arange(len(faces)) + nv + len(uniq)
    new_faces = []
    for k in range(4):
        new_faces.append(np.stack([faces[:, k], e_of[:, k], f_of, e_of[:, (k + 3) % 4]], axis=1))
    return new_points, np.concatenate(new_faces)


def fit_cage(directions, faces, target_radius_fn, iterations):
    """Pre-compensate the cage for Catmull-Clark shrinkage: move each cage point by the gap between its limit
    position and the target surface (measured along the limit point's direction from the centre), repeatedly.
    The limit stencil's eigenvalues lie in (0, 1], so this fixed-point iteration converges."""
    cage = directions * target_radius_fn(directions)[:, None]
    for _ in range(iterations):
        lim = limit_stencil(cage, faces)
        lim_dir = lim / np.linalg.norm(lim, axis=1, keepdims=True)
        cage = cage + (lim_dir * target_radius_fn(lim_dir)[:, None] - lim)
    return cage


def limit_samples(cage, faces, levels=2):
    """Exact limit-surface points: refine `levels` times, then apply the limit stencil (25 points per cage face at
    level 2)."""
    p, f = cage, faces
    for _ in range(levels):
        p, f = catmull_clark_step(p, f)
    return limit_stencil(p, f)


def cornea_residuals(limit_points_mm):
    """(apex error, max |error| for r < outer limbus, max |error| near the limbus (r in [6.2, 6.445] mm),
    max |error| of the sclera beyond the blend), mm. Points are eyeball-centred (mm). Cornea errors are
    vertical (z - f(r)); sclera errors radial."""
    p = limit_points_mm
    z = p[:, 2] + EYEBALL_CENTER_Z
    r = np.hypot(p[:, 0], p[:, 1])
    front = (p[:, 2] > 0) & (r < LIMBUS_OUTER_RADIUS)
    err = z[front] - cornea_sag(r[front])
    apex = np.argmin(r + np.where(front, 0, 1e9))
    apex_err = abs(z[apex] - float(cornea_sag(r[apex])))
    near = (r[front] > LIMBUS_OUTER_RADIUS - 0.25)
    sclera = (p[:, 2] < 0) | (r > LIMBUS_OUTER_RADIUS + BLEND_WIDTH + 0.05)
    sclera_err = np.abs(np.linalg.norm(p[sclera], axis=1) - SCLERA_RADIUS)
    return apex_err, float(np.abs(err).max()), float(np.abs(err[near]).max()), float(sclera_err.max())


# --- PNG ---------------------------------------------------------------------------------------------------------
def write_png(path, rgb):
    """8-bit RGB PNG, every row with the 'Up' filter (better compression of smooth images), zlib level 9.
    rgb: uint8 array (height, width, 3), row 0 at the top of the image."""
    h, w, _ = rgb.shape
    up = rgb.astype(np.int16)
    up[1:] -= rgb[:-1].astype(np.int16)
    filtered = (up % 256).astype(np.uint8).reshape(h, w * 3)
    raw = np.concatenate([np.full((h, 1), 2, np.uint8), filtered], axis=1).tobytes()

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    pathlib.Path(path).write_bytes(png)


def linear_to_srgb8(c):
    c = np.clip(c, 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.round(s * 255).astype(np.uint8)


def _hash01(ix, iy, seed):
    """Uniform [0, 1) from integer lattice coordinates: integer mixing in uint32, identical on every platform."""
    h = (np.asarray(ix, np.int64) * 374761393 + np.asarray(iy, np.int64) * 668265263 + seed * 1442695041)
    h = h.astype(np.uint64) & np.uint64(0xFFFFFFFF)
    h = ((h ^ (h >> np.uint64(13))) * np.uint64(1274126177)) & np.uint64(0xFFFFFFFF)
    h = h ^ (h >> np.uint64(16))
    return h.astype(np.float64) / 4294967296.0


def value_noise(x, y, seed, period_x=None):
    """Smooth value noise on the integer lattice, optionally periodic in x (for angles)."""
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = smoothstep(x - x0), smoothstep(y - y0)
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    x1 = x0 + 1
    if period_x:
        x0, x1 = x0 % period_x, x1 % period_x
    a, b = _hash01(x0, y0, seed), _hash01(x1, y0, seed)
    c, d = _hash01(x0, y0 + 1, seed), _hash01(x1, y0 + 1, seed)
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


def iris_image(size=512):
    """Brown iris over the iris disk in the canonical frame: u along +x, v along +y, [0, 1]^2 = [-7.54, 7.54] mm,
    v = 0 at the bottom row. Linear albedo, sRGB-encoded. Pupil 4 mm (black), pupillary ruff, radial fibres,
    collarette at ~3.3 mm, crypts between collarette and 5.5 mm, dark limbal ring from ~6 mm to the 7.54 mm rim."""
    c = (np.arange(size) + 0.5) / size
    x = (c[None, :] - 0.5) * IRIS_DIAMETER                  # mm, columns -> +x
    y = (0.5 - c[:, None]) * IRIS_DIAMETER                  # mm, rows top -> bottom = +y -> -y
    rho = np.hypot(x, y)
    phi = np.arctan2(y, x) / (2 * math.pi) + 0.5            # [0, 1)
    pupil_r = PUPIL_DIAMETER / 2
    t = np.clip((rho - pupil_r) / (RIM_RADIUS - pupil_r), 0, 1)   # 0 at the pupil edge, 1 at the rim

    # Radial fibres: noise fast in angle, slow in radius; two octaves.
    fibres = 0.65 * value_noise(phi * 180, rho * 1.5, SEED + 1, 180) + 0.35 * value_noise(phi * 420, rho * 3.0,
                                                                                         SEED + 2, 420)
    wobble = 0.25 * (value_noise(phi * 24, np.zeros_like(rho), SEED + 3, 24) - 0.5)   # collarette wanders, mm
    collarette = np.exp(-((rho - 3.3 - wobble) / 0.28) ** 2)
    # Crypts: dark lacunae, elongated radially, between the collarette and ~5.6 mm: one candidate per cell of an
    # (angle, radius) lattice, jittered in both and open in ~40% of the cells.
    crypt = np.zeros_like(rho)
    for ring, (r0, width, count) in enumerate(((3.75, 0.9, 31), (4.6, 1.0, 43))):
        cu = phi * count
        ci = np.floor(cu).astype(np.int64) % count
        jitter_u = _hash01(ci, ring, SEED + 5) - 0.5
        jitter_r = (_hash01(ci, ring, SEED + 6) - 0.5) * 0.5 * width
        size = 0.6 + 0.8 * _hash01(ci, ring, SEED + 7)
        open_ = _hash01(ci, ring, SEED + 4) < 0.45
        du = (cu - np.floor(cu) - 0.5 - 0.5 * jitter_u) / (0.2 * size)
        dv = (rho - r0 - 0.5 * width - jitter_r) / (0.32 * size * width)
        crypt = np.maximum(crypt, np.where(open_, np.exp(-du ** 2 - dv ** 2), 0.0))
    limbal = smoothstep((rho - 5.9) / 1.0)
    ruff = np.exp(-((rho - pupil_r - 0.08) / 0.1) ** 2)

    base = np.array([0.13, 0.060, 0.024])        # linear albedo: mid brown
    light = np.array([0.30, 0.165, 0.065])       # fibre highlights (amber)
    dark = np.array([0.035, 0.016, 0.008])       # collarette, crypts, limbal ring
    col = base + (light - base) * (fibres[..., None] ** 1.5) * (1 - 0.5 * t[..., None])
    col = col + (dark - col) * (0.55 * collarette + 0.75 * crypt + 0.85 * limbal + 0.6 * ruff)[..., None]
    col = np.where((rho < pupil_r)[..., None], 0.004, col)
    return linear_to_srgb8(col)


def sclera_image(width=512, height=256):
    """Sclera albedo in the eyeball's spherical st (u = azimuth about the gaze / 2 pi, v = polar angle from the gaze
    / pi, v = 0 at the corneal apex; row 0 at the top is v = 1): off-white, a little redder away from the cornea,
    with thin veins that run from the equator toward the limbus (theta ~ 34 deg, v ~ 0.19) and fade there."""
    v = 1 - (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    vv = np.broadcast_to(v[:, None], (height, width))
    uu = np.broadcast_to(u[None, :], (height, width))
    blotch = value_noise(uu * 16, vv * 8, SEED + 10, 16)
    redness = 0.15 * smoothstep((vv - 0.25) / 0.35) + 0.05 * blotch
    white = np.array([0.80, 0.77, 0.72])
    red = np.array([0.62, 0.30, 0.26])
    col = white + (red - white) * redness[..., None]

    # Veins: random walks in (azimuth, polar angle) painted as soft lines; Python's random.random() is
    # reproducible across versions for a fixed seed.
    rng = random.Random(SEED + 11)
    vein = np.zeros((height, width))
    ys, xs = np.mgrid[-2:3, -2:3]

    def paint(px, py, strength):
        ix, iy = int(math.floor(px)), int(math.floor(py))
        if 2 <= iy < height - 3:
            fx, fy = px - ix, py - iy
            k = strength * np.exp(-((xs - fx) ** 2 + (ys - fy) ** 2) / 0.7)
            cols = np.arange(ix - 2, ix + 3) % width
            block = vein[iy - 2:iy + 3][:, cols]
            vein[np.ix_(np.arange(iy - 2, iy + 3), cols)] = np.maximum(block, k)

    walks = [(rng.random() * width, 0.42 + 0.3 * rng.random(), 0.5 + 0.5 * rng.random()) for _ in range(40)]
    while walks:
        px, vpos, strength = walks.pop()
        heading = 0.0
        while vpos > 0.2 and strength > 0.15:
            heading = 0.97 * heading + (rng.random() - 0.5) * 0.12
            px += heading
            vpos -= 0.0012
            fade = smoothstep((vpos - 0.19) / 0.15)
            paint(px, (1 - vpos) * height - 0.5, strength * fade)
            if rng.random() < 0.006:
                walks.append((px, vpos, strength * 0.75))
                strength *= 0.9
    vein_col = np.array([0.45, 0.06, 0.05])
    col = col + (vein_col - col) * (0.6 * vein)[..., None]
    return linear_to_srgb8(col)


def checker_image(size=256, checks=2):
    """A checks x checks tile of light and dark grey squares (linear 0.8 / 0.1), tiled by st wrap 'repeat'."""
    i = (np.arange(size) * checks) // size
    board = (i[:, None] + i[None, :]) % 2
    col = np.where(board[..., None] == 0, 0.8, 0.1) * np.ones(3)
    return linear_to_srgb8(col)


# --- USD helpers -----------------------------------------------------------------------------------------------
def rounded_vec3f_array(points, decimals):
    return Vt.Vec3fArray.FromNumpy(np.round(np.asarray(points, np.float64), decimals).astype(np.float32))


def extent_of(points):
    p = np.asarray(points, np.float64)
    return Vt.Vec3fArray([Gf.Vec3f(*map(float, p.min(axis=0))), Gf.Vec3f(*map(float, p.max(axis=0)))])


def new_stage(path, default_prim, doc, animated=False):
    stage = Usd.Stage.CreateNew(str(path))
    layer = stage.GetRootLayer()
    layer.documentation = doc
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)            # centimetres
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    if animated:
        stage.SetStartTimeCode(1)
        stage.SetEndTimeCode(24)
        stage.SetTimeCodesPerSecond(24)
        stage.SetFramesPerSecond(24)
    root = UsdGeom.Xform.Define(stage, "/" + default_prim)
    stage.SetDefaultPrim(root.GetPrim())
    Usd.ModelAPI(root).SetKind(Kind.Tokens.assembly)
    UsdGeom.Scope.Define(stage, "/%s/Looks" % default_prim)
    UsdGeom.Scope.Define(stage, "/%s/Lights" % default_prim)
    return stage


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """Local-to-world matrix (USD row-vector convention) of a camera or light at `eye` whose -z looks at `target`."""
    eye, target, up = (np.asarray(a, np.float64) for a in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    true_up = np.cross(back, right)
    rows = [list(right) + [0.0], list(true_up) + [0.0], list(back) + [0.0], list(eye) + [1.0]]
    return Gf.Matrix4d(*[round(float(v), 9) for row in rows for v in row])


def add_camera(stage, path, eye, target, focal_length=100.0, aperture=24.0):
    """Perspective camera; focal length and (square) aperture in mm as UsdGeom.Camera defines them, clipping in cm."""
    cam = UsdGeom.Camera.Define(stage, path)
    cam.CreateProjectionAttr(UsdGeom.Tokens.perspective)
    cam.CreateFocalLengthAttr(focal_length)
    cam.CreateHorizontalApertureAttr(aperture)
    cam.CreateVerticalApertureAttr(aperture)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 10000.0))
    cam.AddTransformOp().Set(look_at(eye, target))
    return cam


def set_light_common(light, intensity, color, exposure=0.0):
    """UsdLux: emitted radiance = color * intensity * 2^exposure (inputs:normalize left false)."""
    light.CreateIntensityAttr(float(intensity))
    light.CreateColorAttr(Gf.Vec3f(*color))
    light.CreateExposureAttr(float(exposure))


def add_sphere_light(stage, path, position, radius, intensity, color=(1.0, 1.0, 1.0), exposure=0.0):
    light = UsdLux.SphereLight.Define(stage, path)
    light.CreateRadiusAttr(float(radius))
    set_light_common(light, intensity, color, exposure)
    light.AddTranslateOp().Set(Gf.Vec3d(*position))
    return light


def add_dome_light(stage, path, intensity, color):
    light = UsdLux.DomeLight.Define(stage, path)
    set_light_common(light, intensity, color)
    return light


def preview_material(stage, path, diffuse=(0.18, 0.18, 0.18), roughness=0.5, texture=None, wrap=("repeat", "repeat"),
                     opacity=None, ior=None):
    """Material with a UsdPreviewSurface; with `texture`, diffuseColor comes from a UsdUVTexture (sRGB) reading st
    through a UsdPrimvarReader_float2."""
    material = UsdShade.Material.Define(stage, path)
    surface = UsdShade.Shader.Define(stage, path + "/PreviewSurface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(float(roughness))
    if opacity is not None:
        surface.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(float(opacity))
    if ior is not None:
        surface.CreateInput("ior", Sdf.ValueTypeNames.Float).Set(float(ior))
    diffuse_in = surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f)
    if texture is None:
        diffuse_in.Set(Gf.Vec3f(*diffuse))
    else:
        reader = UsdShade.Shader.Define(stage, path + "/STReader")
        reader.CreateIdAttr("UsdPrimvarReader_float2")
        reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
        reader_out = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
        tex = UsdShade.Shader.Define(stage, path + "/DiffuseTexture")
        tex.CreateIdAttr("UsdUVTexture")
        tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(texture))
        tex.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
        tex.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set(wrap[0])
        tex.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set(wrap[1])
        tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader_out)
        diffuse_in.ConnectToSource(tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3))
    material.CreateSurfaceOutput().ConnectToSource(surface.CreateOutput("surface", Sdf.ValueTypeNames.Token))
    return material


def bind(prim, material):
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material)


def add_quad(stage, path, corners, material):
    """A single-quad polygonal Mesh (corners counter-clockwise seen from the lit side), e.g. a backdrop."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*c) for c in corners]))
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(extent_of(corners))
    bind(mesh.GetPrim(), material)
    return mesh


# --- The eye asset -----------------------------------------------------------------------------------------------
class EyeCage:
    """The fitted eyeball cage (eyeball-centred, mm) and its residuals against the analytic target."""

    def __init__(self):
        dirs, self.faces = cube_sphere(CAGE_DIVISIONS)
        fitted_mm = fit_cage(dirs, self.faces, eyeball_radius, FIT_ITERATIONS)
        # Residuals are measured on the points as written (cm, rounded, float32), not on the float64 fit.
        written_cm = np.round(fitted_mm * MM_TO_CM, POINT_DECIMALS).astype(np.float32)
        self.points_mm = written_cm.astype(np.float64) / MM_TO_CM
        limit = limit_samples(self.points_mm, self.faces, levels=2)
        self.apex_err, self.cornea_err, self.limbus_err, self.sclera_err = cornea_residuals(limit)

    def points_cm(self):
        return self.points_mm * MM_TO_CM          # rounds back to the written values


def model_transform():
    """Canonical frame (mm, apex at the origin) -> eyeball local space (cm, eyeball centre at the origin):
    p_local = 0.1 (p - (0, 0, EYEBALL_CENTER_Z)). USD matrices act on row vectors: scale, then translate."""
    m = Gf.Matrix4d(1.0)
    m.SetScale(Gf.Vec3d(MM_TO_CM))
    m.SetTranslateOnly(Gf.Vec3d(0, 0, round(-EYEBALL_CENTER_Z * MM_TO_CM, 9)))
    return m


def spherical_st(points_mm, faces):
    """Face-varying, indexed st: u = azimuth about the gaze (+x toward +y) / 2 pi, v = polar angle from the gaze / pi
    (v = 0 at the corneal apex, 1 at the back). Corners on the u seam take u + 1 where the face straddles it; the
    two pole vertices take their face's centroid azimuth. Returns (values (K, 2), indices (F*4,))."""
    d = points_mm / np.linalg.norm(points_mm, axis=1, keepdims=True)
    theta = np.arccos(np.clip(d[:, 2], -1, 1))
    az = np.mod(np.arctan2(d[:, 1], d[:, 0]) / (2 * math.pi), 1.0)
    corner_u = az[faces]
    corner_v = theta[faces] / math.pi
    centroid = points_mm[faces].mean(axis=1)
    face_az = np.mod(np.arctan2(centroid[:, 1], centroid[:, 0]) / (2 * math.pi), 1.0)
    pole = np.hypot(d[:, 0], d[:, 1])[faces] < 1e-9
    corner_u = np.where(pole, face_az[:, None], corner_u)
    seam = corner_u.max(axis=1) - corner_u.min(axis=1) > 0.5
    corner_u = np.where(seam[:, None] & (corner_u < 0.5), corner_u + 1.0, corner_u)
    st = np.round(np.stack([corner_u, corner_v], axis=2).reshape(-1, 2), 6)
    values, indices = np.unique(st, axis=0, return_inverse=True)
    return values, indices.reshape(-1)


def write_eye_asset(out, cage):
    path = out / "assets" / "eye.usda"
    doc = ("Procedural eye asset for eyeRender (generated by usd_samples/generate_samples.py; do not edit).\n"
           "Eyeball: Catmull-Clark cube-sphere cage, %d points, %d quads, centimetres, eyeball centre at the local\n"
           "origin, gaze +z. Its limit surface follows the analytic ellipsoid-cone cornea inside the %.3f mm outer\n"
           "limbus radius and a %.1f mm sclera sphere (centre %.4f mm behind the apex) beyond a %.1f mm blend.\n"
           "Cage pre-compensated for subdivision shrinkage (%d fixed-point iterations of the limit stencil).\n"
           "Limit-surface residuals (exact limit points at 2 refinement levels): apex %.1e mm, cornea max %.1e mm,\n"
           "limbus (r in [6.195, 6.445] mm) max %.1e mm, sclera max %.1e mm (radial).\n"
           "primvars:st: spherical about the gaze, u = azimuth / 2 pi, v = polar angle from the gaze / pi."
           % (len(cage.points_mm), len(cage.faces), LIMBUS_OUTER_RADIUS, SCLERA_RADIUS, -EYEBALL_CENTER_Z,
              BLEND_WIDTH, FIT_ITERATIONS, cage.apex_err, cage.cornea_err, cage.limbus_err, cage.sclera_err))
    stage = Usd.Stage.CreateNew(str(path))
    stage.GetRootLayer().documentation = doc
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    root = UsdGeom.Xform.Define(stage, "/Eye")
    stage.SetDefaultPrim(root.GetPrim())
    Usd.ModelAPI(root).SetKind(Kind.Tokens.component)

    looks = UsdGeom.Scope.Define(stage, "/Eye/Looks")
    sclera = preview_material(stage, str(looks.GetPath()) + "/ScleraMaterial", roughness=0.3,
                              texture="./sclera.png", wrap=("repeat", "clamp"), ior=CORNEA_IOR)

    mesh = UsdGeom.Mesh.Define(stage, "/Eye/Eyeball")
    points = rounded_vec3f_array(cage.points_cm(), POINT_DECIMALS)
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(cage.faces)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(cage.faces.reshape(-1).astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.catmullClark)
    mesh.CreateOrientationAttr(UsdGeom.Tokens.rightHanded)
    mesh.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(points))
    primvars = UsdGeom.PrimvarsAPI(mesh)
    rest = primvars.CreatePrimvar("rest", Sdf.ValueTypeNames.Point3fArray, UsdGeom.Tokens.vertex)
    rest.Set(points)
    st_values, st_indices = spherical_st(cage.points_mm, cage.faces)
    st = primvars.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying)
    st.Set(Vt.Vec2fArray.FromNumpy(st_values.astype(np.float32)))
    st.SetIndices(Vt.IntArray.FromNumpy(st_indices.astype(np.int32)))
    bind(mesh.GetPrim(), sclera)
    author_eye_api(mesh.GetPrim(), model_transform(), "./iris.png")
    stage.GetRootLayer().Save()
    return path


def author_eye_api(prim, model_xf, iris_texture):
    """Apply EyeAPI and author every eye:* attribute (schema defaults, written out so the sample documents them),
    with the schema's types, so the file does not depend on the plugin being loaded while generating."""
    prim.AddAppliedSchema("EyeAPI")
    T = Sdf.ValueTypeNames
    prim.CreateAttribute("eye:corneaModel", T.Token, variability=Sdf.VariabilityUniform).Set("ellipsoidCone")
    prim.CreateAttribute("eye:corneaIor", T.Float).Set(CORNEA_IOR)
    prim.CreateAttribute("eye:irisDepth", T.Float).Set(IRIS_DEPTH)
    prim.CreateAttribute("eye:limbusInnerRatio", T.Float).Set(0.772)
    prim.CreateAttribute("eye:limbusOuterRatio", T.Float).Set(0.855)
    prim.CreateAttribute("eye:pupilDiameter", T.Float).Set(PUPIL_DIAMETER)
    # White, so the texture shows as painted whether the renderer multiplies (schema) or replaces (delegate).
    prim.CreateAttribute("eye:irisColor", T.Color3f).Set(Gf.Vec3f(1, 1, 1))
    prim.CreateAttribute("eye:scleraColor", T.Color3f).Set(Gf.Vec3f(0.8, 0.78, 0.75))
    prim.CreateAttribute("eye:irisTexture", T.Asset).Set(Sdf.AssetPath(iris_texture))
    prim.CreateAttribute("eye:modelTransform", T.Matrix4d).Set(model_xf)
    prim.CreateAttribute("eye:limbalArc", T.Bool).Set(True)


def reference_eye(stage, path, instanceable=False):
    prim = stage.DefinePrim(path, "Xform")
    prim.GetReferences().AddReference("./assets/eye.usda")
    if instanceable:
        prim.SetInstanceable(True)
    return UsdGeom.Xform(prim)


def add_backdrop(stage, path, center, normal, half_size, shade=0.04):
    """A dark square quad facing `normal`."""
    c, n = np.asarray(center, float), np.asarray(normal, float)
    n /= np.linalg.norm(n)
    a = np.cross((0.0, 1.0, 0.0), n)
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    corners = [tuple(np.round(c + half_size * (sa * a + sb * b), 6)) for sa, sb in ((-1, -1), (1, -1), (1, 1),
                                                                                        (-1, 1))]
    material = preview_material(stage, "/World/Looks/Backdrop", diffuse=(shade, shade, shade), roughness=0.8)
    return add_quad(stage, path, corners, material)


# --- Stages ------------------------------------------------------------------------------------------------------
EYE_CENTER_TO_APEX_CM = -EYEBALL_CENTER_Z * MM_TO_CM     # ~1.30 cm


def write_closeup(out):
    """The default sample: one eye, 3/4 view, small key from the upper left so the iris caustic forms on the
    opposite (camera-side) half of the iris."""
    stage = new_stage(out / "closeup.usda", "World",
                      "Default sample: one eye filling the frame, 3/4 view, small sphere key from the side-top, dim "
                      "constant dome, dark backdrop. Centimetres, Y up. Render ~256x256, tens of spp.")
    reference_eye(stage, "/World/Eye")                             # eyeball centre at the origin, gaze +z
    yaw = math.radians(28)
    cam_pos = (12.0 * math.sin(yaw), 1.6, 12.0 * math.cos(yaw))   # the eyeball fills ~3/4 of the frame
    add_camera(stage, "/World/Camera", cam_pos, (0.15, 0.05, 0.45), focal_length=100.0)
    # Key: 15 cm away, upper left (opposite the camera side); radius 0.4 cm subtends ~3 deg: a small source, so a
    # sharp caustic. Radiance 225 * 2^2 = 900 -> irradiance ~2 at the eye.
    key_dir = np.array([-0.62, 0.55, 0.56])
    key_dir /= np.linalg.norm(key_dir)
    add_sphere_light(stage, "/World/Lights/Key", tuple(np.round(15.0 * key_dir, 6)), 0.4, 225.0, (1.0, 0.97, 0.92),
                     exposure=2.0)
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (0.75, 0.85, 1.0))
    add_backdrop(stage, "/World/Backdrop", tuple(-8.0 * np.array(cam_pos) / np.linalg.norm(cam_pos)),
                 cam_pos, 20.0)
    stage.GetRootLayer().Save()


def write_two_eyes(out):
    """Two instanced eyes in a rough head, converging on a point 40 cm in front, a little left and up."""
    stage = new_stage(out / "two_eyes.usda", "World",
                      "Two eyes (instanceable references to assets/eye.usda) in an ellipsoidal head (a scaled "
                      "UsdGeom.Sphere), both looking at /World/LookAt. Centimetres, Y up.")
    head = UsdGeom.Sphere.Define(stage, "/World/Head")
    head.CreateRadiusAttr(9.0)
    head.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(-9, -9, -9), Gf.Vec3f(9, 9, 9)]))
    head.AddScaleOp().Set(Gf.Vec3f(0.78, 1.15, 1.0))        # ~14 cm wide, ~21 cm tall, 18 cm deep
    skin = preview_material(stage, "/World/Looks/Skin", diffuse=(0.62, 0.40, 0.31), roughness=0.55)
    bind(head.GetPrim(), skin)

    target = np.array([-6.0, 4.0, 40.0])
    look = UsdGeom.Xform.Define(stage, "/World/LookAt")        # the common gaze target, as a locator
    look.AddTranslateOp().Set(Gf.Vec3d(*target))
    for name, x in (("EyeL", 3.15), ("EyeR", -3.15)):           # interpupillary distance 6.3 cm
        # Eyeball centre just under the head surface (z = 8.04 cm at x = +-3.15): the cornea and ~1 cm of sclera
        # show.
        centre = np.array([x, 0.0, 7.6])
        d = target - centre
        yaw = math.degrees(math.atan2(d[0], d[2]))
        pitch = -math.degrees(math.atan2(d[1], math.hypot(d[0], d[2])))
        eye = reference_eye(stage, "/World/" + name, instanceable=True)
        # Ops apply right to left: pitch about x, then yaw about y, then translate; gaze +z lands on the target.
        eye.AddTranslateOp().Set(Gf.Vec3d(*centre))
        eye.AddRotateYOp().Set(round(yaw, 6))
        eye.AddRotateXOp().Set(round(pitch, 6))
    add_camera(stage, "/World/Camera", (6.0, 3.0, 48.0), (0.0, 0.5, 7.0), focal_length=70.0)
    # Small key: radius 1 cm at ~62 cm subtends ~1.8 deg; radiance 3000 -> irradiance ~2.5.
    add_sphere_light(stage, "/World/Lights/Key", (25.0, 30.0, 45.0), 1.0, 3000.0, (1.0, 0.96, 0.9))
    add_dome_light(stage, "/World/Lights/Fill", 0.1, (0.8, 0.87, 1.0))
    # A dim rim from behind and above (a DistantLight emits along its local -z; angle = angular diameter, deg).
    rim = UsdLux.DistantLight.Define(stage, "/World/Lights/Rim")
    rim.CreateAngleAttr(1.0)
    set_light_common(rim, 0.6, (0.9, 0.95, 1.0))
    rim.CreateNormalizeAttr(True)  # intensity 0.6 is then the illuminance (lux) on a surface facing the rim
    rim.AddTransformOp().Set(look_at((-30.0, 40.0, -40.0), (0.0, 0.0, 0.0)))
    add_backdrop(stage, "/World/Backdrop", (0.0, 0.0, -30.0), (0.0, 0.0, 1.0), 60.0, shade=0.08)
    stage.GetRootLayer().Save()


def squash_stretch_scale(frame):
    """Gaze-axis scale at a frame in [1, 24]: 1 -> 1.5 -> 1/1.5 -> 1, a sine in log scale."""
    return math.exp(math.log(1.5) * math.sin(2 * math.pi * (frame - 1) / 23.0))


def write_squash_stretch(out, cage):
    stage = new_stage(out / "squash_stretch.usda", "World",
                      "One eye whose points are animated over frames 1-24: scale s along the gaze and 1/sqrt(s) "
                      "across it about the eyeball centre (volume preserving), s from 1 up to 1.5, down to 0.67 "
                      "and back. primvars:rest (from the asset) holds the undeformed points. Centimetres, Y up.",
                      animated=True)
    reference_eye(stage, "/World/Eye")
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Eye/Eyeball"))
    points_attr = mesh.GetPointsAttr()
    extent_attr = mesh.GetExtentAttr()
    rest = cage.points_cm()
    for frame in range(1, 25):
        s = squash_stretch_scale(frame)
        pts = rounded_vec3f_array(rest * np.array([1 / math.sqrt(s), 1 / math.sqrt(s), s]), ANIMATED_POINT_DECIMALS)
        points_attr.Set(pts, Usd.TimeCode(frame))
        extent_attr.Set(UsdGeom.Mesh.ComputeExtent(pts), Usd.TimeCode(frame))
    yaw = math.radians(60)
    add_camera(stage, "/World/Camera", (11.0 * math.sin(yaw), 1.5, 11.0 * math.cos(yaw)), (0.0, 0.0, 0.3),
               focal_length=100.0)
    add_upper_left_key_and_fill(stage)
    add_backdrop(stage, "/World/Backdrop", (0.0, 0.0, -10.0), (0.3, 0.0, 1.0), 25.0)
    stage.GetRootLayer().Save()


def add_upper_left_key_and_fill(stage):
    """A small warm sphere key 15 cm to the upper left (radius 0.4 cm, radiance 900) and a dim bluish dome."""
    key_dir = np.array([-0.62, 0.55, 0.56])
    key_dir /= np.linalg.norm(key_dir)
    add_sphere_light(stage, "/World/Lights/Key", tuple(np.round(15.0 * key_dir, 6)), 0.4, 900.0, (1.0, 0.97, 0.92))
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (0.75, 0.85, 1.0))


def write_side_lit(out):
    """Front view of the cornea with a key 75 deg off the gaze: the far limbus is shadowed; the light leaks there
    only through the sclera (the limbal arc)."""
    stage = new_stage(out / "side_lit.usda", "World",
                      "One eye seen head-on, lit by a small sphere light 75 degrees from the gaze (the mesh "
                      "counterpart of hdeye::sampleScenes::AddSideLitEye): the limbus away from the light is in the "
                      "cornea's shadow. Corneal apex at the origin. Centimetres, Y up.")
    eye = reference_eye(stage, "/World/Eye")
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, -round(EYE_CENTER_TO_APEX_CM, 9)))   # apex at the world origin
    # 7 cm away with a 100 mm lens: a 1.7 cm field, the whole limbus (1.29 cm) with a margin of sclera.
    add_camera(stage, "/World/Camera", (0.0, 0.0, 7.0), (0.0, 0.0, 0.0), focal_length=100.0)
    a = math.radians(75)
    # Radius 0.3 cm at 15 cm, radiance 1500: irradiance ~1.9 facing the light.
    add_sphere_light(stage, "/World/Lights/Key", (round(15.0 * math.sin(a), 6), 0.0, round(15.0 * math.cos(a), 6)),
                     0.3, 1500.0)
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (1.0, 1.0, 1.0))
    stage.GetRootLayer().Save()


def write_analytic_anterior(out):
    stage = new_stage(out / "analytic_anterior.usda", "World",
                      "The analytic anterior segment alone: an Xform with EyeAPI and no mesh (cornea, limbus, iris "
                      "from the model). eye:modelTransform scales mm to cm; the corneal apex is at the origin. "
                      "Centimetres, Y up.")
    eye = UsdGeom.Xform.Define(stage, "/World/Eye")
    m = Gf.Matrix4d(1.0)
    m.SetScale(Gf.Vec3d(MM_TO_CM))
    author_eye_api(eye.GetPrim(), m, "./assets/iris.png")
    add_camera(stage, "/World/Camera", (1.7, 1.1, 6.3), (0.0, 0.0, -0.25), focal_length=100.0)
    a = math.radians(45)
    add_sphere_light(stage, "/World/Lights/Key", (round(-15.0 * math.sin(a), 6), 3.0, round(15.0 * math.cos(a), 6)),
                     0.3, 300.0)
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (1.0, 1.0, 1.0))
    stage.GetRootLayer().Save()


def box_mesh(stage, path, lo, hi, st_per_cm):
    """Axis-aligned box with 24 unwelded points (flat faces even under smooth-normal shading), vertex st = the two
    in-face coordinates * st_per_cm."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    pts, st, counts, idx = [], [], [], []
    for axis in range(3):
        for sign in (-1, 1):
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            if sign < 0:
                u_axis, v_axis = v_axis, u_axis
            base = len(pts)
            for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = np.where(np.arange(3) == axis, hi if sign > 0 else lo, 0.0)
                p[u_axis] = (lo, hi)[du][u_axis]
                p[v_axis] = (lo, hi)[dv][v_axis]
                pts.append(Gf.Vec3f(*map(float, p)))
                st.append(Gf.Vec2f(float(p[u_axis] * st_per_cm), float(p[v_axis] * st_per_cm)))
            counts.append(4)
            idx.extend(range(base, base + 4))
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(Vt.Vec3fArray(pts))
    mesh.CreateFaceVertexCountsAttr(counts)
    mesh.CreateFaceVertexIndicesAttr(idx)
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, lo)), Gf.Vec3f(*map(float, hi))]))
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.vertex).Set(Vt.Vec2fArray(st))
    return mesh


def write_glass_sphere_table(out):
    stage = new_stage(out / "glass_sphere_table.usda", "World",
                      "No eyes: a glass ball (Catmull-Clark Mesh, UsdPreviewSurface opacity 0, ior 1.5, roughness 0) "
                      "on a checkered table top (box Mesh, UsdUVTexture), a RectLight overhead and a constant "
                      "DomeLight. Centimetres, Y up.")
    dirs, faces = cube_sphere(8)
    sphere_radius = 5.0                                        # cm
    cage = fit_cage(dirs, faces, lambda d: np.full(len(d), sphere_radius), FIT_ITERATIONS)
    cage = cage + np.array([0.0, sphere_radius, 0.0])          # resting on the table top (y = 0)
    ball = UsdGeom.Mesh.Define(stage, "/World/GlassBall")
    pts = rounded_vec3f_array(cage, POINT_DECIMALS)
    ball.CreatePointsAttr(pts)
    ball.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(faces)))
    ball.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(faces.reshape(-1).astype(np.int32)))
    ball.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.catmullClark)
    ball.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(pts))
    bind(ball.GetPrim(), preview_material(stage, "/World/Looks/Glass", diffuse=(1.0, 1.0, 1.0), roughness=0.0,
                                          opacity=0.0, ior=1.5))

    table = box_mesh(stage, "/World/Table", (-30.0, -4.0, -20.0), (30.0, 0.0, 20.0), st_per_cm=0.1)  # 10 cm tiles
    checker = preview_material(stage, "/World/Looks/Checker", roughness=0.6, texture="./assets/checker.png")
    bind(table.GetPrim(), checker)

    add_camera(stage, "/World/Camera", (0.0, 16.0, 42.0), (0.0, 4.0, 0.0), focal_length=50.0)
    rect = UsdLux.RectLight.Define(stage, "/World/Lights/Key")
    rect.CreateWidthAttr(20.0)
    rect.CreateHeightAttr(20.0)
    set_light_common(rect, 6.0, (1.0, 0.98, 0.95))
    # A RectLight emits along its local -z: aim it from above-left at the ball.
    rect.AddTransformOp().Set(look_at((-12.0, 35.0, 10.0), (0.0, 5.0, 0.0)))
    # A warm fill card low at the front right (a DiskLight emits along its local -z).
    disk = UsdLux.DiskLight.Define(stage, "/World/Lights/Fill")
    disk.CreateRadiusAttr(4.0)
    set_light_common(disk, 2.0, (1.0, 0.85, 0.7), exposure=-1.0)
    disk.AddTransformOp().Set(look_at((30.0, 8.0, 25.0), (0.0, 5.0, 0.0)))
    add_dome_light(stage, "/World/Lights/Sky", 0.3, (0.6, 0.7, 0.9))
    stage.GetRootLayer().Save()


def sphere_patch(stage, path, radius_cm, polar_deg, azimuth_deg, divisions, material):
    """An open polygonal patch of the sphere of radius_cm about the local origin (the eyeball centre, gaze +z):
    polar angle from the gaze in polar_deg, azimuth (from +x towards +y) in azimuth_deg, `divisions` = (polar,
    azimuth) quads; faces counter-clockwise seen from outside."""
    n_polar, n_az = divisions
    theta = np.radians(np.linspace(polar_deg[0], polar_deg[1], n_polar + 1))
    phi = np.radians(np.linspace(azimuth_deg[0], azimuth_deg[1], n_az + 1))
    t, p = np.meshgrid(theta, phi, indexing="ij")
    points = radius_cm * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    faces = [[i * (n_az + 1) + j, (i + 1) * (n_az + 1) + j, (i + 1) * (n_az + 1) + j + 1, i * (n_az + 1) + j + 1]
             for i in range(n_polar) for j in range(n_az)]
    return define_quad_mesh(stage, path, points, faces, UsdGeom.Tokens.none, material)


def define_quad_mesh(stage, path, points, faces, scheme, material):
    """A Mesh of quads at path: points (n, 3) rounded to POINT_DECIMALS, faces as vertex-index quadruples, the
    subdivision scheme token, its extent, bound to material."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    pts = rounded_vec3f_array(points, POINT_DECIMALS)
    mesh.CreatePointsAttr(pts)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(faces)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray([int(v) for f in faces for v in f]))
    mesh.CreateSubdivisionSchemeAttr(scheme)
    mesh.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(pts))
    bind(mesh.GetPrim(), material)
    return mesh


# The studio rig's extra meshes, mm from the eyeball centre (the sclera is a 12 mm sphere; the limbus is ~32.5
# degrees from the gaze seen from the centre).
CORNEA_SHELL_OFFSET_MM = 0.15
TEAR_LINE = {"radius_mm": 12.2, "polar_deg": (36.0, 41.0), "azimuth_deg": (200.0, 340.0), "opacity": 0.3}
OCCLUSION = {"radius_mm": 12.4, "polar_deg": (34.0, 65.0), "half_width_deg": 25.0, "opacity": 0.6}


def write_studio_eye_rig(out, cage):
    """An eye rig as studios build it, under a head Xform: the eyeball mesh (EyeAPI), a closed transparent cornea
    shell it targets with eye:corneaShell (not rendered: the analytic cornea replaces it), a wet tear-line strip
    along the lower lid margin and a dark, partly opaque occlusion shell over the two corners (both open meshes:
    thin walls that render as authored)."""
    stage = new_stage(out / "studio_eye_rig.usda", "World",
                      "A studio-style eye rig under /World/Head: Eye_L/Eyeball (the asset's eyeball, EyeAPI) with "
                      "eye:corneaShell targeting Eye_L/Cornea (a closed clear shell 0.15 mm outside the eyeball, "
                      "opacity 0, ior 1.376), Eye_L/TearLine (an open wet strip along the lower lid margin, opacity "
                      "0.3) and Eye_L/Occlusion (open dark patches over the eye corners, opacity 0.6, ior 1). "
                      "Centimetres, Y up.")
    head = UsdGeom.Xform.Define(stage, "/World/Head")
    head_at = Gf.Vec3d(0.0, 160.0, 0.0)
    head.AddTranslateOp().Set(head_at)
    eye_at = Gf.Vec3d(3.2, 4.0, 8.0)                               # the left eye in the head's frame
    eye = reference_eye(stage, "/World/Head/Eye_L")
    eye.AddTranslateOp().Set(eye_at)
    looks = "/World/Looks"

    shell = UsdGeom.Mesh.Define(stage, "/World/Head/Eye_L/Cornea")
    pts = rounded_vec3f_array(cage.points_cm() * (1 + CORNEA_SHELL_OFFSET_MM / SCLERA_RADIUS), POINT_DECIMALS)
    shell.CreatePointsAttr(pts)
    shell.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(cage.faces)))
    shell.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(cage.faces.reshape(-1).astype(np.int32)))
    shell.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.catmullClark)
    shell.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(pts))
    bind(shell.GetPrim(), preview_material(stage, looks + "/CorneaShell", diffuse=(1.0, 1.0, 1.0), roughness=0.0,
                                           opacity=0.0, ior=CORNEA_IOR))
    eyeball = stage.GetPrimAtPath("/World/Head/Eye_L/Eyeball")
    eyeball.CreateRelationship("eye:corneaShell", custom=False).SetTargets([shell.GetPath()])

    tear = preview_material(stage, looks + "/TearLine", diffuse=(0.85, 0.55, 0.5), roughness=0.1,
                            opacity=TEAR_LINE["opacity"], ior=1.33)
    sphere_patch(stage, "/World/Head/Eye_L/TearLine", TEAR_LINE["radius_mm"] * MM_TO_CM, TEAR_LINE["polar_deg"],
                 TEAR_LINE["azimuth_deg"], (2, 28), tear)
    occlusion = preview_material(stage, looks + "/Occlusion", diffuse=(0.0, 0.0, 0.0), roughness=1.0,
                                 opacity=OCCLUSION["opacity"], ior=1.0)
    occlusion_root = UsdGeom.Xform.Define(stage, "/World/Head/Eye_L/Occlusion")
    w = OCCLUSION["half_width_deg"]
    for name, centre in (("Outer", 0.0), ("Inner", 180.0)):
        sphere_patch(stage, str(occlusion_root.GetPath()) + "/" + name, OCCLUSION["radius_mm"] * MM_TO_CM,
                     OCCLUSION["polar_deg"], (centre - w, centre + w), (6, 8), occlusion)

    world_eye = head_at + eye_at
    add_camera(stage, "/World/Camera", tuple(world_eye + Gf.Vec3d(2.5, 1.0, 15.0)),
               tuple(world_eye + Gf.Vec3d(0.0, 0.0, 0.9)), focal_length=100.0)
    key_dir = np.array([-0.35, 0.45, 0.82])
    key_dir /= np.linalg.norm(key_dir)
    add_sphere_light(stage, "/World/Lights/Key", tuple(np.round(np.array(world_eye) + 15.0 * key_dir, 6)), 0.4,
                     900.0, (1.0, 0.97, 0.92))
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (0.75, 0.85, 1.0))
    add_backdrop(stage, "/World/Backdrop", tuple(world_eye + Gf.Vec3d(0.0, 0.0, -3.0)), (0.0, 0.0, 1.0), 15.0,
                 shade=0.25)
    stage.GetRootLayer().Save()


# --- Motion: a saccade and a blink under a film shutter ------------------------------------------------------------
# A 180-degree shutter at 24 frames per second: open a quarter frame before the frame, close a quarter after.
SHUTTER_FRAMES = (-0.25, 0.25)
# The saccade: the eye turns about its centre (yaw, degrees) from SACCADE_YAW[0] to [1] between these frames, i.e.
# 480 degrees per second (saccades reach 300-700), 10 degrees while frame 11's shutter is open.
SACCADE_FRAMES = (10.5, 11.5)
SACCADE_YAW = (-10.0, 10.0)
# The blink: lids on spheres about the eyeball centre clearing the corneal apex (13.03 mm), the lower one inside
# the upper so they overlap when shut; elevations (degrees above the gaze, seen from the centre) of the upper
# lid's margin at integer frames: open, closing over 3 frames (125 ms), shut for one, opening over 5.
LID_RADIUS_MM = 13.6
LOWER_LID_RADIUS_MM = 13.45
LID_AZIMUTH_DEG = (-75.0, 75.0)
UPPER_LID_TOP_DEG, LOWER_LID_BOTTOM_DEG, LOWER_LID_MARGIN_DEG = 80.0, -80.0, -17.0
UPPER_LID_OPEN_DEG, UPPER_LID_SHUT_DEG = 22.0, -20.0
BLINK_KEYS = ((9, 0.0), (12, 1.0), (13, 1.0), (18, 0.0))  # (frame, closure 0..1), smoothstep between keys


def set_shutter(camera):
    camera.CreateShutterOpenAttr(SHUTTER_FRAMES[0])
    camera.CreateShutterCloseAttr(SHUTTER_FRAMES[1])


def add_side_key(stage, degrees_from_gaze, distance=15.0, radius=0.3, intensity=1500.0):
    """A small sphere key in the horizontal plane, `degrees_from_gaze` to the eye's left (its caustic lands on the
    iris half away from it)."""
    a = math.radians(degrees_from_gaze)
    return add_sphere_light(stage, "/World/Lights/Key", (round(-distance * math.sin(a), 6), 1.0,
                                                         round(distance * math.cos(a), 6)), radius, intensity)


def write_saccade(out):
    stage = new_stage(out / "saccade.usda", "World",
                      "A saccade under a film shutter: the eye turns about its centre from -10 to +10 degrees of yaw "
                      "between frames 10.5 and 11.5 (480 degrees per second) and holds before and after; the camera "
                      "authors a 180-degree shutter (shutter:open -0.25, shutter:close 0.25 frames), so frame 11 "
                      "sweeps 10 degrees. A small key 70 degrees to the side casts the iris caustic. Centimetres, "
                      "Y up, 24 fps.", animated=True)
    eye = reference_eye(stage, "/World/Eye")                       # eyeball centre at the origin, gaze +z
    yaw = eye.AddRotateYOp()
    for frame, degrees in zip(SACCADE_FRAMES, SACCADE_YAW):
        yaw.Set(degrees, Usd.TimeCode(frame))
    cam_yaw = math.radians(12)
    camera = add_camera(stage, "/World/Camera", (round(11.0 * math.sin(cam_yaw), 6), 1.2,
                                                 round(11.0 * math.cos(cam_yaw), 6)), (0.0, 0.0, 0.6))
    set_shutter(camera)
    add_side_key(stage, 70.0)
    add_dome_light(stage, "/World/Lights/Fill", 0.05, (0.75, 0.85, 1.0))
    add_backdrop(stage, "/World/Backdrop", (0.0, 0.0, -8.0), (0.0, 0.0, 1.0), 20.0)
    stage.GetRootLayer().Save()


def blink_closure(frame):
    """How far the upper lid is down at `frame` (0 open, 1 shut): smoothstep between BLINK_KEYS."""
    for (f0, c0), (f1, c1) in zip(BLINK_KEYS, BLINK_KEYS[1:]):
        if f0 <= frame <= f1:
            return c0 + (c1 - c0) * smoothstep((frame - f0) / (f1 - f0))
    return BLINK_KEYS[0][1] if frame < BLINK_KEYS[0][0] else BLINK_KEYS[-1][1]


def lid_points(elevations_deg, divisions_az, radius_mm=LID_RADIUS_MM):
    """Points (cm, eyeball-centred, gaze +z) of a lid on the sphere of radius_mm: rows at `elevations_deg`
    (degrees above the gaze), divisions_az quads across LID_AZIMUTH_DEG."""
    el = np.radians(np.asarray(elevations_deg, np.float64))
    az = np.radians(np.linspace(*LID_AZIMUTH_DEG, divisions_az + 1))
    e, a = np.meshgrid(el, az, indexing="ij")
    r = radius_mm * MM_TO_CM
    return r * np.stack([np.cos(e) * np.sin(a), np.sin(e), np.cos(e) * np.cos(a)], axis=-1).reshape(-1, 3)


def lid_mesh(stage, path, points, rows, divisions_az, material, flip):
    """A lid Mesh: `rows` x divisions_az quads over `points`, facing outwards (away from the eyeball)."""
    n = divisions_az + 1
    faces = [[i * n + j, i * n + j + 1, (i + 1) * n + j + 1, (i + 1) * n + j] for i in range(rows) for j in
             range(divisions_az)]
    if flip:
        faces = [f[::-1] for f in faces]
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(faces)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray([int(v) for f in faces for v in f]))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    pts = rounded_vec3f_array(points, ANIMATED_POINT_DECIMALS)
    mesh.CreatePointsAttr(pts)
    mesh.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(pts))
    bind(mesh.GetPrim(), material)
    return mesh


def write_blink(out):
    stage = new_stage(out / "blink.usda", "World",
                      "A blink under a film shutter: point-animated upper and lower lids (sphere patches 13.6 mm "
                      "about the eyeball centre, the lower at 13.45 mm, clear of the cornea) in front of the eye; the "
                      "upper lid's margin comes down from 22 to -20 degrees above the gaze over frames 9-12 (125 "
                      "ms), stays shut to frame 13 and opens by frame 18. The camera authors a 180-degree shutter "
                      "(-0.25, 0.25 frames). Centimetres, Y up, 24 fps.", animated=True)
    reference_eye(stage, "/World/Eye")
    skin = preview_material(stage, "/World/Looks/Skin", diffuse=(0.62, 0.40, 0.31), roughness=0.55)
    rows, across = 10, 24
    upper_rows = lambda margin: np.linspace(margin, UPPER_LID_TOP_DEG, rows + 1)  # noqa: E731
    upper = lid_mesh(stage, "/World/Eye/UpperLid", lid_points(upper_rows(UPPER_LID_OPEN_DEG), across), rows, across,
                     skin, flip=False)
    for frame in range(1, 25):
        margin = UPPER_LID_OPEN_DEG + (UPPER_LID_SHUT_DEG - UPPER_LID_OPEN_DEG) * blink_closure(frame)
        pts = rounded_vec3f_array(lid_points(upper_rows(margin), across), ANIMATED_POINT_DECIMALS)
        upper.GetPointsAttr().Set(pts, Usd.TimeCode(frame))
        upper.GetExtentAttr().Set(UsdGeom.Mesh.ComputeExtent(pts), Usd.TimeCode(frame))
    lid_mesh(stage, "/World/Eye/LowerLid", lid_points(np.linspace(LOWER_LID_BOTTOM_DEG, LOWER_LID_MARGIN_DEG,
                                                                  rows + 1), across, LOWER_LID_RADIUS_MM), rows,
             across, skin, flip=False)
    camera = add_camera(stage, "/World/Camera", (1.5, 1.5, 11.0), (0.0, 0.0, 0.6))
    set_shutter(camera)
    add_upper_left_key_and_fill(stage)
    add_backdrop(stage, "/World/Backdrop", (0.0, 0.0, -8.0), (0.0, 0.0, 1.0), 20.0)
    stage.GetRootLayer().Save()


GENERATED_FILES = ["assets/eye.usda", "assets/iris.png", "assets/sclera.png", "assets/checker.png", "closeup.usda",
                   "two_eyes.usda", "squash_stretch.usda", "side_lit.usda", "analytic_anterior.usda",
                   "glass_sphere_table.usda", "studio_eye_rig.usda", "saccade.usda", "blink.usda",
                   "assets/studio_dome.hdr", "production_head.usda"]


def generate(out):
    out = pathlib.Path(out)
    (out / "assets").mkdir(parents=True, exist_ok=True)
    for name in GENERATED_FILES:                    # CreateNew refuses to overwrite an existing layer file
        target = out / name
        if target.suffix == ".usda" and target.exists():
            target.unlink()
    write_png(out / "assets" / "iris.png", iris_image())
    write_png(out / "assets" / "sclera.png", sclera_image())
    write_png(out / "assets" / "checker.png", checker_image())
    cage = EyeCage()
    write_eye_asset(out, cage)
    write_closeup(out)
    write_two_eyes(out)
    write_squash_stretch(out, cage)
    write_side_lit(out)
    write_analytic_anterior(out)
    write_glass_sphere_table(out)
    write_studio_eye_rig(out, cage)
    write_saccade(out)
    write_blink(out)
    # The production head lives in its own file beside this one and uses this module's helpers.
    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    from production_head import write_production_head
    write_production_head(out)
    return cage


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(HERE), help="output folder (default: usd_samples/)")
    args = parser.parse_args(argv)
    if SCHEMAS_DIR.is_dir():
        Plug.Registry().RegisterPlugins(str(SCHEMAS_DIR))   # not needed to write; lets USD check EyeAPI names
    cage = generate(args.out)
    print("eye cage: %d points, %d quads; eyeball centre %.4f mm behind the apex" % (
        len(cage.points_mm), len(cage.faces), -EYEBALL_CENTER_Z))
    print("limit-surface residual (mm): apex %.2e, cornea max %.2e, limbus max %.2e, sclera max %.2e" % (
        cage.apex_err, cage.cornea_err, cage.limbus_err, cage.sclera_err))
    for name in GENERATED_FILES:
        print("  %-28s %8d bytes" % (name, (pathlib.Path(args.out) / name).stat().st_size))
    return 0


if __name__ == "__main__":
    sys.exit(main())
