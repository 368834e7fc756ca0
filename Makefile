# Single entry point. `make test` and `make render` are the two README commands: each installs what
# a fresh Debian 12 machine (root) is missing, configures, builds and runs.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: deps configure build python lint test render bench clean

deps:
	@bash scripts/install_deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja $(CMAKE_FLAGS)

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The Python interpreter the package goes into: the project venv on a Debian python, else python3 (evaluated
# when a recipe runs, after deps may have created the venv).
PYTHON = $(shell [ -x .venv/bin/python ] && echo .venv/bin/python || echo python3)

# The eyerender package (pip install ., build tree kept in build/pip so reinstalling is incremental).
python: deps
	@$(PYTHON) -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --no-build-isolation .

# ruff over the repository's Python (rules in pyproject.toml [tool.ruff]) and clang-format over its C++
# (.clang-format; scripts/check_format.sh --fix applies it).
LINT = $(PYTHON) -m ruff check --quiet . && bash scripts/check_format.sh

lint: deps
	@$(LINT)

# The lint, Catch2 (CTest), then pytest (schema, scene delegate, eyerecord, samples). Each runs even if another fails;
# the target fails if any does.
test: build python
	@rc=0; \
	$(LINT) || { echo "make test: lint failed (make lint)"; rc=1; }; \
	(cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)) || rc=1; \
	$(PYTHON) -m pytest -q tests/python || rc=1; \
	exit $$rc

# The default sample: the procedural eye close-up, to out/closeup.exr (AOVs) and out/closeup.png.
render: python
	@mkdir -p out
	@$(PYTHON) -m eyerender.cli.eyerecord usd_samples/closeup.usda out/closeup.exr --png -w 256 --spp 64 --aov irisMnee --aov albedo --aov normal --aov depth

bench: build
	@bash scripts/run_benchmarks.sh $(BUILD_DIR)

clean:
	@rm -rf $(BUILD_DIR)
