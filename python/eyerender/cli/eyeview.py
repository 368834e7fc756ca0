"""eyeview STAGE: look-dev in the browser. One command starts a web server on 127.0.0.1 and renders the stage
progressively; the page shows the render as it converges (tone-mapped, with exposure, an AOV selector and the render
plan's lines) and its controls edit the stage through its session layer: the key light's direction and intensity,
the camera, the eye's EyeAPI pupil, limbus ratios, iris depth and gaze (view_edits.py). "save" writes the session
layer as a .usda to sublayer over the stage. docs/eyeview.md."""
import argparse
import os
import sys

from ..errors import EyeRenderError, run_command

DEFAULT_PORT = 8765


def build_parser():
    p = argparse.ArgumentParser(prog="eyeview", description=__doc__.split("\n\n")[0])
    p.add_argument("usdFilePath", help="the USD stage to look at")
    p.add_argument("--camera", "-cam", help="camera prim path or name (default: as eyerecord chooses)")
    p.add_argument("--imageWidth", "-w", type=int, default=256, help="width in pixels (default 256)")
    p.add_argument("--imageHeight", type=int, help="height in pixels (default: from the camera's aperture ratio)")
    p.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"port on 127.0.0.1 (default {DEFAULT_PORT}; "
                   "0: any free port)")
    p.add_argument("--threads", type=int, default=0, help="render threads (default 0: all cores)")
    p.add_argument("--spp", type=int, default=4096, help="samples per pixel a still view converges to")
    p.add_argument("--save", metavar="PATH.usda", help="where 'save' writes the session layer (default: "
                   "STAGE's name + .session.usda in the current folder)")
    return p


def check_args(args):
    if args.imageWidth < 1 or (args.imageHeight is not None and args.imageHeight < 1):
        raise EyeRenderError("--imageWidth and --imageHeight must be at least 1 pixel")
    if not 0 <= args.port <= 65535:
        raise EyeRenderError(f"--port {args.port}: must be 0 to 65535")
    if args.threads < 0 or args.spp < 1:
        raise EyeRenderError("--threads must be 0 or more and --spp at least 1")
    save = args.save or os.path.splitext(os.path.basename(args.usdFilePath))[0] + ".session.usda"
    if not save.endswith(".usda"):
        raise EyeRenderError(f"--save {save}: must be a .usda file")
    return save


def open_viewer(args, save):
    """(viewer, server) for parsed arguments: the stage opened, its session made and its first plan printed."""
    from ..job import SessionOptions, open_session, open_stage
    from ..view_edits import StageEditor
    from ..view_server import ViewServer
    from ..viewer import VIEW_AOVS, Viewer

    stage = open_stage(args.usdFilePath)
    options = SessionOptions(width=args.imageWidth, height=args.imageHeight, camera=args.camera, aovs=VIEW_AOVS,
                             settings=(("threads", args.threads),))
    session = open_session(stage, options)
    editor = StageEditor(stage, session.camera_id, session.scene.time)
    viewer = Viewer(session, editor, spp=args.spp)
    try:
        server = ViewServer(viewer, args.port, save, session.aovs)
    except OSError as e:
        raise EyeRenderError(f"cannot serve on 127.0.0.1:{args.port}: {e.strerror or e}") from None
    return viewer, server


def run(argv=None):
    args = build_parser().parse_args(argv)
    save = check_args(args)
    viewer, server = open_viewer(args, save)
    from ..console import print_warnings

    print_warnings(viewer.session.scene.warnings, tool="eyeview")
    server.start()
    print(f"eyeview: {args.usdFilePath} at {server.url} (Ctrl-C to stop)", flush=True)
    try:
        viewer.run()
    finally:
        server.close()
    return 0


def main(argv=None):
    return run_command("eyeview", run, argv, interrupted="stopped")


if __name__ == "__main__":
    sys.exit(main())
