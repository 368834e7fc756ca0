#!/usr/bin/env bash
# Runs the benchmark programs and redraws their plots in docs/. Usage: run_benchmarks.sh BUILD_DIR
set -euo pipefail
build=${1:-build}
python3 -c "import matplotlib" 2>/dev/null || pip install -q matplotlib
"$build/bench/bench_intersect" --csv "$build/intersection_benchmark.csv"
python3 bench/plot_intersect.py "$build/intersection_benchmark.csv"
"$build/bench/bench_mnee" --csv "$build/mnee_benchmark"
python3 bench/plot_mnee.py "$build/mnee_benchmark"
"$build/bench/bench_delegate" --csv "$build/delegate_benchmark"
"$build/bench/bench_deformed_eye"  # tables for docs/deformed_eyes.md
"$build/bench/bench_motion_blur"  # the table in docs/delegate.md (motion blur)
"${PYTHON:-python3}" bench/bench_farm.py
"${PYTHON:-python3}" bench/bench_skinning.py  # table in docs/usd_support.md
"${PYTHON:-python3}" bench/bench_motion.py  # table in docs/motion_blur.md
"${PYTHON:-python3}" bench/bench_eye_crowd.py  # sweep chamber-cache in docs/render_plan.md
# Scene B lives outside the repository (an independent reference): measured where it is present.
if [[ -f "${EYERENDER_SCENE_B:-/work/shared/bench/sceneB}/sceneB.usda" ]]; then
  "${PYTHON:-python3}" bench/bench_iris.py
fi
"${PYTHON:-python3}" bench/bench_textures.py  # the table in docs/textures.md
