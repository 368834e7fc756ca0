#!/usr/bin/env python3
"""Interactive look-dev numbers (docs/eyeview.md): what eyeview's render loop gives after an edit, on scene B.

- Time to first pixel after an edit (stage edit to the end of the first full-image pass, sync and plan included)
  at 256 x 256 on 2 threads, over light moves and pupil edits: median and worst.
- The iris's relative RMSE against scene B's independent reference (compare.py's pixels: the albedo-0.5 annulus,
  glint excluded) against the seconds since a light move: the key starts 30 degrees away, renders a second, and is
  moved back to the reference position through the session layer (view_edits.StageEditor, as eyeview does).
- At 1920 x 1080: the first full image of a fresh session (stage opened, first render) and after an edit.

    python3 bench/bench_interactive.py [--scene-dir DIR] [--threads 2] [--repeats 5]
"""
import argparse
import os
import statistics
import sys
import time

import numpy as np

DEFAULT_SCENE_DIR = os.environ.get("EYERENDER_SCENE_B", "/work/shared/bench/sceneB")
CHECKPOINTS = (0.25, 0.5, 1.0, 2.0, 4.0)  # seconds after the light move


def open_view(scene_dir, width, height, threads):
    from eyerender.job import SessionOptions, open_session, open_stage
    from eyerender.view_edits import StageEditor

    stage = open_stage(os.path.join(scene_dir, "sceneB.usda"))
    options = SessionOptions(width=width, height=height, camera="/World/main_cam", settings=(("threads", threads),))
    session = open_session(stage, options)
    return session, StageEditor(stage, session.camera_id, session.scene.time)


def first_pixel_after(session, editor, name, value):
    """Seconds from the edit to the first image of the render it restarts, as eyeview renders it (a first pass in
    stages, viewer.FIRST_PASS_STRIDE = 4): (to its stride-4 stage, to its stride-2 stage, to every pixel's first
    sample), each an image over the whole frame at 1/4, 1/2 and full resolution."""
    from eyerender.viewer import FIRST_PASS_STRIDE

    stages = {}
    start = time.perf_counter()

    def on_pass(p):
        stages[p.stride] = time.perf_counter() - start
        return False

    editor.apply(name, value)
    session.render(spp=1 << 20, on_pass=on_pass, first_pass_stride=FIRST_PASS_STRIDE)
    return stages[4], stages[2], stages[1]


def iris_error(scene_dir):
    """A function of an image (h, w, 3) giving its relative RMSE over compare.py's iris pixels."""
    from bench_iris import compared_pixels
    ref, sel = compared_pixels(scene_dir)
    return lambda image: float(np.sqrt(np.mean(((image[..., :3].mean(-1)[sel] - ref[sel]) / ref[sel]) ** 2)))


def converge_after_light_move(scene_dir, threads):
    """[(seconds since the move, samples, iris relative RMSE)] at the first pass past each checkpoint."""
    session, editor = open_view(scene_dir, 256, 256, threads)
    home = editor.controls["keyAzimuth"].value
    editor.apply("keyAzimuth", home + 30)
    session.render(spp=1 << 20, time_limit=1.0)
    error, rows, images = iris_error(scene_dir), [], []
    start = time.perf_counter()
    editor.apply("keyAzimuth", home)

    def on_pass(p):
        since = time.perf_counter() - start
        if len(images) < len(CHECKPOINTS) and since >= CHECKPOINTS[len(images)]:
            images.append((since, p.samples_done, session.image("color").copy()))
        return len(images) < len(CHECKPOINTS)

    session.render(spp=1 << 20, on_pass=on_pass, pass_seconds=0.05)
    for since, samples, image in images:
        rows.append((since, samples, error(image)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene-dir", default=DEFAULT_SCENE_DIR)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    if not os.path.isfile(os.path.join(args.scene_dir, "sceneB.usda")):
        sys.exit(f"bench_interactive: no sceneB.usda in {args.scene_dir} (--scene-dir)")

    session, editor = open_view(args.scene_dir, 256, 256, args.threads)
    session.render(spp=4)  # the first render builds what later ones reuse (the chamber cache, the BVH)
    home, pupil = editor.controls["keyAzimuth"].value, editor.controls["pupil"].value
    light, eye = [], []
    for i in range(args.repeats):
        light.append(first_pixel_after(session, editor, "keyAzimuth", home + 5 * (i % 2 + 1)))
        eye.append(first_pixel_after(session, editor, "pupil", pupil + 0.2 * (i % 2 + 1)))
    big, big_editor = open_view(args.scene_dir, 1920, 1080, args.threads)
    big.render(spp=1)
    big_light = [first_pixel_after(big, big_editor, "keyAzimuth", home + 5 * (i % 2 + 1)) for i in range(3)]
    print(f"| seconds after an edit (scene B, {args.threads} threads), median (worst) | to a 1/4-resolution image "
          "| 1/2 resolution | every pixel sampled |")
    print("|---|---|---|---|")
    for label, values in (("a light move, 256 x 256", light), ("a pupil edit, 256 x 256", eye),
                          ("a light move, 1920 x 1080", big_light)):
        cells = [f"{statistics.median(v):.3f} ({max(v):.3f})" for v in zip(*values)]
        print(f"| {label} | {' | '.join(cells)} |")
    print()
    print("| seconds after the light move | samples per pixel | iris relative RMSE |")
    print("|---|---|---|")
    for since, samples, err in converge_after_light_move(args.scene_dir, args.threads):
        print(f"| {since:.2f} | {samples} | {100 * err:.2f} % |")


if __name__ == "__main__":
    main()
