# Single entry point. `make test` and `make render` are the two README commands: each installs what
# a fresh Debian 12 machine (root) is missing, configures, builds and runs.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: deps configure build test render bench clean

deps:
	@bash scripts/install_deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja $(CMAKE_FLAGS)

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# Catch2 (CTest), then pytest (the USD schema for now). Each runs even if the other fails; the target fails if either does.
test: build
	@rc=0; \
	(cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)) || rc=1; \
	py=python3; [ -x .venv/bin/python ] && py=.venv/bin/python; \
	$$py -m pytest -q tests/python || rc=1; \
	exit $$rc

# Until the USD front end (eyerecord) lands, the default render is the delegate's C++ example: an
# analytic eye under a side light, written to out/eye.exr (all AOVs) and out/eye.png.
render: build
	@mkdir -p out
	@$(BUILD_DIR)/delegate/hdeye_render_scene out/eye --spp 32 --size 256x256 --light-angle 75 --exposure 2

bench: build
	@bash scripts/run_benchmarks.sh $(BUILD_DIR)

clean:
	@rm -rf $(BUILD_DIR)
