"""UsdSkel for the scene delegate: which prims a skeleton deforms, and their points or transform at a time code,
computed by usd-core's own UsdSkel (UsdSkel.Cache, SkeletonQuery, SkinningQuery, BlendShapeQuery) the way
UsdSkel.BakeSkinning does, so a skinned stage renders as its baked copy.

- Points: blend shapes first (BlendShapeQuery, in-betweens included), then the skinning method the prim asks for
  (skel:skinningMethod: classicLinear or dualQuaternion, SkinningQuery.ComputeSkinnedPoints). UsdSkel's result is
  in skeleton space; it is moved into the prim's own space (skeleton-to-world x inverse prim-to-world), as the
  baked points are, with GfMatrix4d::Transform's arithmetic (double sums, float result).
- Rigid bindings (constant jointIndices / jointWeights, SkinningQuery.IsRigidlyDeformed): the prim's points stay,
  its transform is SkinningQuery.ComputeSkinnedTransform x skeleton-to-world. This covers Xforms bound to a joint
  (an analytic eye on a head joint: skel_xform_binding.py, binding properties inherited as UsdSkel inherits them);
  prims below a rigid binding that UsdSkel does not skin itself (cameras, Xforms authoring no binding property)
  follow it.
- Eye meshes skinned per vertex can ask for a moving frame (`follow_dominant_joint`): the transform follows the
  joint that carries most weight (geomBindTransform x that joint's skinning transform x skeleton-to-world) and the
  points are the skinned points in that frame, so the eye's analytic cornea moves with the head and, at the bind
  pose, the points are the bind points (the iris projection's rest pose).

Bad skeleton data (joint counts that do not match, NaN or negative weights, out-of-range joint indices, singular
or non-finite geomBindTransform, a skeleton without bind pose, an animationSource that is not a SkelAnimation)
never raises: the prim gets one warning naming it and renders unskinned (its authored points and transform).
"""
import math

import numpy as np
from pxr import Tf, Usd, UsdGeom, UsdSkel, Vt

from .eyes import is_eye
from .skel_xform_binding import XformSkinningQuery, binds_itself

PREDICATE = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)


def skel_root_of(prim):
    """prim's nearest SkelRoot ancestor-or-self, or None (also for an invalid prim)."""
    while prim and not prim.IsPseudoRoot():
        if prim.IsA(UsdSkel.Root):
            return prim
        prim = prim.GetParent()
    return None


class SkinningError(Exception):
    """Bad skeleton data for one prim: the caller warns once and renders it unskinned."""


def transform_points(points, matrix):
    """float32 (n, 3) points through a Gf.Matrix4d (row vectors), as GfMatrix4d::Transform(GfVec3f) computes:
    double products summed in row order, rounded to float, divided by w in float."""
    m = np.asarray(matrix, dtype=np.float64).reshape(4, 4)
    p = np.asarray(points, dtype=np.float32).astype(np.float64).reshape(-1, 3)
    h = (p[:, 0:1] * m[0] + p[:, 1:2] * m[1] + p[:, 2:3] * m[2] + m[3]).astype(np.float32)
    w = h[:, 3:4]
    inverse = np.where(w != 0, np.float32(1) / np.where(w != 0, w, np.float32(1)), np.float32(1))
    return np.ascontiguousarray(h[:, :3] * inverse)


def transform_normals(normals, matrix):
    """float32 (n, 3) normals times a Gf.Matrix3d (row vectors), as GfVec3f * GfMatrix3d computes: double sums,
    float result."""
    m = np.asarray(matrix, dtype=np.float64).reshape(3, 3)
    v = np.asarray(normals, dtype=np.float32).astype(np.float64).reshape(-1, 3)
    return np.ascontiguousarray((v[:, 0:1] * m[0] + v[:, 1:2] * m[1] + v[:, 2:3] * m[2]).astype(np.float32))


def _inverse_transpose(matrix):
    """The matrix normals take under a transform (BakeSkinning's: of its 3x3 rotation-and-scale part)."""
    return matrix.ExtractRotationMatrix().GetInverse().GetTranspose()


def _finite_matrices(matrices):
    return all(math.isfinite(v) for m in matrices for row in m for v in row)


def _call(what, prim, function, *args):
    """A UsdSkel call whose failure (False, None or a Tf error) becomes a SkinningError naming prim."""
    try:
        result = function(*args)
    except Tf.ErrorException as e:
        first = str(e).strip().splitlines()[-1].strip() if str(e).strip() else "error"
        raise SkinningError(f"{prim.GetPath()}: {what} failed ({first[:120]})") from None
    if result is None or result is False:
        raise SkinningError(f"{prim.GetPath()}: {what} failed")
    return result


class SkinnedPrim:
    """One prim a skeleton deforms (one SkinningQuery target of a SkelRoot's bindings)."""

    def __init__(self, skinning_query, skel_query):
        self.query, self.skel_query = skinning_query, skel_query
        self.prim = skinning_query.GetPrim()
        self.skeleton = skel_query.GetSkeleton().GetPrim()
        self.point_based = self.prim.IsA(UsdGeom.PointBased)
        self.rigid = skinning_query.HasJointInfluences() and skinning_query.IsRigidlyDeformed()
        self.skins_points = self.point_based and skinning_query.HasJointInfluences() and not self.rigid
        self.frame_joint = None  # prim-order joint index whose motion the transform follows (eye meshes)
        self._check()
        self.blend_shapes = self._blend_shape_inputs()

    # -- what it deforms ---------------------------------------------------------------------------------------

    @property
    def deforms_points(self):
        """Whether the prim's points change (per-vertex skinning or blend shapes); else only its transform."""
        return self.skins_points or self.blend_shapes is not None

    @property
    def moves_frame(self):
        """Whether the prim's transform comes from the skeleton (rigid bindings, eye meshes' joint frame)."""
        return self.rigid or self.frame_joint is not None

    def might_vary(self, transform_varies):
        """Whether anything skinning reads may change with time; transform_varies(prim) tells about transforms."""
        anim = self.skel_query.GetAnimQuery()
        if anim and anim.JointTransformsMightBeTimeVarying():
            return True
        if self.blend_shapes is not None and anim and anim.BlendShapeWeightsMightBeTimeVarying():
            return True
        attrs = [self.query.GetJointIndicesPrimvar().GetAttr(), self.query.GetJointWeightsPrimvar().GetAttr(),
                 self.query.GetGeomBindTransformAttr()]
        if self.point_based:
            mesh = UsdGeom.PointBased(self.prim)
            normals = UsdGeom.PrimvarsAPI(self.prim).GetPrimvar("normals")
            attrs += [mesh.GetPointsAttr(), mesh.GetNormalsAttr(), normals.GetAttr() if normals else None]
        if any(a and a.ValueMightBeTimeVarying() for a in attrs):
            return True
        return transform_varies(self.skeleton) or transform_varies(self.prim)

    def follow_dominant_joint(self):
        """Makes the transform follow the joint carrying most of the weight (see the module doc)."""
        if not self.skins_points:
            return
        indices, weights = self._influences(Usd.TimeCode.Default())
        totals = np.bincount(indices, weights=weights, minlength=self._joint_count())
        self.frame_joint = int(np.argmax(totals))

    # -- evaluation --------------------------------------------------------------------------------------------

    def rest_points(self, time):
        """The authored (unskinned) points at `time`, float32 (n, 3): the bind pose."""
        points = UsdGeom.PointBased(self.prim).GetPointsAttr().Get(time)
        return np.asarray(points if points is not None else [], dtype=np.float32).reshape(-1, 3)

    def points(self, time, xform_cache):
        """The deformed points at `time`, float32 (n, 3), in the space `world` maps from."""
        return self.deform(time, xform_cache, with_normals=False)[0]

    def _normals_input(self, time):
        """(normals, interpolation) the prim renders with: primvars:normals (flattened) over the normals
        attribute; (None, None) without either."""
        primvar = UsdGeom.PrimvarsAPI(self.prim).GetPrimvar("normals")
        if primvar and primvar.HasValue():
            return primvar.ComputeFlattened(time), primvar.GetInterpolation()
        mesh = UsdGeom.PointBased(self.prim)
        if mesh.GetNormalsAttr().HasAuthoredValue():
            return mesh.GetNormalsAttr().Get(time), mesh.GetNormalsInterpolation()
        return None, None

    def skinnable_normals(self):
        """Whether the prim's normals can be skinned with its points: per point (vertex, varying: what UsdSkel and
        BakeSkinning skin, from the normals attribute) or per face corner (faceVarying, meshes: each corner takes
        its point's joint influences). Constant and uniform normals cannot follow per-vertex skinning."""
        _, interpolation = self._normals_input(Usd.TimeCode.Default())
        per_corner = interpolation == UsdGeom.Tokens.faceVarying and self.prim.IsA(UsdGeom.Mesh)
        return self.skins_points and (interpolation in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying) or per_corner)

    def normals_interpolation(self):
        return self._normals_input(Usd.TimeCode.Default())[1]

    def deform(self, time, xform_cache, with_normals):
        """(points, normals) at `time`, float32 (n, 3) each, in the space `world` maps from; normals None unless
        with_normals and skinnable_normals(). Blend shapes move points only (their normal offsets are not applied)."""
        points = UsdGeom.PointBased(self.prim).GetPointsAttr().Get(time)
        if points is None or len(points) == 0:
            raise SkinningError(f"{self.prim.GetPath()}: skinned prim has no points")
        if self.blend_shapes is not None:
            self._apply_blend_shapes(points, time)
        if not self.skins_points:
            return np.asarray(points, dtype=np.float32).reshape(-1, 3), None
        xforms = self._skinning_transforms(time)
        _call("skinning points", self.prim, self.query.ComputeSkinnedPoints, xforms, points, time)
        if self.frame_joint is not None:
            skel_to_local = (self._geom_bind(time) * self._prim_order(xforms)[self.frame_joint]).GetInverse()
        else:
            skel_to_local = xform_cache.GetLocalToWorldTransform(self.skeleton) * \
                xform_cache.GetLocalToWorldTransform(self.prim).GetInverse()
        result = transform_points(points, skel_to_local)
        if not np.isfinite(result).all():
            raise SkinningError(f"{self.prim.GetPath()}: skinned points are not finite")
        normals = None
        if with_normals and self.skinnable_normals():
            normals = self._skinned_normals(time, xforms, skel_to_local)
        return result, normals

    def _skinned_normals(self, time, xforms, skel_to_local):
        """The `normals` attribute skinned like the points (UsdSkel.SkinNormals with the joints' inverse-transpose
        transforms, as BakeSkinning does), in the points' space."""
        normals, interpolation = self._normals_input(time)
        indices, weights = _call("reading joint influences", self.prim, self.query.ComputeJointInfluences, time)
        if interpolation == UsdGeom.Tokens.faceVarying:  # each face corner follows its point's joints
            per = self.query.GetNumInfluencesPerComponent()
            corners = np.asarray(UsdGeom.Mesh(self.prim).GetFaceVertexIndicesAttr().Get(time) or [], dtype=np.int64)
            indices = Vt.IntArray.FromNumpy(np.ascontiguousarray(np.asarray(indices).reshape(-1, per)[corners].ravel()))
            weights = Vt.FloatArray.FromNumpy(np.ascontiguousarray(
                np.asarray(weights, dtype=np.float32).reshape(-1, per)[corners].ravel()))
            count = len(corners)
        else:
            count = len(UsdGeom.PointBased(self.prim).GetPointsAttr().Get(time) or [])
        if normals is None or len(normals) != count:
            raise SkinningError(f"{self.prim.GetPath()}: {0 if normals is None else len(normals)} {interpolation} "
                                f"normals for {count} {'face corners' if interpolation == 'faceVarying' else 'points'}")
        normals = Vt.Vec3fArray(normals)
        joint_normals = Vt.Matrix3dArray([_inverse_transpose(m) for m in self._prim_order(xforms)])
        _call("skinning normals", self.prim, UsdSkel.SkinNormals, self.query.GetSkinningMethod(),
              _inverse_transpose(self._geom_bind(time)), joint_normals, indices, weights,
              self.query.GetNumInfluencesPerComponent(), normals)
        result = transform_normals(normals, _inverse_transpose(skel_to_local))
        if not np.isfinite(result).all():
            raise SkinningError(f"{self.prim.GetPath()}: skinned normals are not finite")
        return result

    def world(self, time, xform_cache):
        """The prim's local-to-world transform at `time` (Gf.Matrix4d) with its skinning applied."""
        if self.rigid:
            xforms = self._skinning_transforms(time)
            skinned = _call("skinning the transform", self.prim, self.query.ComputeSkinnedTransform, xforms, time)
            # As BakeSkinning writes it: a local transform under the parent, then composed with the parent.
            parent = xform_cache.GetParentToWorldTransform(self.prim)
            local = skinned * xform_cache.GetLocalToWorldTransform(self.skeleton) * parent.GetInverse()
            world = local * parent
        elif self.frame_joint is not None:
            xforms = self._skinning_transforms(time)
            world = self._geom_bind(time) * self._prim_order(xforms)[self.frame_joint] * \
                xform_cache.GetLocalToWorldTransform(self.skeleton)
        else:
            return xform_cache.GetLocalToWorldTransform(self.prim)
        if not _finite_matrices([world]) or abs(world.GetDeterminant3()) < 1e-300:
            raise SkinningError(f"{self.prim.GetPath()}: skinned transform is singular or not finite")
        return world

    # -- inputs ------------------------------------------------------------------------------------------------

    def _joint_count(self):
        order = self.query.GetJointOrder()
        return len(order) if order else len(self.skel_query.GetJointOrder())

    def _prim_order(self, xforms):
        """Skinning transforms (skeleton order) in the prim's skel:joints order."""
        order = self.query.GetJointOrder()
        if not order:
            return list(xforms)
        by_name = dict(zip(self.skel_query.GetJointOrder(), xforms))
        return [by_name[name] for name in order]

    def _influences(self, time):
        indices, weights = _call("reading joint influences", self.prim, self.query.ComputeJointInfluences, time)
        return np.asarray(indices, dtype=np.int64), np.asarray(weights, dtype=np.float64)

    def _geom_bind(self, time):
        return self.query.GetGeomBindTransform(time)

    def _skinning_transforms(self, time):
        xforms = _call("computing skinning transforms", self.prim, self.skel_query.ComputeSkinningTransforms, time)
        if not _finite_matrices(xforms):
            raise SkinningError(f"{self.prim.GetPath()}: skeleton {self.skeleton.GetPath()} has non-finite joint "
                                f"transforms at time {time}")
        return xforms

    def _blend_shape_inputs(self):
        """(BlendShapeQuery, point indices, sub-shape offsets) when the prim has blend shapes and the skeleton's
        animation drives them; None otherwise."""
        anim = self.skel_query.GetAnimQuery()
        if not (self.point_based and self.query.HasBlendShapes() and anim and anim.GetBlendShapeOrder()):
            return None
        query = UsdSkel.BlendShapeQuery(UsdSkel.BindingAPI(self.prim))
        if not query.GetNumBlendShapes():
            return None
        return query, query.ComputeBlendShapePointIndices(), query.ComputeSubShapePointOffsets()

    def _apply_blend_shapes(self, points, time):
        query, point_indices, offsets = self.blend_shapes
        anim = self.skel_query.GetAnimQuery()
        weights = _call("reading blend shape weights", self.prim, anim.ComputeBlendShapeWeights, time)
        if len(weights) != len(anim.GetBlendShapeOrder()):
            raise SkinningError(f"{self.prim.GetPath()}: animation {anim.GetPrim().GetPath()} has {len(weights)} "
                                f"blendShapeWeights for {len(anim.GetBlendShapeOrder())} blendShapes at time {time}")
        mapper = self.query.GetBlendShapeMapper()
        if mapper and not mapper.IsIdentity():
            weights = _call("remapping blend shape weights", self.prim, mapper.Remap, weights)
        if len(weights) != query.GetNumBlendShapes():
            raise SkinningError(f"{self.prim.GetPath()}: {len(weights)} blend shape weights at time {time} for "
                                f"{query.GetNumBlendShapes()} blend shapes")
        if not all(math.isfinite(w) for w in weights):
            raise SkinningError(f"{self.prim.GetPath()}: blend shape weights are not finite at time {time}")
        sub_weights, shape_indices, sub_indices = _call("resolving blend shape weights", self.prim,
                                                        query.ComputeSubShapeWeights, weights)
        _call("applying blend shapes", self.prim, query.ComputeDeformedPoints, sub_weights, shape_indices,
              sub_indices, point_indices, offsets, points)

    def _check(self):
        """Raises SkinningError for data UsdSkel would reject or turn into NaN (checked once, before the first use,
        so USD's own warnings never fire)."""
        path = self.prim.GetPath()
        skeleton = UsdSkel.Skeleton(self.skeleton)
        if self.query.HasJointInfluences():  # blend shapes alone need no bind pose (a Skeleton of no joints)
            self._check_bind_pose(path, skeleton)
        order = self.query.GetJointOrder()
        missing = [name for name in (order or []) if name not in set(self.skel_query.GetJointOrder())]
        if missing:
            raise SkinningError(f"{path}: skel:joints names '{missing[0]}', not a joint of {self.skeleton.GetPath()}")
        geom_bind = self._geom_bind(Usd.TimeCode.Default())
        if not _finite_matrices([geom_bind]) or abs(geom_bind.GetDeterminant3()) < 1e-300:
            raise SkinningError(f"{path}: skel:geomBindTransform is singular or not finite")
        if self.query.HasJointInfluences():
            self._check_influences(path)
        method = self.query.GetSkinningMethodAttr().Get() if self.query.GetSkinningMethodAttr() else None
        if method is not None and method not in (UsdSkel.Tokens.classicLinear, UsdSkel.Tokens.dualQuaternion):
            raise SkinningError(f"{path}: skel:skinningMethod '{method}' is not classicLinear or dualQuaternion")
        self._check_animation()
        if self.point_based and self.query.HasBlendShapes():
            self._check_blend_shapes(path)
        if self.query.HasJointInfluences():
            self._skinning_transforms(Usd.TimeCode.Default())

    def _check_bind_pose(self, path, skeleton):
        """One bind transform per joint, finite and invertible, and one rest transform per joint if any."""
        joints = skeleton.GetJointsAttr().Get() or []
        binds = skeleton.GetBindTransformsAttr().Get()
        if not self.skel_query.HasBindPose() or binds is None or len(binds) != len(joints):
            raise SkinningError(f"{path}: skeleton {self.skeleton.GetPath()} has {0 if binds is None else len(binds)} "
                                f"bindTransforms for {len(joints)} joints")
        rests = skeleton.GetRestTransformsAttr().Get()
        if rests is not None and len(rests) != len(joints):
            raise SkinningError(f"{path}: skeleton {self.skeleton.GetPath()} has {len(rests)} restTransforms for "
                                f"{len(joints)} joints")
        if not _finite_matrices(binds) or any(abs(b.GetDeterminant3()) < 1e-300 for b in binds):
            raise SkinningError(f"{path}: skeleton {self.skeleton.GetPath()} has a singular or non-finite bind "
                                f"transform")

    def _check_animation(self):
        """The SkelAnimation's translations, rotations and scales hold one value per animated joint at every time
        sample (UsdSkel would warn and fall back to the rest pose)."""
        anim = self.skel_query.GetAnimQuery()
        if not anim:
            return
        animation = UsdSkel.Animation(anim.GetPrim())
        if not animation:
            return
        joints = len(animation.GetJointsAttr().Get() or [])
        for attr in (animation.GetTranslationsAttr(), animation.GetRotationsAttr(), animation.GetScalesAttr()):
            if not attr.HasAuthoredValue():
                continue
            for time in attr.GetTimeSamples() or [Usd.TimeCode.Default()]:
                value = attr.Get(time)
                if value is not None and len(value) != joints:
                    raise SkinningError(f"{self.prim.GetPath()}: animation {animation.GetPath()} has {len(value)} "
                                        f"{attr.GetName()} for {joints} joints")

    def _check_blend_shapes(self, path):
        """Every skel:blendShapeTargets target is a BlendShape whose offsets match its point indices (or the points)
        and whose point indices are in range, and skel:blendShapes names one target each."""
        api = UsdSkel.BindingAPI(self.prim)
        targets = api.GetBlendShapeTargetsRel().GetForwardedTargets() if api.GetBlendShapeTargetsRel() else []
        names = api.GetBlendShapesAttr().Get() or []
        if len(names) != len(targets):
            raise SkinningError(f"{path}: skel:blendShapes has {len(names)} names for {len(targets)} "
                                f"skel:blendShapeTargets")
        count = len(self.rest_points(Usd.TimeCode.Default()))
        for target in targets:
            shape = UsdSkel.BlendShape(self.prim.GetStage().GetPrimAtPath(target))
            if not shape:
                raise SkinningError(f"{path}: skel:blendShapeTargets {target} is not a BlendShape")
            indices = shape.GetPointIndicesAttr().Get()
            for offsets in [shape.GetOffsetsAttr().Get()] + [i.GetOffsets() for i in shape.GetInbetweens()]:
                expected = count if indices is None else len(indices)
                if offsets is not None and len(offsets) != expected:
                    raise SkinningError(f"{path}: blend shape {target} has {len(offsets)} offsets for {expected} "
                                        f"{'points' if indices is None else 'point indices'}")
            if indices is not None and len(indices) and (min(indices) < 0 or max(indices) >= count):
                raise SkinningError(f"{path}: blend shape {target} has point indices outside [0, {count})")

    def _check_influences(self, path):
        indices, weights = self._influences(Usd.TimeCode.Default())
        per = self.query.GetNumInfluencesPerComponent()
        if len(indices) != len(weights):
            raise SkinningError(f"{path}: {len(indices)} jointIndices for {len(weights)} jointWeights")
        if self.query.GetInterpolation() == UsdGeom.Tokens.vertex:
            count = len(self.rest_points(Usd.TimeCode.Default())) if self.point_based else 0
            if len(indices) != count * per:
                raise SkinningError(f"{path}: {len(indices)} jointIndices for {count} points x {per} influences")
        elif len(indices) != per:
            raise SkinningError(f"{path}: constant jointIndices hold {len(indices)} values, elementSize is {per}")
        if not np.isfinite(weights).all() or (weights < 0).any():
            raise SkinningError(f"{path}: jointWeights hold NaN, infinite or negative values")
        joints = self._joint_count()
        if len(indices) and (indices.min() < 0 or indices.max() >= joints):
            raise SkinningError(f"{path}: jointIndices refer to joints outside [0, {joints})")


class StageSkinning:
    """The skinned prims of a stage, SkelRoot by SkelRoot (`add_root`, called as the scene delegate meets each
    SkelRoot, before its children), through one UsdSkel.Cache per SkelRoot so that re-populating one rebuilds only
    its own; unskinnable bindings are reported in `warnings` (one line each, naming the prim) and left out.
    Bindings outside a SkelRoot are not skinned (UsdSkel's rule; BakeSkinning's output relies on it)."""

    def __init__(self, warnings):
        self.warnings = warnings
        self.targets = {}   # prim path -> SkinnedPrim
        self._anchors = {}  # prim path -> the nearest rigidly skinned ancestor-or-self (a SkinnedPrim) or None
        self._caches = {}   # SkelRoot path -> its UsdSkel.Cache

    def add_root(self, root_prim):
        """Finds the skinned prims under a SkelRoot (replacing what an earlier add_root of it found)."""
        self.remove_under(root_prim.GetPath())
        self._caches[root_prim.GetPath()] = UsdSkel.Cache()
        self._add_root(root_prim)

    def remove_under(self, path):
        """Forgets the SkelRoots and skinned prims at or under `path` (before they are re-populated)."""
        for root in [r for r in self._caches if r.HasPrefix(path)]:
            del self._caches[root]
        for target in [t for t in self.targets if t.HasPrefix(path)]:
            del self.targets[target]
        self._anchors.clear()

    @staticmethod
    def _has_joint_influences(prim):
        return prim.HasAPI(UsdSkel.BindingAPI) and UsdSkel.BindingAPI(prim).GetJointIndicesPrimvar().HasAuthoredValue()

    def _add_root(self, root_prim):
        root, cache = UsdSkel.Root(root_prim), self._caches[root_prim.GetPath()]
        try:
            cache.Populate(root, PREDICATE)
            bindings = cache.ComputeSkelBindings(root, PREDICATE)
        except Tf.ErrorException:
            self.warnings.append(f"{root_prim.GetPath()}: UsdSkel could not read this SkelRoot (rendered unskinned)")
            return
        for binding in bindings:
            skel_query = cache.GetSkelQuery(binding.GetSkeleton())
            skeleton = binding.GetSkeleton().GetPrim()
            self._check_animation_source(skeleton, skel_query)
            for query in binding.GetSkinningTargets():
                prim = query.GetPrim()
                if not skel_query:
                    self.warnings.append(f"{prim.GetPath()}: skeleton {skeleton.GetPath()} is not valid "
                                         f"(rendered unskinned)")
                    continue
                try:
                    skinned = SkinnedPrim(query, skel_query)
                except SkinningError as e:
                    self.warnings.append(f"{e} (rendered unskinned)")
                    continue
                except Tf.ErrorException:
                    self.warnings.append(f"{prim.GetPath()}: UsdSkel could not read its binding (rendered unskinned)")
                    continue
                if skinned.deforms_points or skinned.rigid:
                    if is_eye(prim):
                        skinned.follow_dominant_joint()
                    self.targets[prim.GetPath()] = skinned
        for prim in Usd.PrimRange(root_prim, PREDICATE):
            if prim.GetPath() in self.targets:
                continue
            xform = prim.IsA(UsdGeom.Xformable) and not prim.IsA(UsdGeom.Boundable)
            if xform and binds_itself(prim) and self._add_xform(prim, cache):
                continue
            if not self._has_joint_influences(prim):
                continue
            if not any(w.startswith(f"{prim.GetPath()}:") for w in self.warnings):
                self.warnings.append(f"{prim.GetPath()}: {self._why_not_bound(prim)} (rendered unskinned)")

    def _add_xform(self, prim, cache):
        """Adds an Xform rigidly bound to a joint (XformSkinningQuery, its binding properties inherited as UsdSkel
        inherits them); False when it has no skeleton or no joint influences."""
        skeleton = UsdSkel.BindingAPI(prim).GetInheritedSkeleton()
        skel_query = cache.GetSkelQuery(skeleton) if skeleton else None
        query = XformSkinningQuery(prim, skel_query) if skel_query else None
        if query is None or not query.HasJointInfluences():
            return False
        try:
            if not query.IsRigidlyDeformed():
                raise SkinningError(f"{prim.GetPath()}: an Xform can only be bound rigidly (constant jointIndices)")
            self.targets[prim.GetPath()] = SkinnedPrim(query, skel_query)
        except SkinningError as e:
            self.warnings.append(f"{e} (rendered unskinned)")
        return True

    @staticmethod
    def _why_not_bound(prim):
        """Why UsdSkel made no skinning target of a prim with joint influences under a SkelRoot."""
        api = UsdSkel.BindingAPI(prim)
        skeleton = api.GetSkeletonRel().GetForwardedTargets() if api.GetSkeletonRel() else []
        if not api.GetInheritedSkeleton():
            return f"has joint influences but skel:skeleton {skeleton[0]} is not a Skeleton" if skeleton else \
                "has joint influences but no skel:skeleton"
        indices, weights = api.GetJointIndicesPrimvar(), api.GetJointWeightsPrimvar()
        return (f"jointIndices / jointWeights are not usable by UsdSkel (elementSize {indices.GetElementSize()} / "
                f"{weights.GetElementSize()}, interpolation {indices.GetInterpolation()} / "
                f"{weights.GetInterpolation()}; they must match, vertex or constant)")

    def _check_animation_source(self, skeleton, skel_query):
        rel = UsdSkel.BindingAPI(skeleton).GetAnimationSourceRel()
        targets = rel.GetForwardedTargets() if rel else []
        if targets and not (skel_query and skel_query.GetAnimQuery()):
            self.warnings.append(f"{skeleton.GetPath()}: skel:animationSource {targets[0]} is not a SkelAnimation "
                                 f"(the skeleton stays in its rest pose)")

    def get(self, prim):
        """The SkinnedPrim for prim, or None."""
        return self.targets.get(prim.GetPath())

    def drop(self, skinned, error):
        """Stops skinning a prim whose data failed at some time (one warning): it renders unskinned from then."""
        self.targets.pop(skinned.prim.GetPath(), None)
        self._anchors.clear()
        self.warnings.append(f"{error} (rendered unskinned)")

    def rigid_anchor(self, prim):
        """The nearest rigidly skinned ancestor-or-self of prim (a SkinnedPrim whose transform prim follows), or
        None."""
        path = prim.GetPath()
        if path not in self._anchors:
            anchor = self.targets.get(path)
            if anchor is None or not anchor.moves_frame:
                parent = prim.GetParent()
                anchor = self.rigid_anchor(parent) if parent and not parent.IsPseudoRoot() else None
            self._anchors[path] = anchor
        return self._anchors[path]

    def world(self, prim, xform_cache, time):
        """prim's local-to-world transform with the skinning of it or of a rigidly skinned ancestor applied.
        Raises SkinningError for data that fails at this time."""
        anchor = self.rigid_anchor(prim)
        if anchor is None:
            return xform_cache.GetLocalToWorldTransform(prim)
        world = anchor.world(time, xform_cache)
        if anchor.prim == prim:
            return world
        relative, _ = xform_cache.ComputeRelativeTransform(prim, anchor.prim)
        return relative * world
