"""bench_skinning: the per-frame cost of a frame where only UsdSkel skinning changed, against a full sync.

Scene (authored in memory): a SkelRoot with a --grid x --grid quad sheet (polygons, no subdivision) skinned per
vertex to a chain of --joints joints (4 influences per point, linear blend), an eye mesh rigidly bound to the last
joint, and --static unskinned quad cards beside it; the chain bends over frames 1-10.

Measured (median of --repeats, seconds; each sync is `set_time` + the render index's sync, nothing rendered):
  first sync        RenderSession built at frame 1 (populate: UsdSkel cache, skinning, every prim added) + sync
  skinning frame    the same session moved to the next frame: only the skinned points and the rigid transform
  full sync         a new session built at that frame (what re-populating everything costs)
and, for the skinning frame, the re-synced prims by kind (the scene delegate's `last_update`) and what the sheet's
sync did (point uploads, topology builds).

Usage: python3 bench/bench_skinning.py [--grid 160] [--joints 8] [--static 50] [--repeats 9]
"""
import argparse
import math
import statistics
import time

from pxr import Gf, Usd, UsdGeom, UsdSkel

from eyerender import RenderSession


def build_stage(grid, joints, static):
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(10)
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 12))
    UsdSkel.Root.Define(stage, "/World/Rig")
    skel = UsdSkel.Skeleton.Define(stage, "/World/Rig/Skel")
    names = ["/".join(f"j{k}" for k in range(i + 1)) for i in range(joints)]
    step = 4.0 / joints
    skel.CreateJointsAttr(names)
    skel.CreateBindTransformsAttr([Gf.Matrix4d().SetTranslate(Gf.Vec3d(-2 + i * step, 0, 0)) for i in range(joints)])
    rest = [Gf.Matrix4d().SetTranslate(Gf.Vec3d(-2 if i == 0 else step, 0, 0)) for i in range(joints)]
    skel.CreateRestTransformsAttr(rest)
    anim = UsdSkel.Animation.Define(stage, "/World/Rig/Skel/Anim")
    anim.CreateJointsAttr(names)
    anim.CreateTranslationsAttr([Gf.Vec3f(r.ExtractTranslation()) for r in rest])
    anim.CreateScalesAttr([Gf.Vec3h(1, 1, 1)] * joints)
    rotations = anim.CreateRotationsAttr()
    for t in range(1, 11):
        angle = 40.0 * t / 10 / joints
        rotations.Set([Gf.Quatf(Gf.Rotation(Gf.Vec3d(0, 0, 1), angle).GetQuat())] * joints, t)
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])

    sheet = UsdGeom.Mesh.Define(stage, "/World/Rig/Sheet")
    n = grid
    points = [(-2 + 4.0 * i / n, -1 + 2.0 * j / n, 0.0) for j in range(n + 1) for i in range(n + 1)]
    sheet.CreatePointsAttr(points)
    sheet.CreateFaceVertexCountsAttr([4] * (n * n))
    sheet.CreateFaceVertexIndicesAttr([v for j in range(n) for i in range(n) for v in
                                       (j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                                        (j + 1) * (n + 1) + i)])
    sheet.CreateSubdivisionSchemeAttr("none")
    indices, weights = [], []
    for x, _, _ in points:
        u = min(joints - 1.0, max(0.0, (x + 2) / step))
        nearest = sorted(range(joints), key=lambda k: abs(k - u))[:4]
        w = [max(0.0, 1 - abs(k - u)) + 1e-3 for k in nearest]
        indices += nearest + [0] * (4 - len(nearest))
        weights += [v / sum(w) for v in w] + [0.0] * (4 - len(nearest))
    api = UsdSkel.BindingAPI.Apply(sheet.GetPrim())
    api.CreateSkeletonRel().SetTargets([skel.GetPath()])
    api.CreateJointIndicesPrimvar(False, 4).Set(indices)
    api.CreateJointWeightsPrimvar(False, 4).Set(weights)

    eye = UsdGeom.Mesh.Define(stage, "/World/Rig/Eye")
    eye.CreatePointsAttr([(-0.2, -0.2, 0.3), (0.2, -0.2, 0.3), (0.2, 0.2, 0.3), (-0.2, 0.2, 0.3)])
    eye.CreateFaceVertexCountsAttr([4])
    eye.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    eye.CreateSubdivisionSchemeAttr("none")
    eye.GetPrim().AddAppliedSchema("EyeAPI")
    eye_api = UsdSkel.BindingAPI.Apply(eye.GetPrim())
    eye_api.CreateSkeletonRel().SetTargets([skel.GetPath()])
    eye_api.CreateJointIndicesPrimvar(True, 1).Set([joints - 1])
    eye_api.CreateJointWeightsPrimvar(True, 1).Set([1.0])

    for k in range(static):
        card = UsdGeom.Mesh.Define(stage, f"/World/Static/card{k}")
        card.CreatePointsAttr([(0, 0, 0), (0.2, 0, 0), (0.2, 0.2, 0), (0, 0.2, 0)])
        card.CreateFaceVertexCountsAttr([4])
        card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
        card.CreateSubdivisionSchemeAttr("none")
        card.AddTranslateOp().Set(Gf.Vec3d(-3 + 0.25 * (k % 24), -3 + 0.25 * (k // 24), -1))
    return stage


def timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=160, help="sheet resolution in quads per side")
    parser.add_argument("--joints", type=int, default=8)
    parser.add_argument("--static", type=int, default=50, help="unskinned cards beside the rig")
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args()
    stage = build_stage(args.grid, args.joints, args.static)

    def first():
        session = RenderSession(stage, width=8, height=8, time=1)
        session.index.sync_all()
        return session

    firsts, frames, fulls = [], [], []
    for r in range(args.repeats):
        seconds, session = timed(first)
        firsts.append(seconds)
        before = session.index.mesh_stats("/World/Rig/Sheet")
        t = 2 + r % 8
        seconds, _ = timed(lambda s=session, t=t: (s.scene.set_time(t), s.index.sync_all()))
        frames.append(seconds)
        counts = dict(session.scene.last_update)
        after = session.index.mesh_stats("/World/Rig/Sheet")
        fulls.append(timed(lambda t=t: RenderSession(stage, width=8, height=8, time=t).index.sync_all())[0])
    sheet = {k: after[k] - before[k] for k in ("point_uploads", "topology_builds", "refinements", "transform_updates")}
    prims = len(session.index.rprim_ids())
    points = (args.grid + 1) ** 2
    print(f"bench_skinning: sheet {args.grid}x{args.grid} quads ({points} points, 4 influences), {args.joints} joints, "
          f"eye rigidly bound, {args.static} static cards: {prims} rprims; median of {args.repeats}")
    print("| sync | seconds (median) | vs full sync |")
    print("|---|---|---|")
    full = statistics.median(fulls)
    for name, values in (("first sync (populate + sync)", firsts), ("skinning-only frame", frames),
                         ("full sync of that frame (new session)", fulls)):
        m = statistics.median(values)
        print(f"| {name} | {m:.4f} | {m / full:.3f} |")
    print(f"skinning-only frame re-synced by kind: {counts}; the sheet's sync: {sheet}")
    if not math.isfinite(full):
        raise SystemExit("bench_skinning: non-finite timing")


if __name__ == "__main__":
    main()
