"""Small UsdSkel stages the skinning tests author with pxr: a two-joint strip, blend shapes, a head joint with an
eye bound to it, and their baked copies (UsdSkel.BakeSkinning) to compare against."""
import math

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdSkel

HEAD_EYE_OFFSET = Gf.Vec3d(0.3, 0.2, 0.4)  # the eye's bind position in the head joint's frame (scene units)


def translate(x, y=0.0, z=0.0):
    return Gf.Matrix4d().SetTranslate(Gf.Vec3d(x, y, z))


def base_stage(camera_z=6.0):
    """A y-up stage, frames 1-3, a camera on +z looking at the origin and a sphere light."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(3)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(1.0, 0.5, camera_z))
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateIntensityAttr(30.0)
    light.CreateRadiusAttr(0.5)
    light.AddTranslateOp().Set(Gf.Vec3d(2, 3, 4))
    return stage


def skeleton(stage, root_path, joints, binds, anim_rotations=None, anim_translations=None, blend_shapes=None):
    """A Skeleton under a SkelRoot at root_path (bind = rest), with a SkelAnimation when anim_* are given:
    anim_rotations {time: [Gf.Quatf per joint]}, anim_translations [Gf.Vec3f per joint] (constant),
    blend_shapes {"names": [...], "weights": {time: [...]}}."""
    UsdSkel.Root.Define(stage, root_path)
    skel = UsdSkel.Skeleton.Define(stage, f"{root_path}/Skel")
    skel.CreateJointsAttr(joints)
    skel.CreateBindTransformsAttr(binds)
    locals_ = UsdSkel.ComputeJointLocalTransforms(UsdSkel.Topology(joints), binds, Gf.Matrix4d(1)) \
        if hasattr(UsdSkel, "ComputeJointLocalTransforms") else binds
    skel.CreateRestTransformsAttr(locals_)
    if anim_rotations is None and blend_shapes is None:
        return skel
    anim = UsdSkel.Animation.Define(stage, f"{root_path}/Skel/Anim")
    anim.CreateJointsAttr(joints)
    rests = [Gf.Transform(m) for m in locals_]
    anim.CreateTranslationsAttr(anim_translations or [Gf.Vec3f(r.GetTranslation()) for r in rests])
    rotations = anim.CreateRotationsAttr()
    for t, quats in (anim_rotations or {Usd.TimeCode.Default(): [Gf.Quatf(1)] * len(joints)}).items():
        rotations.Set(quats, t)
    anim.CreateScalesAttr([Gf.Vec3h(1, 1, 1)] * len(joints))
    if blend_shapes:
        anim.CreateBlendShapesAttr(blend_shapes["names"])
        weights = anim.CreateBlendShapeWeightsAttr()
        for t, w in blend_shapes["weights"].items():
            weights.Set(w, t)
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    return skel


def z_rotation(degrees):
    return Gf.Quatf(Gf.Rotation(Gf.Vec3d(0, 0, 1), degrees).GetQuat())


def strip_mesh(stage, path, segments=8, length=2.0, height=0.4):
    """A quad strip along x from 0 to `length`, `height` tall, in the xy plane (polygons, no subdivision)."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    points = [(length * i / segments, y, 0.0) for i in range(segments + 1) for y in (0.0, height)]
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr([4] * segments)
    mesh.CreateFaceVertexIndicesAttr([v for i in range(segments) for v in (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1)])
    mesh.CreateSubdivisionSchemeAttr("none")
    mesh.CreateDisplayColorAttr([(0.7, 0.6, 0.5)])
    return mesh


def bind(prim, skel, indices, weights, element_size, constant=False, geom_bind=None):
    api = UsdSkel.BindingAPI.Apply(prim)
    api.CreateSkeletonRel().SetTargets([skel.GetPath()])
    api.CreateJointIndicesPrimvar(constant, element_size).Set(indices)
    api.CreateJointWeightsPrimvar(constant, element_size).Set(weights)
    if geom_bind is not None:
        api.CreateGeomBindTransformAttr(geom_bind)
    return api


def two_joint_strip(method="classicLinear", bend=60.0, segments=8):
    """A strip skinned to joints root (origin) and root/tip (x = 1): weights blend linearly from root to tip over
    x in [0.5, 1.5]; the tip joint turns about z by 0 / bend/2 / bend degrees at frames 1 / 2 / 3."""
    stage = base_stage()
    skel = skeleton(stage, "/World/Rig", ["root", "root/tip"], [Gf.Matrix4d(1), translate(1.0)],
                    anim_rotations={t: [Gf.Quatf(1), z_rotation(bend * (t - 1) / 2)] for t in (1, 2, 3)})
    mesh = strip_mesh(stage, "/World/Rig/Strip", segments)
    indices, weights = [], []
    for x, _, _ in mesh.GetPointsAttr().Get():
        tip = min(1.0, max(0.0, x - 0.5))
        indices += [0, 1]
        weights += [1.0 - tip, tip]
    api = bind(mesh.GetPrim(), skel, indices, weights, 2, geom_bind=Gf.Matrix4d(1))
    api.CreateSkinningMethodAttr(method)
    return stage


def blend_shape_strip(joints=True):
    """A strip with one blend shape ("lift": the last column up by 0.5 in z, an in-between at weight 0.5 lifting
    it 0.4) driven 0 / 0.5 / 1 at frames 1 / 2 / 3, and no joint motion; joints=False: a Skeleton of no joints
    and no bind pose, the mesh bound to it without joint influences (OpenUSD's blendshapes test stage)."""
    stage = base_stage()
    skel = skeleton(stage, "/World/Rig", ["root"] if joints else [], [Gf.Matrix4d(1)] if joints else [],
                    blend_shapes={"names": ["lift"], "weights": {1: [0.0], 2: [0.5], 3: [1.0]}})
    if not joints:
        for attr in (skel.GetBindTransformsAttr(), skel.GetRestTransformsAttr()):
            attr.Clear()
    mesh = strip_mesh(stage, "/World/Rig/Strip")
    count = len(mesh.GetPointsAttr().Get())
    shape = UsdSkel.BlendShape.Define(stage, "/World/Rig/Strip/lift")
    shape.CreatePointIndicesAttr([count - 2, count - 1])
    shape.CreateOffsetsAttr([(0, 0, 0.5), (0, 0, 0.5)])
    shape.CreateInbetween("half").SetOffsets([(0, 0.0, 0.4), (0, 0.0, 0.4)])
    shape.GetInbetween("half").SetWeight(0.5)
    if joints:
        api = bind(mesh.GetPrim(), skel, [0] * count, [1.0] * count, 1)
    else:
        api = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
        api.CreateSkeletonRel().SetTargets([skel.GetPath()])
    api.CreateBlendShapesAttr(["lift"])
    api.CreateBlendShapeTargetsRel().SetTargets([shape.GetPath()])
    return stage


def head_rig(turn=40.0):
    """A SkelRoot with joints root and root/head (head bound at (0, 1, 0)); the head turns about y by 0 / turn/2 /
    turn degrees at frames 1 / 2 / 3."""
    stage = base_stage()
    skel = skeleton(stage, "/World/Rig", ["root", "root/head"], [Gf.Matrix4d(1), translate(0, 1, 0)],
                    anim_rotations={t: [Gf.Quatf(1), Gf.Quatf(Gf.Rotation(Gf.Vec3d(0, 1, 0),
                                                                          turn * (t - 1) / 2).GetQuat())]
                                    for t in (1, 2, 3)})
    return stage, skel


def eye_sphere_mesh(stage, path, radius=0.25, rings=8, segments=12):
    """A small UV sphere mesh with the EyeAPI (gaze +z), centred at the prim's origin."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    points = [(0.0, 0.0, -radius)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            points.append((radius * math.sin(theta) * math.cos(phi), radius * math.sin(theta) * math.sin(phi),
                           -radius * math.cos(theta)))
    points.append((0.0, 0.0, radius))
    top = len(points) - 1

    def ring(r, s):
        return 1 + (r - 1) * segments + s % segments
    counts, indices = [], []
    for s in range(segments):
        counts.append(3)
        indices += [0, ring(1, s + 1), ring(1, s)]
    for r in range(1, rings - 1):
        for s in range(segments):
            counts.append(4)
            indices += [ring(r, s), ring(r, s + 1), ring(r + 1, s + 1), ring(r + 1, s)]
    for s in range(segments):
        counts.append(3)
        indices += [top, ring(rings - 1, s), ring(rings - 1, s + 1)]
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr(counts)
    mesh.CreateFaceVertexIndicesAttr(indices)
    mesh.CreateSubdivisionSchemeAttr("none")
    mesh.GetPrim().AddAppliedSchema("EyeAPI")
    # The canonical eye is in mm; this eye is 0.5 units across: the model scales 24 mm down to it.
    mesh.GetPrim().CreateAttribute("eye:modelTransform", Sdf.ValueTypeNames.Matrix4d).Set(
        Gf.Matrix4d().SetScale(0.5 / 24.0) * translate(0, 0, radius))
    return mesh


def eye_on_head(rigid=True):
    """head_rig with an eye mesh at HEAD_EYE_OFFSET from the head joint, bound to the head joint only: rigidly
    (constant jointIndices) or per vertex (weight 1 on the head); geomBindTransform = its bind placement."""
    stage, skel = head_rig()
    eye = eye_sphere_mesh(stage, "/World/Rig/Eye")
    geom_bind = translate(*(HEAD_EYE_OFFSET + Gf.Vec3d(0, 1, 0)))
    eye.AddTransformOp().Set(geom_bind)
    count = len(eye.GetPointsAttr().Get())
    if rigid:
        bind(eye.GetPrim(), skel, [1], [1.0], 1, constant=True, geom_bind=geom_bind)
    else:
        bind(eye.GetPrim(), skel, [1] * count, [1.0] * count, 1, geom_bind=geom_bind)
    return stage


def baked_copy(stage):
    """A copy of stage with its skinning baked into points and transforms by UsdSkel.BakeSkinning."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.TransferContent(stage.GetRootLayer())
    copy = Usd.Stage.Open(layer)
    if not UsdSkel.BakeSkinning(copy.Traverse()):
        raise RuntimeError("UsdSkel.BakeSkinning failed")
    return copy
