#!/usr/bin/env python3
"""Regenerates every paper figure and docs/paper_figures.md in one go: runs each figure script (each prints its own
command and writes its images and a markdown fragment to docs/figures/), then assembles the page from
docs/figures/page_template.md with the fragments inlined. With --update-baselines it also rewrites the figure 4 and
figure 5 regression baselines (tests/baselines/figure4_*, figure5_*) and runs that test.

Run: python3 scripts/figures/make_all.py [--update-baselines] [--quick] [--page-only]
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
DOCS = REPO / "docs"
TEMPLATE = DOCS / "figures" / "page_template.md"
PAGE = DOCS / "paper_figures.md"
SCRIPTS = ["fig3_profile.py", "fig4_iris_depth.py", "fig5_limbal_arc.py", "fig_deformed.py"]


def run(cmd, env=None):
    if cmd[0] != sys.executable or cmd[1] == "-m":  # the figure scripts print their own command
        print("$ " + " ".join(["python3"] + cmd[1:] if cmd[0] == sys.executable else cmd), flush=True)
    start = time.perf_counter()
    subprocess.run(cmd, cwd=REPO, check=True, env=env)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--update-baselines", action="store_true",
                        help="also rewrite tests/baselines/figure4_*, figure5_* and run "
                        "tests/python/test_paper_figures.py")
    parser.add_argument("--quick", action="store_true", help="pass --quick to the render scripts (smoke run)")
    parser.add_argument("--page-only", action="store_true",
                        help="only re-assemble docs/paper_figures.md from the existing fragments")
    args = parser.parse_args()
    print("$ python3 scripts/figures/make_all.py" + (" --update-baselines" if args.update_baselines else "")
          + (" --quick" if args.quick else "") + (" --page-only" if args.page_only else ""))
    timings = {}
    for script in [] if args.page_only else SCRIPTS:
        cmd = [sys.executable, str(pathlib.Path("scripts/figures") / script)]
        if args.quick and script != "fig3_profile.py":
            cmd.append("--quick")
        timings[script] = run(cmd)

    # Script run times are kept beside the fragments so that --page-only can still show them.
    timing_file = DOCS / "figures" / "timings.json"
    if timings:
        timing_file.write_text(json.dumps({k: round(v, 1) for k, v in timings.items()}, indent=2) + "\n")
    elif timing_file.is_file():
        timings = json.loads(timing_file.read_text())
    page = TEMPLATE.read_text()
    for name in ("fig3", "fig4", "fig5", "fig_deformed"):
        fragment = (DOCS / "figures" / f"{name}.md").read_text()
        page = page.replace(f"{{{{{name}}}}}", fragment.strip())
    page = page.replace("{{generated}}", time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    page = page.replace("{{timings}}", ", ".join(f"`{s}` {t:.0f} s" for s, t in timings.items())
                        or "run times unknown")
    PAGE.write_text(page)
    print(f"wrote {PAGE.relative_to(REPO)}")

    if args.update_baselines:
        env = dict(os.environ, EYERENDER_UPDATE_BASELINES="1")
        run([sys.executable, "-m", "pytest", "-q", "-s", "tests/python/test_paper_figures.py"], env=env)
        run([sys.executable, "-m", "pytest", "-q", "-s", "tests/python/test_paper_figures.py"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
