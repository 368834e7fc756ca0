"""An eyeview of a small authored stage (an analytic eye, a sphere key light, a camera), its render loop on a thread
of its own as `eyeview` runs it on the main one, and its server on port 0."""
import threading

from pxr import Gf, Usd, UsdGeom, UsdLux

from eyerender.cli.eyeview import build_parser, check_args, open_viewer


def eye_stage(path):
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, "Y")
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    cam = UsdGeom.Camera.Define(stage, "/World/cam")
    cam.CreateFocalLengthAttr(80.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 60))
    UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim().AddAppliedSchema("EyeAPI")
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateRadiusAttr(1.0)
    light.CreateIntensityAttr(3000.0)
    light.AddTranslateOp().Set(Gf.Vec3d(20, 10, 30))
    stage.Save()
    return str(path)


class RunningView:
    """viewer, server and url of an eyeview on `stage_path`; close() stops the loop and the server."""

    def __init__(self, stage_path, save_path, width=64):
        args = build_parser().parse_args([stage_path, "-w", str(width), "--port", "0", "--threads", "2",
                                          "--save", str(save_path)])
        self.viewer, self.server = open_viewer(args, check_args(args))
        self.url = self.server.url
        self.server.start()
        self.loop = threading.Thread(target=self.viewer.run, name="eyeview-render", daemon=True)
        self.loop.start()
        self.closed = False

    def close(self):
        if not self.closed:
            self.closed = True
            self.viewer.stop()
            self.loop.join(timeout=30)
            self.server.close()
