# lampnav: the README's two commands, plus a few conveniences.
#   make demo   install what is missing, build (Release, Ninja, ccache), run the main job
#   make test   install what is missing, build, run every test
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
LAMPNAV := $(BUILD_DIR)/apps/lampnav
OUT ?= lampnav-out

.PHONY: all deps configure build demo test test-quick bench sweep format clean interop-deps test-sanitized fuzz

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

# The unit tests alone (ctest label quick, under a minute); `ctest -L mission`, `-L interop` and
# `-L long` run the others (tests/CMakeLists.txt says which is which).
test-quick: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L '^quick$$'

# The whole suite under AddressSanitizer and UndefinedBehaviorSanitizer (GCC; any report fails the
# test). GCC's warnings change under the sanitizers (false uninitialized warnings in Boost.Graph),
# so they are not errors in this build. Debug information is line tables only (-g1: every report
# still names file and line), and the test programs' and lampnav's own sources are built at -O1
# (the libraries at -O2): on 2 cores this build took 29 min with -g and -O2 throughout. The tests
# labelled long (whole drives of more than 40 s each there, whose code shorter tests run there too;
# tests/CMakeLists.txt) are left out, 64 of 537: the 473 left took 1,917 CPU-s there (12-08).
SAN_DIR ?= build-asan
SAN_FLAGS = -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
test-sanitized: interop-deps
	@cmake -S . -B $(SAN_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLAMPNAV_BUILD_BENCH=OFF \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DLAMPNAV_GLUE_OPTIONS=-O1 \
	  -DLAMPNAV_WERROR=OFF -DCMAKE_CXX_FLAGS="$(SAN_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
	@cmake --build $(SAN_DIR) -j $(JOBS)
	@cd $(SAN_DIR) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ctest --output-on-failure -j $(JOBS) -LE '^long$$'

# libFuzzer (clang) on each outside input, FUZZ_SECONDS each (tests/fuzz/, docs/reliability.md).
# Each starts from its checked-in seeds; what it finds new goes to build-fuzz/corpus/, faults to
# build-fuzz/crashes/ (add each as a regression: tests/fuzz/regressions/<harness>/). With
# FUZZ_RUNS (CI), each runs that many inputs from the seeds alone with FUZZ_SEED: the same run
# every time, so CI fails only for a change that breaks a contract, never by the luck of the draw.
FUZZ_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_RUNS ?=
FUZZ_SEED ?= 1
FUZZERS = map_geojson robot_json mcap mission_log route_commands image ros2_cdr calibration
FUZZ_FLAGS = -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g
FUZZ_BUDGET = $(if $(FUZZ_RUNS),-runs=$(FUZZ_RUNS) -seed=$(FUZZ_SEED),-max_total_time=$(FUZZ_SECONDS))
FUZZ_CORPUS = $(if $(FUZZ_RUNS),$(FUZZ_DIR)/ci-corpus,$(FUZZ_DIR)/corpus)
fuzz: deps
	@cmake -S . -B $(FUZZ_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_CXX_COMPILER=clang++ -DLAMPNAV_FUZZ=ON -DLAMPNAV_BUILD_TESTS=OFF \
	  -DLAMPNAV_BUILD_BENCH=OFF -DLAMPNAV_WERROR=OFF -DCMAKE_CXX_FLAGS="$(FUZZ_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
	@cmake --build $(FUZZ_DIR) -j $(JOBS) --target fuzzers
	@mkdir -p $(FUZZ_DIR)/crashes
	@$(if $(FUZZ_RUNS),rm -rf $(FUZZ_CORPUS);) set -e; for f in $(FUZZERS); do \
	  mkdir -p $(FUZZ_CORPUS)/$$f; \
	  echo "fuzz $$f: $(FUZZ_BUDGET)"; \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	  $(FUZZ_DIR)/tests/fuzz/fuzz_$$f $(FUZZ_CORPUS)/$$f tests/fuzz/corpus/$$f $(FUZZ_BUDGET) \
	    -timeout=10 -rss_limit_mb=4096 -max_len=1048576 \
	    -artifact_prefix=$(FUZZ_DIR)/crashes/$$f- -print_final_stats=1 2>&1 | \
	    grep -E "^(stat::number_of_executed_units|stat::average_exec_per_sec|SUMMARY)|ERROR: libFuzzer|contract broken|^#[0-9]+ +DONE" || true; \
	  if ls $(FUZZ_DIR)/crashes/$$f-* >/dev/null 2>&1; then echo "fuzz $$f: FOUND A FAULT"; exit 1; fi; \
	done

bench: build
	@cmake --build $(BUILD_DIR) --target benchmarks

# The localization sweep (docs/hypotheses.md, "The thirteenth sweep"): 64 carried drives on
# buildings the localizer was not tuned on, replayed without their start; about 10 minutes.
sweep: build
	@python3 scripts/localization_sweep.py --build $(BUILD_DIR) --out $(BUILD_DIR)/sweep

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	@rm -rf $(BUILD_DIR)
