"""bench_motion_bias: is a motion-blurred render the average of sharp renders over its shutter?

For each stage (authored here, frames 1-3, rendered at frame 2 under the shutter (-0.5, 0.5)): the blurred render
(every camera path at its own time in the shutter, seeds 1 and 2) against the mean of N sharp renders at the
centres of N equal strata of the same interval (each with its own seed; two such means, seeds 1 and 2). Printed per
stage: RMS over the image (RGB) of (blurred - mean of sharp), both averaged over their two seeds; the noise that
difference has when the two agree (from the seed-to-seed differences); their ratio (about 1 when unbiased; the
stratified mean's own discretisation is far below the noise here); and RMS(blurred - sharp at the frame), how far
the blur is from doing nothing.

Stages: a ball moving straight (transform, keys at frames 1 and 3), a ball on an arm turning 60 degrees over the
shutter about the origin (transform on an arc), a straight camera move, a camera on a rig turning 40 degrees
around a still ball (camera on an arc), and a strip skinned to a joint turning 60 degrees over the shutter
(UsdSkel deformation).

Usage: python3 bench/bench_motion_bias.py [--width 40] [--spp 64] [--sharp 16] [--stages orbit,camera_orbit]
"""
import argparse

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdLux, UsdSkel

from eyerender import RenderSession

FRAME, SHUTTER = 2.0, (-0.5, 0.5)
STAGES = ("straight", "orbit", "camera", "camera_orbit", "skinned")


def _lit_stage():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(3)
    key = UsdLux.DistantLight.Define(stage, "/World/key")
    key.CreateIntensityAttr(2.0)
    key.AddRotateXYZOp().Set(Gf.Vec3f(-30, -40, 0))
    UsdLux.DomeLight.Define(stage, "/World/dome").CreateIntensityAttr(0.5)
    return stage


def _camera(stage, path, x_keys=None):
    cam = UsdGeom.Camera.Define(stage, path)
    op = cam.AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 10))
    for t, x in (x_keys or {}).items():
        op.Set(Gf.Vec3d(x, 0, 10), t)
    cam.CreateFocalLengthAttr(35.0)
    return cam


def _skinned_strip(stage):
    """A 1 x 0.4 strip 0.8 units out from a joint at the origin that turns about z by 0 / 120 degrees at frames
    1 / 3, every point bound rigidly to it."""
    UsdSkel.Root.Define(stage, "/World/Rig")
    skel = UsdSkel.Skeleton.Define(stage, "/World/Rig/Skel")
    skel.CreateJointsAttr(["root"])
    skel.CreateBindTransformsAttr([Gf.Matrix4d(1)])
    skel.CreateRestTransformsAttr([Gf.Matrix4d(1)])
    anim = UsdSkel.Animation.Define(stage, "/World/Rig/Skel/Anim")
    anim.CreateJointsAttr(["root"])
    anim.CreateTranslationsAttr([Gf.Vec3f(0)])
    anim.CreateScalesAttr([Gf.Vec3h(1, 1, 1)])
    rotations = anim.CreateRotationsAttr()
    for t, degrees in ((1, 0.0), (3, 120.0)):
        rotations.Set([Gf.Quatf(Gf.Rotation(Gf.Vec3d(0, 0, 1), degrees).GetQuat())], t)
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    mesh = UsdGeom.Mesh.Define(stage, "/World/Rig/Strip")
    mesh.CreatePointsAttr([(0.8 + 0.25 * i, y, 0) for i in range(5) for y in (0.0, 0.4)])
    mesh.CreateFaceVertexCountsAttr([4] * 4)
    mesh.CreateFaceVertexIndicesAttr([v for i in range(4) for v in (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1)])
    mesh.CreateSubdivisionSchemeAttr("none")
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 1).Set([0] * 10)
    binding.CreateJointWeightsPrimvar(False, 1).Set([1.0] * 10)
    binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1))


def stage_for(name):
    """The stage of one row (see the module doc)."""
    stage = _lit_stage()
    if name == "skinned":
        _camera(stage, "/World/main_cam").GetPrim().GetAttribute("xformOp:translate").Set(Gf.Vec3d(0.5, 0.5, 6))
        _skinned_strip(stage)
        return stage
    rig = UsdGeom.Xform.Define(stage, "/World/Rig")
    if name in ("orbit", "camera_orbit"):
        turn = rig.AddRotateZOp() if name == "orbit" else rig.AddRotateYOp()
        turn.Set(-60.0 if name == "orbit" else -40.0, 1)
        turn.Set(60.0 if name == "orbit" else 40.0, 3)
    _camera(stage, "/World/Rig/main_cam" if name == "camera_orbit" else "/World/main_cam",
            {1: -1.5, 3: 1.5} if name == "camera" else None)
    ball = UsdGeom.Sphere.Define(stage, "/World/Rig/Ball" if name == "orbit" else "/World/Ball")
    op = ball.AddTranslateOp()
    op.Set(Gf.Vec3d(2.5 if name == "orbit" else 0.0, 0, 0))
    if name == "straight":
        op.Set(Gf.Vec3d(-2, 0, 0), 1)
        op.Set(Gf.Vec3d(2, 0, 0), 3)
    return stage


def rgb(stage, width, spp, seed, shutter, times):
    """The mean over `times` (time codes) of renders of `spp` samples (seed * 1000 + i for the i-th time)."""
    session = RenderSession(stage, width=width, height=width, shutter=shutter, settings={"seed": seed},
                            time=Usd.TimeCode(FRAME))
    total = 0.0
    for i, t in enumerate(times):
        session.delegate.settings.seed = seed * 1000 + i
        session.render(time=t, spp=spp)
        total = total + session.image("color")[..., :3].astype(np.float64)
    return total / len(times)


def measure(name, width, spp, sharp):
    """(RMS of blurred - mean of sharp, its noise, RMS of blurred - the frame's sharp render)."""
    stage = stage_for(name)
    span = SHUTTER[1] - SHUTTER[0]
    times = [FRAME + SHUTTER[0] + span * (i + 0.5) / sharp for i in range(sharp)]
    blurred = [rgb(stage, width, spp, seed, SHUTTER, [FRAME]) for seed in (1, 2)]
    averaged = [rgb(stage, width, spp, seed, (0.0, 0.0), times) for seed in (1, 2)]
    frame = rgb(stage, width, spp, 1, (0.0, 0.0), [FRAME])

    def rms(a):
        return float(np.sqrt(np.mean(a ** 2)))
    # Each mean of two seeds has half the variance of one; so has the seed-to-seed difference over 2.
    noise = np.hypot(rms(blurred[0] - blurred[1]), rms(averaged[0] - averaged[1])) / 2
    difference = rms(0.5 * (blurred[0] + blurred[1] - averaged[0] - averaged[1]))
    return difference, noise, rms(0.5 * (blurred[0] + blurred[1]) - frame)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=40)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--sharp", type=int, default=16, help="sharp renders averaged over the shutter")
    parser.add_argument("--stages", default=",".join(STAGES))
    args = parser.parse_args()
    print(f"{args.width}x{args.width}, {args.spp} spp per render, {args.sharp} sharp renders, shutter {SHUTTER} "
          f"at frame {FRAME:g}")
    print("| stage | RMS(blurred - mean of sharp) | its noise | ratio | RMS(blurred - sharp at the frame) |")
    print("|---|---|---|---|---|")
    for name in args.stages.split(","):
        difference, noise, frame = measure(name, args.width, args.spp, args.sharp)
        print(f"| {name} | {difference:.5f} | {noise:.5f} | {difference / noise:.2f} | {frame:.5f} |")


if __name__ == "__main__":
    main()
