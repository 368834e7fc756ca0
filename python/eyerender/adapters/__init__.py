"""The prim adapters (UsdImaging's prim adapters): one per kind of prim the scene delegate renders, each behind
the PrimAdapter interface (base.py), and the registry that picks a prim's adapter.

The registry is ordered as a prim's kinds are tested: a PointInstancer, a Mesh (an eye mesh with the EyeAPI),
BasisCurves, Points, a Camera, a UsdLux light, another Gprim (the implicit surfaces), then an Xformable with the
EyeAPI (an analytic eye). UsdImaging keys its registry by the prim's exact schema type; here a kind is an IsA test
(a NurbsCurves is a Gprim, an eye any Xformable with the API), so the first adapter whose `handles` accepts the
prim is its adapter. Materials have an adapter too, reached through bindings rather than traversal.
"""
from .base import PrimAdapter
from .basis_curves import BasisCurvesAdapter
from .camera import CameraAdapter
from .eye import EyeAdapter
from .gprim import GprimAdapter
from .light import LightAdapter
from .material import MaterialAdapter
from .mesh import MeshAdapter
from .point_instancer import PointInstancerAdapter
from .points import PointsAdapter


class AdapterRegistry:
    """One adapter of each kind for one scene delegate; the adapters other code calls are attributes."""

    def __init__(self, delegate):
        self.material = MaterialAdapter(delegate)
        self.eye = EyeAdapter(delegate)
        self.mesh = MeshAdapter(delegate)
        self.light = LightAdapter(delegate)
        self.camera = CameraAdapter(delegate)
        self.ordered = (PointInstancerAdapter(delegate), self.mesh, BasisCurvesAdapter(delegate),
                        PointsAdapter(delegate), self.camera, self.light, GprimAdapter(delegate), self.eye)

    def for_prim(self, prim):
        """The adapter of prim's kind, or None for a prim that renders nothing of its own (an Xform, a Scope)."""
        return next((adapter for adapter in self.ordered if adapter.handles(prim)), None)

    def __iter__(self):
        """Every adapter, the material adapter included."""
        return iter((*self.ordered, self.material))


__all__ = ["AdapterRegistry", "BasisCurvesAdapter", "CameraAdapter", "EyeAdapter", "GprimAdapter", "LightAdapter",
           "MaterialAdapter", "MeshAdapter", "PointInstancerAdapter", "PointsAdapter", "PrimAdapter"]
