# lampnav: the README's two commands, plus a few conveniences.
#   make demo   install what is missing, build (Release, Ninja, ccache), run the main job
#   make test   install what is missing, build, run every test
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
LAMPNAV := $(BUILD_DIR)/apps/lampnav
OUT ?= lampnav-out

.PHONY: all deps configure build demo test bench format clean interop-deps

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: the office mission in simulation, driven by route commands, kidnapped halfway,
# relocalized by the omni camera, arriving; its log, replay outputs and report in $(OUT)/.
demo: build
	$(LAMPNAV) run --out $(OUT)
	@echo "open $(OUT)/report.html" >&2

# The official TypeScript MCAP reader and writer, Foxglove's schemas, and Foxglove's ROS 2 CDR
# serializer with ROS 2's message definitions, for the interoperability tests (npm registry,
# pinned by the lock file).
INTEROP_PACKAGES = @mcap/core @foxglove/schemas @foxglove/rosmsg2-serialization @foxglove/rosmsg-msgs-common
interop-deps: deps
	@cd tests/interop && { ( for p in $(INTEROP_PACKAGES); do [ -d node_modules/$$p ] || exit 1; done ) || npm ci --no-audit --no-fund --loglevel=error; }

test: build interop-deps
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	@cmake --build $(BUILD_DIR) --target benchmarks

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	@rm -rf $(BUILD_DIR)
