"""check_usd_assets: the scene delegate against usd-core's own answers on a directory of real USD assets.

For every stage file (.usd, .usda, .usdc, .usdz) found under the directories given:
- UsdSkel (stages with a SkelRoot): at several frames (each moved to the nearest time BakeSkinning wrote a sample
  at: baked points are linear between samples, where the delegate skins the interpolated joints), with
  `--complexity low` and `high` (refinement levels 0 and 2), the points and transforms the scene delegate hands to
  the renderer, in world space, against the same stage baked by UsdSkel.BakeSkinning (its bakes in a session layer
  over the asset, so a .usdz's relative paths resolve as they do in the asset) read by the same delegate: the
  largest point deviation in the asset's units (points of meshes, the origin and unit axes of transforms of prims
  without points), and the largest skinned-normal angle where BakeSkinning baked the normals attribute (it leaves
  primvars:normals in the bind pose, so those have no reference here: "-").
- GeomSubsets (meshes with materialBind subsets): the material each face renders with (the mesh's, or its first
  subset's) against UsdShade.MaterialBindingAPI.ComputeBoundMaterial of that subset (the mesh's for faces in none),
  on every instance proxy of an instanced mesh too: the faces whose material differs.
- --render: also renders each skinned stage and its baked copy with eyerecord (same frame, seed, width, samples
  and camera: the asset's, else one framing the baked stage) and prints the largest and mean colour difference.
  They differ where the asset has primvars:normals, which BakeSkinning leaves in the bind pose (the bake's shading
  is then wrong, not the render's).

Usage: python3 bench/check_usd_assets.py DIR_OR_FILE... [--frames 5] [--render] [--width 256] [--spp 16]
Rows print as they are measured; the exit status is 1 when any row differs by more than --tolerance (points) or
has a face whose material differs, else 0.
"""
import argparse
import glob
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdShade, UsdSkel

import eyerender
from eyerender import cameras
from eyerender.usd_scene_delegate import UsdSceneDelegate

COMPLEXITIES = {"low": 0, "high": 2}
EXTENSIONS = (".usd", ".usda", ".usdc", ".usdz")
AXES = np.array([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]], dtype=np.float64)


class RecordingStore:
    """A SceneStore keeping the last points, transform, material, subsets and normals sent per prim."""

    def __init__(self):
        self.store = eyerender.SceneStore(eyerender.RenderIndex(eyerender.RenderDelegate()))
        self.points, self.transforms, self.materials, self.subsets, self.normals = {}, {}, {}, {}, {}

    def __getattr__(self, name):
        return getattr(self.store, name)

    def add_mesh(self, prim_id, counts, indices, points, transform, material_id, *args, **kwargs):
        self.points[prim_id], self.transforms[prim_id] = np.array(points), np.array(transform)
        self.materials[prim_id] = (material_id, len(counts))
        return self.store.add_mesh(prim_id, counts, indices, points, transform, material_id, *args, **kwargs)

    def add_eye_mesh(self, prim_id, counts, indices, points, eye, transform, material_id, *args):
        self.points[prim_id], self.transforms[prim_id] = np.array(points), np.array(transform)
        self.materials[prim_id] = (material_id, len(counts))
        return self.store.add_eye_mesh(prim_id, counts, indices, points, eye, transform, material_id, *args)

    def add_analytic_eye(self, prim_id, eye, transform):
        self.transforms[prim_id] = np.array(transform)
        return self.store.add_analytic_eye(prim_id, eye, transform)

    def set_points(self, prim_id, points):
        self.points[prim_id] = np.array(points)
        return self.store.set_points(prim_id, points)

    def set_transform(self, prim_id, transform):
        self.transforms[prim_id] = np.array(transform)
        return self.store.set_transform(prim_id, transform)

    def set_geom_subsets(self, prim_id, subsets):
        self.subsets[prim_id] = subsets
        return self.store.set_geom_subsets(prim_id, subsets)

    def set_primvar(self, prim_id, name, interpolation, values):
        if name == "normals":
            self.normals[prim_id] = np.array(values)
        return self.store.set_primvar(prim_id, name, interpolation, values)


def stage_files(roots):
    for root in roots:
        if os.path.isfile(root):
            yield root
            continue
        for folder, _, names in sorted(os.walk(root)):
            for name in sorted(names):
                if name.endswith(EXTENSIONS):
                    yield os.path.join(folder, name)


def read_delegate(stage, time, refine_level):
    store = RecordingStore()
    scene = UsdSceneDelegate(stage, store, time=time, refine_level=refine_level)
    scene.populate()
    return scene, store


def world_points(store, prim_id):
    if prim_id in store.points and len(store.points[prim_id]):
        points = np.c_[store.points[prim_id].astype(np.float64), np.ones(len(store.points[prim_id]))]
    else:
        points = AXES
    return (points @ store.transforms[prim_id])[:, :3]


def world_normals(store, prim_id):
    normals = store.normals.get(prim_id)
    if normals is None:
        return None
    m = np.linalg.inv(store.transforms[prim_id][:3, :3]).T
    n = normals.astype(np.float64) @ m
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)


# -- UsdSkel ---------------------------------------------------------------------------------------------------------

def has_skel(stage):
    return any(p.IsA(UsdSkel.Root) for p in stage.Traverse(Usd.TraverseInstanceProxies()))


def baked_stage(path, frames):
    """The asset with BakeSkinning's output (over the frames' interval) in its session layer, which takes the root
    layer's timeCodesPerSecond (else its samples are scaled in time against the asset's: BrainStem's 37)."""
    stage = Usd.Stage.Open(path)
    session, root = stage.GetSessionLayer(), stage.GetRootLayer()
    session.timeCodesPerSecond, session.framesPerSecond = root.timeCodesPerSecond, root.framesPerSecond
    stage.SetEditTarget(session)
    # One frame (no authored time range): a frame either side, so the bake has samples around it to snap to.
    interval = Gf.Interval(min(frames) - (len(frames) == 1), max(frames) + (len(frames) == 1))
    if not UsdSkel.BakeSkinning(stage.Traverse(), interval):
        raise RuntimeError(f"{path}: UsdSkel.BakeSkinning failed")
    return stage


def baked_file(path, stage, folder):
    """The baked session layer as a file over the asset (for eyerecord)."""
    layer = Sdf.Layer.CreateNew(os.path.join(folder, "baked.usda"))
    layer.TransferContent(stage.GetSessionLayer())  # its timeCodesPerSecond too
    root = stage.GetRootLayer()
    for key in ("upAxis", "metersPerUnit", "defaultPrim", "startTimeCode", "endTimeCode", "renderSettingsPrimPath"):
        if root.pseudoRoot.HasInfo(key):  # what eyerecord reads from the root layer: its camera and frame range
            layer.pseudoRoot.SetInfo(key, root.pseudoRoot.GetInfo(key))
    layer.subLayerPaths.append(os.path.abspath(path))
    layer.Save()
    return layer.identifier


def skel_frames(stage, count):
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    if not stage.HasAuthoredTimeCodeRange() or end <= start:
        return [start]
    return sorted({round(start + (end - start) * k / max(count - 1, 1)) for k in range(count)})


def baked_times(baked):
    """The times BakeSkinning wrote samples at (its points and transforms are exact there, linear between)."""
    layer = baked.GetSessionLayer()
    times = set()
    layer.Traverse(Sdf.Path.absoluteRootPath, lambda path: times.update(
        layer.ListTimeSamplesForPath(path) if path.IsPropertyPath() else ()))
    return sorted(times)


def snapped(frames, times):
    """Each frame moved to the nearest baked sample time (none baked: the frames)."""
    return sorted({min(times, key=lambda t: abs(t - f)) for f in frames}) if times else frames


def compare_skel(stage, baked, frame, refine_level):
    """(max point deviation, max normal angle in degrees, prims compared, the worst prim)."""
    _, got = read_delegate(stage, frame, refine_level)
    _, want = read_delegate(baked, frame, refine_level)
    worst, angle, prim = 0.0, None, ""
    shared = sorted(set(got.transforms) & set(want.transforms))
    for prim_id in shared:
        a, b = world_points(got, prim_id), world_points(want, prim_id)
        deviation = float(np.abs(a - b).max()) if a.shape == b.shape else math.inf
        if deviation > worst:
            worst, prim = deviation, prim_id
        na, nb = world_normals(got, prim_id), world_normals(want, prim_id)
        baked_normals = UsdGeom.Mesh(baked.GetPrimAtPath(prim_id)).GetNormalsAttr() if \
            Sdf.Path.IsValidPathString(prim_id) and baked.GetPrimAtPath(prim_id) else None
        if not (baked_normals and baked_normals.GetNumTimeSamples()):
            continue  # BakeSkinning bakes the normals attribute only, not primvars:normals: no reference
        if na is not None and nb is not None and na.shape == nb.shape:
            cos = np.clip((na * nb).sum(axis=1), -1, 1)
            angle = max(angle or 0.0, float(np.degrees(np.arccos(cos)).max()))
    return worst, angle, len(shared), prim


def camera_layer(stage, baked, frame, folder):
    """A session layer holding /CheckCamera: the asset's camera if it has one, else eyerecord's framing of the baked
    stage's bounds (a SkelRoot's authored extent, which frames the unbaked stage, may hold only its joints)."""
    layer = Sdf.Layer.CreateNew(os.path.join(folder, "camera.usda"))
    camera_stage = Usd.Stage.Open(layer)
    camera = UsdGeom.Camera.Define(camera_stage, "/CheckCamera")
    found = [p for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]
    time = Usd.TimeCode(frame)
    if found:
        source = UsdGeom.Camera(found[0])
        world = UsdGeom.XformCache(time).GetLocalToWorldTransform(found[0])
        for name in ("focalLength", "horizontalAperture", "verticalAperture", "clippingRange", "projection"):
            value = source.GetPrim().GetAttribute(name).Get(time)
            if value is not None:
                camera.GetPrim().GetAttribute(name).Set(value)
    else:
        params, world = cameras.default_camera(baked, time, ("default", "proxy"), 1.0)
        camera.CreateFocalLengthAttr(params.focal_length)
        camera.CreateHorizontalApertureAttr(params.horizontal_aperture)
        camera.CreateVerticalApertureAttr(params.vertical_aperture)
        camera.CreateClippingRangeAttr(Gf.Vec2f(params.near_clip, params.far_clip))
    camera.AddTransformOp().Set(world)
    layer.Save()
    return layer.identifier


def render_difference(path, baked_path, frame, complexity, args, folder, camera):
    """eyerecord renders of the asset and of its bake through one camera (camera_layer), same seed."""
    images = []
    for name, source in (("asset", path), ("baked", baked_path)):
        for old in glob.glob(os.path.join(folder, f"{name}.*.exr")):
            os.remove(old)
        cmd = [sys.executable, "-m", "eyerender.cli.eyerecord", source, os.path.join(folder, f"{name}.####.##.exr"),
               "--frames", f"{frame:g}", "-w", str(args.width), "--spp", str(args.spp), "--seed", "1",
               "--complexity", complexity, "--quiet", "--overwrite", "--sessionLayer", camera,
               "--camera", "/CheckCamera"]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            return f"eyerecord failed: {(run.stderr.strip().splitlines() or ['?'])[-1][:80]}"
        channels = eyerender.read_exr(glob.glob(os.path.join(folder, f"{name}.*.exr"))[0])
        images.append(np.stack([channels[c] for c in "RGB"], axis=-1))
    difference = np.abs(images[0] - images[1])
    return f"{difference.max():.4f} max, {difference.mean():.5f} mean"


def check_skel(path, args, rows):
    stage = Usd.Stage.Open(path)
    frames = skel_frames(stage, args.frames)
    baked = baked_stage(path, frames)
    frames = snapped(frames, baked_times(baked))
    with tempfile.TemporaryDirectory() as folder:
        baked_path = baked_file(path, baked, folder) if args.render else None
        camera = None
        for frame in frames:
            for complexity, level in COMPLEXITIES.items():
                worst, angle, count, prim = compare_skel(stage, baked, frame, level)
                image = ""
                if args.render:
                    camera = camera_layer(stage, baked, frame, folder) if complexity == "low" else camera
                    image = render_difference(path, baked_path, frame, complexity, args, folder, camera)
                shown = "-" if angle is None else f"{angle:.3g}"
                rows.append((path, f"{frame:.6g}", complexity, f"{worst:.3g}", shown, count, prim, image))
                print_row(rows[-1], args)
                sys.stdout.flush()


# -- GeomSubsets ---------------------------------------------------------------------------------------------------

def expected_face_materials(mesh_prim, face_count):
    """Per face: the material path UsdShade binds (preview purpose, which falls back to all-purpose bindings)."""
    def bound(prim):
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(UsdShade.Tokens.preview)
        return material.GetPath().pathString if material else ""
    faces = [None] * face_count
    for subset in UsdShade.MaterialBindingAPI(mesh_prim).GetMaterialBindSubsets():
        if subset.GetElementTypeAttr().Get() != UsdGeom.Tokens.face:
            continue
        material = bound(subset.GetPrim())
        for face in subset.GetIndicesAttr().Get() or []:
            if 0 <= face < face_count and faces[face] is None:
                faces[face] = material
    mesh_material = bound(mesh_prim)
    return [mesh_material if m is None else m for m in faces]


def delegate_face_materials(store, prim_id):
    material, face_count = store.materials[prim_id]
    faces = [None] * face_count
    for subset_material, indices in store.subsets.get(prim_id, []):
        for face in indices:
            if faces[face] is None and subset_material:
                faces[face] = subset_material
    return [material if m is None else m for m in faces]


def mesh_prims_of(scene, prim_id):
    """The stage prims (instance proxies for native instances) an rprim draws."""
    stage = scene.stage
    if prim_id not in scene.instanced_prims:
        return [stage.GetPrimAtPath(prim_id)]
    prim, binding = scene.instanced_prims[prim_id]
    proxies = [stage.GetPrimAtPath(n) for n in scene.instance_names.get(prim_id, []) if Sdf.Path.IsValidPathString(n)]
    return [p for p in proxies if p] or [binding]


def check_subsets(path, args, rows):
    stage = Usd.Stage.Open(path)
    meshes = [p for p in stage.Traverse(Usd.TraverseInstanceProxies()) if p.IsA(UsdGeom.Mesh) and
              UsdShade.MaterialBindingAPI(p).GetMaterialBindSubsets()]
    if not meshes:
        return
    scene, store = read_delegate(stage, stage.GetStartTimeCode(), 0)
    checked, faces, wrong, worst = set(), 0, 0, ""
    for prim_id in store.materials:
        for prim in mesh_prims_of(scene, prim_id):
            if not UsdShade.MaterialBindingAPI(prim).GetMaterialBindSubsets():
                continue
            got = delegate_face_materials(store, prim_id)
            want = expected_face_materials(prim, len(got))
            bad = sum(a != b for a, b in zip(got, want))
            checked.add(prim.GetPath())
            faces += len(got)
            if bad:
                wrong += bad
                first = next(k for k, (a, b) in enumerate(zip(got, want)) if a != b)
                worst = worst or f"{prim.GetPath()} face {first}: {got[first] or '-'} for {want[first] or '-'}"
    missing = [p.GetPath() for p in meshes if p.GetPath() not in checked]
    rows.append((path, f"{stage.GetStartTimeCode():g}", "low", f"{len(checked)}/{len(meshes)} meshes", faces, wrong,
                 worst or (f"not drawn: {missing[0]}" if missing else "")))
    print_row(rows[-1], args)


def print_row(row, args):
    shown = [os.path.relpath(row[0], args.relative_to) if args.relative_to else row[0], *row[1:]]
    print(" | ".join(str(c) for c in shown))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("paths", nargs="+", help="directories (searched recursively) or stage files")
    p.add_argument("--frames", type=int, default=5, help="frames per skinned stage, spread over its time range")
    p.add_argument("--render", action="store_true", help="also compare eyerecord renders of asset and bake")
    p.add_argument("--width", type=int, default=256, help="render width in pixels (--render)")
    p.add_argument("--spp", type=int, default=16, help="samples per pixel (--render)")
    p.add_argument("--tolerance", type=float, default=1e-4, help="point deviation counted as a difference, in the "
                   "asset's units (default 1e-4)")
    p.add_argument("--relative-to", help="print asset paths relative to this directory")
    args = p.parse_args(argv)
    Tf.Debug.SetDebugSymbolsByName("", False)
    skel_rows, subset_rows = [], []
    print("UsdSkel: asset | frame | complexity | max point deviation (asset units) | max normal angle (deg) | prims |"
          " worst prim | render difference")
    for path in stage_files(args.paths):
        try:
            stage = Usd.Stage.Open(path)
        except Tf.ErrorException as e:
            print(f"{path}: cannot open ({str(e).strip().splitlines()[-1][:80]})")
            continue
        if has_skel(stage):
            check_skel(path, args, skel_rows)
    print("GeomSubsets: asset | frame | complexity | meshes checked | faces | faces with another material | first")
    for path in stage_files(args.paths):
        try:
            check_subsets(path, args, subset_rows)
        except Tf.ErrorException as e:
            print(f"{path}: cannot open ({str(e).strip().splitlines()[-1][:80]})")
    failed = any(float(r[3]) > args.tolerance for r in skel_rows) or any(r[5] for r in subset_rows)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
