#!/usr/bin/env python3
"""The motion-blur contact sheet of docs/motion_blur.md: the saccade and the blink of usd_samples, each at three
frames, sharp (--shutter 0) above blurred (the camera's 180-degree shutter, -0.25 to 0.25 frames).

Rows: saccade sharp, saccade blurred (frames 10, 11, 12: the eye turns 10 degrees within frame 11's shutter and
is still through 10's and 12's), blink sharp, blink blurred (frames 10 and 11 closing, 16 opening). Each tile is
rendered through eyerender.RenderSession with the render plan, --width pixels square at --spp samples, then tiled
by scripts/contact_sheet.py and re-encoded as a 256-colour PNG (fig5_limbal_arc.contact_sheet) to stay small.

Writes docs/motion_blur_contact_sheet.png. Run: python3 scripts/figures/motion_blur_sheet.py [--width 96] [--spp 64]
"""
import argparse
import pathlib
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
import fig5_limbal_arc as f5  # noqa: E402  (the contact sheet)

ROWS = (("saccade", (10, 11, 12)), ("blink", (10, 11, 16)))
OUT = REPO / "docs" / "motion_blur_contact_sheet.png"


def render_tile(stage_name, frame, shutter, width, spp, path):
    from pxr import Usd

    from eyerender import RenderSession
    from eyerender.plan import make_overrides

    stage = Usd.Stage.Open(str(REPO / "usd_samples" / f"{stage_name}.usda"))
    session = RenderSession(stage, width=width, time=Usd.TimeCode(frame), shutter=shutter,
                            plan_overrides=make_overrides())
    session.render(spp=spp)
    session.write(str(path))
    return session.scene.shutter


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=96, help="tile size in pixels (default 96)")
    parser.add_argument("--spp", type=int, default=64, help="samples per pixel (default 64)")
    args = parser.parse_args(argv)
    tiles = []
    with tempfile.TemporaryDirectory() as tmp:
        for stage_name, frames in ROWS:
            for label, shutter in (("sharp", (0.0, 0.0)), ("blurred", None)):
                for frame in frames:
                    path = pathlib.Path(tmp) / f"{stage_name}_{label}_{frame}.png"
                    used = render_tile(stage_name, frame, shutter, args.width, args.spp, path)
                    print(f"{stage_name} frame {frame}: {used.describe() if used.blurred else 'sharp'}")
                    tiles.append(path)
        f5.contact_sheet(OUT, tiles, max(len(frames) for _, frames in ROWS))
    print(f"wrote {OUT.relative_to(REPO)} ({OUT.stat().st_size // 1024} KB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
