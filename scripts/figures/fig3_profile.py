#!/usr/bin/env python3
"""Figures 2-3 of Chiang and Burley 2018: the anterior-surface profile z = f(r) of the ellipsoid-cone model (with the
cone offset that makes it continuous) and of the paraboloid 14.5 z + r^2 = 0, with the paper's numbers marked, and
the paraboloid's sag difference.

The profile is computed here from the paper's formulas (eye_profile.py), not from eyelib; eyelib is checked against it
through the numbers its Catch2 tests print (build/tests/eyelib_tests, if that build exists; it is not built here).

Writes docs/figures/fig3_profile.png, docs/figures/fig3_sag_difference.png and the fragment docs/figures/fig3.md.
Run: python3 scripts/figures/fig3_profile.py
"""
import pathlib
import re
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
import eye_profile as ep  # noqa: E402

OUT = REPO / "docs" / "figures"
EYELIB_TESTS = REPO / "build" / "tests" / "eyelib_tests"
COMMAND = "python3 scripts/figures/fig3_profile.py"


def cxx_numbers():
    """Numbers printed by eyelib's paper tests: {'f_rim': ..., 'junction_f': ..., 'slope_in', 'slope_out',
    'sag': [(r, f_ec, f_par)]}, or None (with the reason) when the test binary is not there or fails."""
    if not EYELIB_TESTS.is_file():
        return None, f"{EYELIB_TESTS.relative_to(REPO)} not built"
    out = {}
    # Catch2 test-spec: a trailing * matches the rest of the name (the names contain commas, which separate specs).
    specs = {"rim": "the 15.08 mm chord sits 3.735 mm below the apex*",
             "junction": "the ellipsoid-cone junction at the 10.02 mm chord*",
             "table": "the paraboloid 14.5 z + r^2 = 0 against the ellipsoid-cone*"}
    text = {}
    for key, spec in specs.items():
        try:
            proc = subprocess.run([str(EYELIB_TESTS), spec, "-s"], capture_output=True, text=True, timeout=60)
        except (OSError, subprocess.TimeoutExpired) as e:
            return None, f"eyelib_tests failed to run: {e}"
        if proc.returncode != 0:
            return None, f"eyelib_tests '{spec}' exited with {proc.returncode}"
        text[key] = proc.stdout
    m = re.search(r"f\(7\.54\) = (-?[\d.]+) mm", text["rim"])
    if m:
        out["f_rim"] = float(m.group(1))
    m = re.search(r"junction: f = (-?[\d.]+) mm, slope ellipsoid (-?[\d.]+), cone (-?[\d.]+)", text["junction"])
    if m:
        out["junction_f"], out["slope_in"], out["slope_out"] = map(float, m.groups())
    out["sag"] = [tuple(map(float, row)) for row in
                  re.findall(r"^\s*([\d.]+) \|\s+(-?[\d.]+) \|\s+(-?[\d.]+) \|", text["table"], re.M)]
    built = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(EYELIB_TESTS.stat().st_mtime))
    return out, f"{EYELIB_TESTS.relative_to(REPO)} (built {built})"


def plot_profile(path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # Half profile r >= 0 (the surface is rotationally symmetric), equal axes so the 38 degrees look like 38.
    r = np.linspace(0, ep.RIM_R, 755)
    fig, ax = plt.subplots(figsize=(4.0, 2.9), dpi=100)
    ax.plot(r, ep.ellipsoid_cone_sag(r), color="k", lw=1.4, label="ellipsoid-cone")
    ax.plot(r, ep.paraboloid_sag(r), color="tab:orange", lw=1.0, ls="--", label="paraboloid 14.5z + r² = 0")
    re_ = np.linspace(ep.JUNCTION_R, ep.RIM_R, 100)
    ax.plot(re_, ep.ellipsoid_sag(re_), color="tab:blue", lw=0.8, ls=":", label="ellipsoid continued")
    ax.axhline(-ep.ANATOMICAL_IRIS_DEPTH, color="tab:green", lw=0.8)
    ax.text(0.1, -ep.ANATOMICAL_IRIS_DEPTH + 0.08, "iris plane, 3.735 mm deep", color="tab:green", fontsize=6)
    zj = float(ep.ellipsoid_cone_sag(ep.JUNCTION_R))
    ax.plot([ep.JUNCTION_R], [zj], "ks", ms=3)
    ax.annotate("junction, 10.02 mm chord", (ep.JUNCTION_R, zj), fontsize=6, xytext=(1.0, -2.3),
                arrowprops={"arrowstyle": "-", "lw": 0.5})
    for chord, colour, dy in ((ep.LIMBUS_INNER_CHORD, "tab:red", 0.0), (ep.LIMBUS_OUTER_CHORD, "tab:purple", 0.0)):
        x = chord / 2
        z = float(ep.ellipsoid_cone_sag(x))
        ax.plot([x], [z], "o", color=colour, ms=3)
        ax.text(x - 0.15, z - 0.05 + dy, f"limbus {chord} mm", color=colour, fontsize=6, ha="right", va="top")
    ax.plot([ep.RIM_R], [float(ep.ellipsoid_cone_sag(ep.RIM_R))], "k^", ms=3)
    ax.text(ep.RIM_R, -ep.ANATOMICAL_IRIS_DEPTH - 0.2, "15.08 mm chord", fontsize=6, ha="right", va="top")
    zr = float(ep.ellipsoid_cone_sag(ep.RIM_R))
    ax.plot([ep.RIM_R - 1.2, ep.RIM_R], [zr, zr], color="0.4", lw=0.5)
    ax.text(ep.RIM_R - 1.15, zr + 0.12, "38°", fontsize=6.5)
    ax.set_aspect("equal")
    ax.set_xlim(-0.2, 8.0)
    ax.set_ylim(-4.9, 0.3)
    ax.set_xlabel("r (mm)", fontsize=7)
    ax.set_ylabel("z (mm)", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.legend(fontsize=5.5, loc="lower left", frameon=False)
    fig.tight_layout(pad=0.3)
    fig.savefig(path)
    plt.close(fig)


def plot_difference(path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = np.linspace(0, ep.RIM_R, 755)
    diff_um = (ep.paraboloid_sag(r) - ep.ellipsoid_cone_sag(r)) * 1000
    fig, ax = plt.subplots(figsize=(4.0, 2.0), dpi=100)
    ax.plot(r, diff_um, color="tab:orange", lw=1.2)
    ax.axhline(0, color="k", lw=0.5)
    for x, label in ((ep.JUNCTION_R, "10.02"), (ep.LIMBUS_INNER_CHORD / 2, "11.64"),
                     (ep.LIMBUS_OUTER_CHORD / 2, "12.89")):
        ax.axvline(x, color="0.6", lw=0.6, ls=":")
        ax.text(x, diff_um.min() * 0.95, label, fontsize=5.5, ha="center")
    ax.set_xlabel("r (mm)", fontsize=7)
    ax.set_ylabel("paraboloid − ellipsoid-cone (µm)", fontsize=6.5)
    ax.tick_params(labelsize=6)
    fig.tight_layout(pad=0.3)
    fig.savefig(path)
    plt.close(fig)


def main():
    print(f"$ {COMMAND}")
    start = time.perf_counter()
    OUT.mkdir(parents=True, exist_ok=True)
    plot_profile(OUT / "fig3_profile.png")
    plot_difference(OUT / "fig3_sag_difference.png")

    kink, slope_in = ep.junction_kink_deg()
    f_junction = float(ep.ellipsoid_sag(ep.JUNCTION_R))
    f_rim = float(ep.ellipsoid_cone_sag(ep.RIM_R))
    f_rim_no_offset = -ep.RIM_R * ep.TAN_CONE  # the paper's printed z - r tan 38 = 0, taken literally
    par_rim = float(ep.paraboloid_sag(ep.RIM_R))
    r = np.linspace(0, ep.RIM_R, 7541)
    diff = ep.paraboloid_sag(r) - ep.ellipsoid_cone_sag(r)
    i_max, i_min = int(np.argmax(diff)), int(np.argmin(diff))
    inner, outer = ep.LIMBUS_INNER_CHORD / 2, ep.LIMBUS_OUTER_CHORD / 2
    depth_a, depth_b = -float(ep.ellipsoid_cone_sag(inner)), -float(ep.ellipsoid_cone_sag(outer))
    par_r_at_iris = ep.inverse_sag("paraboloid", ep.ANATOMICAL_IRIS_DEPTH)
    # Where the paraboloid crosses the ellipsoid-cone (sign changes of the difference, r > 0).
    crossings = [float(r[i]) for i in range(1, len(r)) if np.sign(diff[i]) != np.sign(diff[i - 1]) and r[i] > 0.01]

    # Angle between the two surfaces' normals at the same r: refraction depends on the slope, not the sag.
    tilt = np.degrees(np.abs(np.arctan(ep.ellipsoid_cone_slope(r)) - np.arctan(ep.paraboloid_slope(r))))
    clear = r <= inner
    rows = [
        ("ellipsoid-cone junction, 10.02 mm chord: f(5.01)", f"{f_junction:.6f} mm", "continuous by construction"),
        ("ellipsoid slope / cone slope at the junction", f"{slope_in:.4f} / {-ep.TAN_CONE:.4f}",
         f"kink {kink:.2f} deg; convex"),
        ("cone angle from the xy-plane", f"{ep.CONE_ANGLE_DEG:.0f} deg", "tan 38 = %.6f" % ep.TAN_CONE),
        ("f(7.54), the 15.08 mm chord (iris depth)", f"{f_rim:.5f} mm", "paper: 3.735 mm"),
        ("same, cone without offset (z = r tan 38, as printed)", f"{f_rim_no_offset:.3f} mm", "not the paper's 3.735"),
        ("ellipsoid alone continued to r = 7.54", f"{float(ep.ellipsoid_sag(ep.RIM_R)):.3f} mm",
         "why the cone is needed"),
        ("limbus start, 11.64 mm chord: depth", f"{depth_a:.4f} mm", "figure 4 (a)"),
        ("limbus end, 12.89 mm chord: depth", f"{depth_b:.4f} mm", "figure 4 (b)"),
        ("paraboloid at r = 7.54", f"{par_rim:.4f} mm", f"{(f_rim - par_rim) * 1000:.0f} um deeper than the model"),
        ("paraboloid meets the 3.735 mm iris plane at", f"r = {par_r_at_iris:.4f} mm",
         f"chord {2 * par_r_at_iris:.3f} mm (vs 15.08)"),
        ("paraboloid - ellipsoid-cone, max", f"{diff[i_max] * 1000:+.1f} um at r = {r[i_max]:.2f} mm", "shallower"),
        ("paraboloid - ellipsoid-cone, min (r <= 7.54)", f"{diff[i_min] * 1000:+.1f} um at r = {r[i_min]:.2f} mm",
         "deeper"),
        ("... inside the limbus (r <= 5.82)",
         f"{np.abs(diff[r <= inner]).max() * 1000:.1f} um (largest absolute difference)", "the optically clear cornea"),
        ("curves cross at r", ", ".join(f"{c:.3f}" for c in crossings) + " mm", ""),
        ("normal direction difference, max for r <= 5.82",
         f"{tilt[clear].max():.2f} deg at r = {r[clear][np.argmax(tilt[clear])]:.2f} mm",
         "what refraction sees; apex radii 7.8 vs 7.25 mm"),
        ("normal direction difference, max for r <= 7.54",
         f"{tilt.max():.2f} deg at r = {r[np.argmax(tilt)]:.2f} mm", ""),
    ]
    for name, value, note in rows:
        print(f"  {name:55s} {value:32s} {note}")

    cxx, source = cxx_numbers()
    check_lines = []
    worst = 0.0
    if cxx:
        pairs = []
        if "f_rim" in cxx:
            pairs.append(("f(7.54)", cxx["f_rim"], f_rim, 5e-6))  # printed with 5 decimals
        if "junction_f" in cxx:
            pairs += [("f(5.01)", cxx["junction_f"], f_junction, 5e-9),
                      ("slope in", cxx["slope_in"], slope_in, 5e-5),
                      ("slope out", cxx["slope_out"], -ep.TAN_CONE, 5e-5)]
        for rr, fe, fpar in cxx["sag"]:
            pairs += [(f"ellipsoid-cone f({rr:.2f})", fe, float(ep.ellipsoid_cone_sag(rr)), 5e-6),
                      (f"paraboloid f({rr:.2f})", fpar, float(ep.paraboloid_sag(rr)), 5e-6)]
        for name, c, p, rounding in pairs:
            err = abs(c - p)
            worst = max(worst, err - rounding)
            ok = err <= rounding * 1.01
            check_lines.append(f"| {name} | {c:.6f} | {p:.6f} | {err * 1e6:.2f} | {'ok' if ok else 'MISMATCH'} |")
        mismatches = sum("MISMATCH" in line for line in check_lines)
        print(f"  C++ cross-check against {source}: {len(pairs)} values, {mismatches} mismatches")
        if mismatches:
            print("  MISMATCH between the Python profile and eyelib:",
                  *[line for line in check_lines if "MISMATCH" in line], sep="\n    ")
    else:
        print(f"  C++ cross-check skipped: {source}")
    seconds = time.perf_counter() - start

    md = [
        "<!-- generated by scripts/figures/fig3_profile.py; do not edit by hand -->",
        "![profile](figures/fig3_profile.png) ![sag difference](figures/fig3_sag_difference.png)",
        "",
        "Left: the profile (equal axes, mm): ellipsoid-cone (black; square: the 10.02 mm junction; triangle: the 15.08 "
        "mm rim; dots: the limbus at 11.64 and 12.89 mm), the paraboloid (dashed), the ellipsoid continued past the "
        "junction (dotted), the iris plane at 3.735 mm. Right: the paraboloid's sag minus the ellipsoid-cone's (um; "
        "positive = the paraboloid is shallower); dotted: the 10.02 mm junction and the 11.64 / 12.89 mm limbus "
        "chords.",
        "",
        "| quantity | value | note |",
        "|---|---|---|",
        *[f"| {n} | {v} | {note} |" for n, v, note in rows],
        "",
    ]
    if cxx:
        mismatches = sum("MISMATCH" in line for line in check_lines)
        md += [f"Cross-check against eyelib (C++), the values printed by `{source}` "
               f"(`eyelib_tests \"the paraboloid 14.5 z + r^2 = 0 against the ellipsoid-cone*\" -s` and two more paper "
               f"tests): {len(check_lines)} values, {mismatches} mismatches beyond the printed rounding.",
               "",
               "<details><summary>values (mm; error in um)</summary>",
               "",
               "| value | eyelib | Python | abs error (um) | |",
               "|---|---|---|---|---|",
               *check_lines,
               "",
               "</details>",
               ""]
    else:
        md += [f"Cross-check against eyelib skipped: {source}. There is no Python binding of the anterior surface, "
               "so the check reads the numbers eyelib's tests print.", ""]
    md += [f"Regenerate: `{COMMAND}` ({seconds:.1f} s, no rendering)."]
    (OUT / "fig3.md").write_text("\n".join(md) + "\n")
    print(f"  wrote {OUT.relative_to(REPO)}/fig3_profile.png, fig3_sag_difference.png, fig3.md in {seconds:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
