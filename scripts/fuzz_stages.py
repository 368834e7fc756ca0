"""Fuzzes eyerecord's front end: mutates small stages it authors itself and renders each mutant in a subprocess.

    python scripts/fuzz_stages.py [--seed S] [--count N] [--keep DIR] [--timeout SECONDS] [--python PYTHON]

Each mutant is one edit of a seed stage's .usda text: a number set to NaN/Inf/0/1e30/1e20/huge/negative, an
attribute's type name swapped for another, a quoted token garbled or emptied, a line removed or repeated, the file
truncated, or random bytes (non-UTF-8 among them) inserted. eyerecord renders it at 16 pixels and 1 sample with
--png; a run is a problem when it dies by a signal or times out, prints a traceback, prints a line of 200 characters
or more, exits 0 without writing its outputs, or leaves a temporary file. Prints the counts by outcome and the
problems; exits 1 if there was any. The same seed gives the same mutants.
"""
import argparse
import collections
import os
import random
import re
import subprocess
import sys
import tempfile

MAX_LINE = 200
NUMBER = re.compile(r"(?<![\w.#@])-?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w#])")
TYPED_ATTRIBUTE = re.compile(r"^(\s*(?:uniform |custom )*)([A-Za-z][\w\[\]]*)(\s+[\w:]+\s*=)", re.M)
QUOTED = re.compile(r'"([^"\n]*)"')
BAD_NUMBERS = ("nan", "inf", "-inf", "0", "-0", "1e30", "-1e30", "1e20", "1e-30", "-1", "-1000",
               "99999999999999999999", "1e308")
TYPE_NAMES = ("int", "float", "double", "bool", "string", "token", "asset", "float3", "double3", "color3f",
              "matrix4d", "float[]", "int[]", "point3f[]", "quatf", "half", "rel")


def _camera(stage, UsdGeom, Gf):
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 1000))
    cam.AddTransformOp().Set(Gf.Matrix4d(1).SetTranslate(Gf.Vec3d(0, 0, 40)))


def seed_stages():
    """{name: .usda text} of the stages the mutants start from: an eye shot and a props scene."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade

    stages = {}
    eye_shot = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(eye_shot, 0.001)
    _camera(eye_shot, UsdGeom, Gf)
    eye = UsdGeom.Xform.Define(eye_shot, "/World/Eye")
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, 0))
    eye.AddRotateXYZOp().Set(Gf.Vec3f(0, 10, 0))
    prim = eye.GetPrim()
    prim.AddAppliedSchema("EyeAPI")
    for name, kind, value in (("eye:corneaIor", Sdf.ValueTypeNames.Float, 1.376),
                              ("eye:pupilDiameter", Sdf.ValueTypeNames.Float, 4.0),
                              ("eye:irisDepth", Sdf.ValueTypeNames.Float, 3.7),
                              ("eye:scleraMeanFreePath", Sdf.ValueTypeNames.Float3, Gf.Vec3f(1, 0.8, 0.6)),
                              ("eye:irisColor", Sdf.ValueTypeNames.Color3f, Gf.Vec3f(0.3, 0.2, 0.1)),
                              ("eye:corneaModel", Sdf.ValueTypeNames.Token, "ellipsoidCone"),
                              ("eye:limbalArc", Sdf.ValueTypeNames.Bool, True)):
        prim.CreateAttribute(name, kind).Set(value)
    key = UsdLux.SphereLight.Define(eye_shot, "/World/key")
    key.CreateRadiusAttr(2.0)
    key.CreateIntensityAttr(500.0)
    key.CreateColorAttr(Gf.Vec3f(1, 0.9, 0.8))
    key.AddTranslateOp().Set(Gf.Vec3d(10, 10, 30))
    key.AddScaleOp().Set(Gf.Vec3f(1, 1, 1))
    sun = UsdLux.DistantLight.Define(eye_shot, "/World/sun")
    sun.CreateAngleAttr(1.0)
    sun.CreateIntensityAttr(2.0)
    sun.AddRotateXYZOp().Set(Gf.Vec3f(-30, 20, 0))
    stages["eye_shot"] = eye_shot.GetRootLayer().ExportToString()

    props = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(props, UsdGeom.Tokens.y)
    props.SetStartTimeCode(1)
    props.SetEndTimeCode(2)
    _camera(props, UsdGeom, Gf)
    card = UsdGeom.Mesh.Define(props, "/World/card")
    card.CreatePointsAttr([(-10, -10, -5), (10, -10, -5), (10, 10, -5), (-10, 10, -5)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("catmullClark")
    card.CreateNormalsAttr([(0, 0, 1)] * 4)
    card.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    UsdGeom.PrimvarsAPI(card).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.vertex).Set([(0, 0), (1, 0), (1, 1), (0, 1)])
    card.CreateDisplayColorAttr([(0.8, 0.3, 0.2)])
    op = card.AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 0), 1)
    op.Set(Gf.Vec3d(0, 1, 0), 2)
    ball = UsdGeom.Sphere.Define(props, "/World/ball")
    ball.CreateRadiusAttr(3.0)
    ball.AddTranslateOp().Set(Gf.Vec3d(4, 0, 0))
    box = UsdGeom.Cube.Define(props, "/World/box")
    box.CreateSizeAttr(2.0)
    box.AddXformOp(UsdGeom.XformOp.TypeScale).Set(Gf.Vec3f(1, 2, 1))
    material = UsdShade.Material.Define(props, "/World/Looks/red")
    shader = UsdShade.Shader.Define(props, "/World/Looks/red/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set((0.8, 0.1, 0.1))
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.4)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(ball.GetPrim()).Bind(material)
    instancer = UsdGeom.PointInstancer.Define(props, "/World/scatter")
    tile = UsdGeom.Mesh.Define(props, "/World/scatter/protos/tile")
    tile.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    tile.CreateFaceVertexCountsAttr([3])
    tile.CreateFaceVertexIndicesAttr([0, 1, 2])
    instancer.CreatePrototypesRel().SetTargets([tile.GetPath()])
    instancer.CreatePositionsAttr([(0, 5, 0), (3, 5, 0)])
    instancer.CreateProtoIndicesAttr([0, 0])
    rect = UsdLux.RectLight.Define(props, "/World/rect")
    rect.CreateWidthAttr(5.0)
    rect.CreateHeightAttr(5.0)
    rect.CreateIntensityAttr(50.0)
    rect.AddTranslateOp().Set(Gf.Vec3d(0, 0, 30))
    stages["props"] = props.GetRootLayer().ExportToString()
    return stages


def mutate(text, rng):
    """(kind, mutant bytes) of one random edit of a stage's .usda text."""
    kind = rng.choice(("number", "number", "number", "type", "token", "drop_line", "repeat_line", "truncate",
                       "bytes"))
    if kind == "number":
        spots = list(NUMBER.finditer(text))
        m = rng.choice(spots)
        return kind, (text[:m.start()] + rng.choice(BAD_NUMBERS) + text[m.end():]).encode()
    if kind == "type":
        spots = list(TYPED_ATTRIBUTE.finditer(text))
        m = rng.choice(spots)
        return kind, (text[:m.start(2)] + rng.choice(TYPE_NAMES) + text[m.end(2):]).encode()
    if kind == "token":
        spots = list(QUOTED.finditer(text))
        m = rng.choice(spots)
        garbled = rng.choice(("", "bogus", m.group(1)[::-1], m.group(1) + "X", "xformOp:bogus", "::", "a b"))
        return kind, (text[:m.start(1)] + garbled + text[m.end(1):]).encode()
    lines = text.splitlines(keepends=True)
    if kind == "drop_line":
        del lines[rng.randrange(1, len(lines))]
        return kind, "".join(lines).encode()
    if kind == "repeat_line":
        k = rng.randrange(1, len(lines))
        lines.insert(k, lines[k])
        return kind, "".join(lines).encode()
    raw = text.encode()
    if kind == "truncate":
        return kind, raw[:rng.randrange(10, len(raw))]
    at = rng.randrange(10, len(raw))
    noise = bytes(rng.choice((0xff, 0xfe, 0x80, 0x00, 0x22, 0x7b, 0x28, rng.randrange(256))) for _ in range(3))
    return kind, raw[:at] + noise + raw[at:]


def problems_of(rc, out, err, workdir, outputs):
    """What is wrong with one run (empty: nothing)."""
    found = []
    if rc is None:
        found.append("timeout")
    elif rc < 0 or rc not in (0, 1, 2):
        found.append(f"signal/exit {rc}")
    if "Traceback" in err:
        found.append("traceback")
    long_lines = [line for line in (out + err).splitlines() if len(line) >= MAX_LINE]
    if long_lines:
        found.append(f"line of {len(long_lines[0])} chars")
    if rc == 0 and not all(os.path.exists(p) for p in outputs):
        found.append("exit 0 without its outputs")
    if any(".tmp." in name for name in os.listdir(workdir)):
        found.append("leftover temporary file")
    return found


def run_mutant(data, workdir, timeout, python=sys.executable):
    """Renders one mutant in a subprocess: (outcome, problems, first stderr line)."""
    for name in os.listdir(workdir):
        os.remove(os.path.join(workdir, name))
    stage = os.path.join(workdir, "mutant.usda")
    with open(stage, "wb") as f:
        f.write(data)
    exr, png = os.path.join(workdir, "out.exr"), os.path.join(workdir, "out.png")
    cmd = [python, "-m", "eyerender.cli.eyerecord", stage, exr, "--png", "-w", "16", "--spp", "1", "-q",
           "--threads", "1"]
    try:
        proc = subprocess.run(cmd, capture_output=True, timeout=timeout, cwd=workdir)
        rc, out, err = proc.returncode, proc.stdout.decode(errors="replace"), proc.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, out, err = None, "", ""
    outcome = {0: "rendered", 1: "one-line error", 2: "usage error"}.get(rc, "crashed")
    first = next((line for line in err.splitlines() if "error" in line), "")
    return outcome, problems_of(rc, out, err, workdir, (exr, png)), first


def fuzz(seed, count, timeout=60.0, keep=None, python=sys.executable, log=None):
    """Runs `count` mutants from `seed`; returns (Counter of outcomes, [(mutant id, kind, problems, stderr line)])."""
    rng = random.Random(seed)
    stages = seed_stages()
    names = sorted(stages)
    outcomes, problems = collections.Counter(), []
    with tempfile.TemporaryDirectory(prefix="eyerender_fuzz_") as workdir:
        for n in range(count):
            name = rng.choice(names)
            kind, data = mutate(stages[name], rng)
            outcome, found, first = run_mutant(data, workdir, timeout, python)
            outcomes[outcome] += 1
            if found:
                problems.append((f"{seed}:{n}", f"{name}/{kind}", found, first))
                if keep:
                    os.makedirs(keep, exist_ok=True)
                    with open(os.path.join(keep, f"mutant_{seed}_{n}.usda"), "wb") as f:
                        f.write(data)
            if log:
                log(f"{n + 1}/{count} {name}/{kind}: {outcome}{' PROBLEM ' + ', '.join(found) if found else ''}")
    return outcomes, problems


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--count", type=int, default=200)
    p.add_argument("--timeout", type=float, default=60.0, help="seconds per render (default 60)")
    p.add_argument("--keep", metavar="DIR", help="write every mutant with a problem here")
    p.add_argument("--python", default=sys.executable, help="the interpreter whose eyerender package is fuzzed "
                   "(e.g. another checkout's venv, to compare; default: this one)")
    p.add_argument("--verbose", "-v", action="store_true")
    args = p.parse_args(argv)
    outcomes, problems = fuzz(args.seed, args.count, args.timeout, args.keep, python=args.python,
                              log=(lambda line: print(line, flush=True)) if args.verbose else None)
    print(f"{args.count} mutants (seed {args.seed}): " + ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items())))
    for mutant, what, found, first in problems:
        print(f"  {mutant} {what}: {', '.join(found)}  {first[:120]}")
    print(f"problems: {len(problems)}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
