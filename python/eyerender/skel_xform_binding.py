"""Xforms bound to a joint (an analytic eye on a head joint), for skinning.py. UsdSkel binds only boundable
prims (UsdSkel.IsSkinnablePrim), so UsdSkel.Cache makes no SkinningQuery for an Xform, and usd-core's Python
SkinningQuery cannot be built from attributes. XformSkinningQuery is the part of a SkinningQuery a rigid binding
needs, with the binding properties resolved as UsdSkel resolves them for a gprim in the Xform's place.

UsdSkel's inheritance (UsdSkel_CacheImpl::ReadScope::Populate): jointIndices, jointWeights, geomBindTransform,
skel:joints and skel:skinningMethod each come from the nearest ancestor-or-self, up to and including the SkelRoot,
that has an authored value; skel:skeleton through UsdSkel.BindingAPI.GetInheritedSkeleton. Blend shapes are not
inherited (and an Xform has no points to shape).

Which Xforms are bound themselves (`binds_itself`): one that authors any of those properties. One that authors
none follows its nearest bound ancestor with its own local transform (StageSkinning.rigid_anchor), where UsdSkel
would move a gprim there onto the ancestor's geomBindTransform: two eyes under one bound head stay apart.
"""
from pxr import Gf, UsdGeom, UsdSkel, Vt

# UsdSkel.BindingAPI getters of the properties UsdSkel inherits down the namespace.
INHERITED_GETTERS = ("GetJointIndicesAttr", "GetJointWeightsAttr", "GetGeomBindTransformAttr", "GetJointsAttr",
                     "GetSkinningMethodAttr")


def _authored(prim, getter):
    attr = getattr(UsdSkel.BindingAPI(prim), getter)()
    return attr if attr and attr.HasAuthoredValue() else None


def inherited_binding_attr(prim, getter):
    """The attribute UsdSkel reads for a binding property of prim (getter: one of INHERITED_GETTERS): prim's own
    when authored, else the nearest authored one of its ancestors up to its SkelRoot; else prim's own (unauthored,
    possibly invalid)."""
    p = prim
    while p and not p.IsPseudoRoot():
        attr = _authored(p, getter)
        if attr is not None:
            return attr
        if p.IsA(UsdSkel.Root):
            break
        p = p.GetParent()
    return getattr(UsdSkel.BindingAPI(prim), getter)()


def binds_itself(prim):
    """Whether an Xform authors a binding property of its own (then it is bound as UsdSkel binds a gprim)."""
    return prim.HasAPI(UsdSkel.BindingAPI) and any(_authored(prim, g) is not None for g in INHERITED_GETTERS)


class XformSkinningQuery:
    """A rigid binding of an Xform (constant jointIndices / jointWeights, geomBindTransform, skel:joints,
    skinningMethod, each resolved as UsdSkel inherits it); its transform is skinned with UsdSkel's own
    UsdSkel.SkinTransform. BakeSkinning and usdview leave such an Xform in place."""

    def __init__(self, prim, skel_query):
        self._prim, self._skel_query = prim, skel_query
        self._attrs = {getter: inherited_binding_attr(prim, getter) for getter in INHERITED_GETTERS}

    def GetPrim(self):
        return self._prim

    def GetJointIndicesPrimvar(self):
        return UsdGeom.Primvar(self._attrs["GetJointIndicesAttr"])

    def GetJointWeightsPrimvar(self):
        return UsdGeom.Primvar(self._attrs["GetJointWeightsAttr"])

    def GetGeomBindTransformAttr(self):
        return self._attrs["GetGeomBindTransformAttr"]

    def GetGeomBindTransform(self, time):
        attr = self.GetGeomBindTransformAttr()
        value = attr.Get(time) if attr else None
        return value if value is not None else Gf.Matrix4d(1)

    def GetJointOrder(self):
        attr = self._attrs["GetJointsAttr"]
        return attr.Get() if attr else None

    def GetSkinningMethodAttr(self):
        return self._attrs["GetSkinningMethodAttr"]

    def GetSkinningMethod(self):
        attr = self.GetSkinningMethodAttr()
        return (attr.Get() if attr else None) or UsdSkel.Tokens.classicLinear

    def GetInterpolation(self):
        return self.GetJointIndicesPrimvar().GetInterpolation()

    def GetNumInfluencesPerComponent(self):
        return self.GetJointIndicesPrimvar().GetElementSize()

    def HasJointInfluences(self):
        indices, weights = self._attrs["GetJointIndicesAttr"], self._attrs["GetJointWeightsAttr"]
        return bool(indices and weights and indices.HasAuthoredValue() and weights.HasAuthoredValue())

    def IsRigidlyDeformed(self):
        return self.GetInterpolation() == UsdGeom.Tokens.constant

    def HasBlendShapes(self):
        return False

    def GetTimeSamplesInInterval(self, interval):
        """Time samples in `interval` (Gf.Interval) of the binding's inputs, as UsdSkel.SkinningQuery gives them."""
        attrs = [self._attrs["GetJointIndicesAttr"], self._attrs["GetJointWeightsAttr"],
                 self.GetGeomBindTransformAttr()]
        return sorted({t for a in attrs if a for t in a.GetTimeSamplesInInterval(interval)})

    def ComputeJointInfluences(self, time):
        return self.GetJointIndicesPrimvar().Get(time), self.GetJointWeightsPrimvar().Get(time)

    def ComputeSkinnedTransform(self, xforms, time):
        order = self.GetJointOrder()
        if order:
            by_name = dict(zip(self._skel_query.GetJointOrder(), xforms))
            xforms = Vt.Matrix4dArray([by_name[name] for name in order])
        indices, weights = self.ComputeJointInfluences(time)
        return UsdSkel.SkinTransform(self.GetSkinningMethod(), self.GetGeomBindTransform(time), xforms, indices,
                                     weights)
