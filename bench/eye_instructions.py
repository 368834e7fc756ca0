#!/usr/bin/env python3
"""Instructions per camera sample of the side-lit eye (docs/delegate_benchmark.md), counted by callgrind.

The scene is hdeye_render_scene's default (sampleScenes::AddSideLitEye: an analytic eye, a 3 mm sphere key 75 degrees
off its gaze and a dim constant dome; the eye scene of bench_delegate), rendered on one thread at SPP_LOW and SPP_HIGH
samples per pixel. The difference of the two totals over the difference in samples is the cost of one sample: the
set-up (scene sync, BVH, the chamber cache's build) cancels. Instruction counts do not depend on the machine's load,
so a before/after needs no idle machine; each binary is run in turn.

    python3 bench/eye_instructions.py [--binary LABEL=PATH ...] [--size 96] [--spp-low 4] [--spp-high 12]

Without --binary: build/delegate/hdeye_render_scene, as "this build". Needs valgrind.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BINARY = os.path.join(HERE, "..", "build", "delegate", "hdeye_render_scene")


def instructions(binary, size, spp, workdir):
    """Total instructions callgrind counts for one render."""
    out = os.path.join(workdir, "callgrind.out")
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", binary, os.path.join(workdir, "render"),
           "--spp", str(spp), "--size", f"{size}x{size}", "--threads", "1"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    found = re.search(r"Collected\s*:\s*(\d+)", run.stderr)
    if run.returncode != 0 or not found:
        sys.exit(f"eye_instructions: {binary} failed under callgrind: {run.stderr.strip().splitlines()[-1:]}")
    return int(found.group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", action="append", metavar="LABEL=PATH",
                        help="an hdeye_render_scene to measure (repeatable)")
    parser.add_argument("--size", type=int, default=96, help="image width and height, pixels")
    parser.add_argument("--spp-low", type=int, default=4)
    parser.add_argument("--spp-high", type=int, default=12)
    args = parser.parse_args()
    if shutil.which("valgrind") is None:
        sys.exit("eye_instructions: valgrind is not installed (apt-get install valgrind)")
    if not 0 < args.spp_low < args.spp_high or args.size < 1:
        sys.exit("eye_instructions: need 0 < --spp-low < --spp-high and a positive --size")
    binaries = []
    for item in args.binary or [f"this build={DEFAULT_BINARY}"]:
        label, sep, path = item.partition("=")
        if not sep or not os.access(path, os.X_OK):
            sys.exit(f"eye_instructions: --binary wants LABEL=PATH to an executable, got {item!r}")
        binaries.append((label, path))
    samples = args.size * args.size * (args.spp_high - args.spp_low)
    rows = []
    with tempfile.TemporaryDirectory(prefix="eye_instructions_") as workdir:
        for label, path in binaries:
            print(f"  {label}: {args.spp_low} and {args.spp_high} spp under callgrind ...", file=sys.stderr, flush=True)
            low = instructions(path, args.size, args.spp_low, workdir)
            high = instructions(path, args.size, args.spp_high, workdir)
            rows.append((label, (high - low) / samples, low))
    first = rows[0][1]
    print(f"\nside-lit eye, {args.size} x {args.size}, 1 thread: instructions per camera sample "
          f"(from {args.spp_low} and {args.spp_high} spp)\n")
    print("| build | instructions per sample | of the first | render at the lower spp |")
    print("|---|---|---|---|")
    for label, per, low in rows:
        print(f"| {label} | {per:,.0f} | {per / first:.3f} | {low / 1e9:.2f} G |")


if __name__ == "__main__":
    main()
