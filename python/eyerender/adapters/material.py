"""UsdShade materials as delegate materials (HdMaterial): added once, on the first prim bound to one (the binding
purposes in order: UsdShade's ComputeBoundMaterial), and followed where their network varies in time."""
from pxr import Sdf, Usd, UsdShade

from .. import materials
from ..usd_values import varies as _varies
from .base import PrimAdapter


class MaterialAdapter(PrimAdapter):

    def __init__(self, delegate):
        super().__init__(delegate)
        self.st_names = {}  # material path -> the st primvar name its textures read

    def bind(self, prim):
        """(material id, st primvar name) of prim's bound material, adding the material on first use."""
        d = self.delegate
        material = materials.bound_material(prim, d.material_purposes)
        if not material:
            return "", "st"
        path = material.GetPath().pathString
        if path not in self.st_names:
            params, st_name, ignored = materials.read_material(material, d.time)
            d.store.add_material(path, params)
            d.warnings.extend(ignored)
            self.st_names[path] = st_name
            if any(_varies(p.GetAttributes()) for p in Usd.PrimRange(material.GetPrim())):
                d.add_updater("material", lambda t: d.store.set_material_params(
                    path, materials.read_material(material, t)[0]), owner=material.GetPath())
        return path, self.st_names[path]

    def material_at(self, path):
        """The path (a string) of the added material at or above property or prim path `path`, or None."""
        return next((m for m in self.st_names if path.HasPrefix(Sdf.Path(m))), None)

    def push(self, material_path):
        """Re-sends an added material's params at the current time (an edit in its network)."""
        d = self.delegate
        d.store.set_material_params(material_path, materials.read_material(
            UsdShade.Material(d.stage.GetPrimAtPath(material_path)), d.time)[0])
