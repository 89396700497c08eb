# The two commands: `make demo` and `make test`. Each installs missing Debian packages,
# configures and builds in Release into build/, then runs the demo or the whole test suite.
BUILD       ?= build
JOBS        ?= $(shell nproc)
WERROR      ?= OFF
CMAKE_FLAGS ?=

.PHONY: all deps configure build python install demo test test-blender test-slurm test-sanitize test-tsan bench bench-peers fuzz format format-check clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DDISPEX_BUILD_BENCH=ON \
	  -DDISPEX_WERROR=$(WERROR) $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j$(JOBS)

# The Python module alone (build/python/dispex; PYTHONPATH=build/python, docs/PYTHON.md).
python: configure
	@cmake --build $(BUILD) -j$(JOBS) --target dispex_python

# The library, headers, CMake package, pkg-config file, Python module and the command into
# PREFIX (docs/LIBRARY.md).
PREFIX ?= /usr/local
install: build
	@cmake --install $(BUILD) --prefix $(PREFIX)

# The demo needs only the command-line tool: tests and benchmarks are built by `make test`.
demo: configure
	@cmake --build $(BUILD) -j$(JOBS) --target dispex
	@scripts/demo.sh $(BUILD)

# Every ctest run writes a JUnit report; scripts/check-skips.py then fails on any skipped test
# that tests/allowed-skips.txt does not allow (ctest itself passes a skipped test).
CHECK_SKIPS = scripts/check-skips.py

# The `browser` tests (the pages of `dispex view` in Chromium headless) run here too: Chromium
# is installed first (DISPEX_WITH_BROWSER=1).
test: build
	@DISPEX_WITH_BROWSER=1 scripts/install-deps.sh
	@cd $(BUILD) && ctest --output-on-failure -j$(JOBS) --timeout 900 -LE 'blender|slurm' \
	  --output-junit ctest-junit.xml
	@$(CHECK_SKIPS) $(BUILD)/ctest-junit.xml

# Blender 3.4 headless displacing with dispex's UV-space maps (tests/blender), Blender
# installed first (DISPEX_WITH_BLENDER=1). About 40 s.
test-blender: build
	@DISPEX_WITH_BLENDER=1 scripts/install-deps.sh
	@cd $(BUILD) && ctest --output-on-failure -L blender --timeout 900 --output-junit ctest-junit-blender.xml
	@$(CHECK_SKIPS) $(BUILD)/ctest-junit-blender.xml

# The farm on a real Slurm (tests/farm): starts munged, slurmctld and slurmd on localhost for
# the test's length; needs root (skips otherwise) and Debian's slurm-wlm and munge.
test-slurm: build
	@DISPEX_WITH_SLURM=1 scripts/install-deps.sh
	@cd $(BUILD) && ctest --output-on-failure -L slurm --output-junit ctest-junit-slurm.xml
	@$(CHECK_SKIPS) $(BUILD)/ctest-junit-slurm.xml

# The production-scale benchmark (bench/run): assets generated on first use in
# $$DISPEX_BENCH_CACHE (default ~/.cache/dispex/bench), table on stdout, JSON in out/bench/.
bench: build
	@DISPEX_BUILD=$(BUILD) bench/run $(BENCH_ARGS)

# Blender's Cycles bake beside dispex on the cape asset (bench/peers/run; installs Debian's
# blender when it is missing). Table on stdout, JSON in out/bench/peers/.
bench-peers: build
	@DISPEX_BUILD=$(BUILD) bench/peers/run $(BENCH_ARGS)

# The sanitized builds' optimisation and debug information: line tables only (-g1), which is
# what the sanitizers' stack traces print (function, file and line); full -g made compiling
# under AddressSanitizer 1.8x slower (src/verify/verify.cpp: 105 s against 60 s). The ASan +
# UBSan suite is built at -Og: it compiles the whole tree and its tests, and -Og compiles a
# file about 40% faster than -O1 under the sanitizers (tests/extract/extract_e2e_test.cpp
# 17.9 -> 10.1 s, src/verify/verify.cpp 16.8 -> 10.5 s; the whole tree in 471 s on 2 cores),
# which pays many times for its tests running a little slower (288 -> 326 s); the
# ThreadSanitizer build (the tool alone, then a few small extractions) is at -O1, the lowest
# level TSan's documentation advises.
sanitize_flags = -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$(1) -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$(1) -g1 -DNDEBUG"
SANITIZE_BUILD_FLAGS = $(call sanitize_flags,-Og)
TSAN_BUILD_FLAGS = $(call sanitize_flags,-O1)

# The whole test suite (unit, end-to-end, accuracy) built with AddressSanitizer and
# UndefinedBehaviorSanitizer, but for the repeats of the tracer's suite under each Embree ISA
# (label isa): Embree is not instrumented, and the code of dispex they run is the same as in
# the default run (`make test` runs them all).
test-sanitize: deps
	@cmake -S . -B $(BUILD)-sanitize $(SANITIZE_BUILD_FLAGS) -DDISPEX_SANITIZE=ON \
	  -DDISPEX_BUILD_BENCH=OFF -DDISPEX_WERROR=$(WERROR) $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD)-sanitize -j$(JOBS)
	@DISPEX_WITH_BROWSER=1 scripts/install-deps.sh
	@cd $(BUILD)-sanitize && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j$(JOBS) --timeout 900 -LE 'blender|slurm|isa' --output-junit ctest-junit.xml
	@$(CHECK_SKIPS) $(BUILD)-sanitize/ctest-junit.xml

# The extraction pipeline (TBB tasks at 4 threads) under ThreadSanitizer.
test-tsan: deps
	@cmake -S . -B $(BUILD)-tsan $(TSAN_BUILD_FLAGS) -DDISPEX_TSAN=ON \
	  -DDISPEX_BUILD_TESTS=OFF -DDISPEX_BUILD_BENCH=OFF -DDISPEX_WERROR=$(WERROR) \
	  $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD)-tsan -j$(JOBS) --target dispex
	@scripts/build-tsan-tbb.sh $(BUILD)-tsan/tbb
	@scripts/tsan-extract.sh $(BUILD)-tsan

# The tree's formatting, by Debian's clang-format 14 (pinned: other versions format some
# constructs differently). `format-check` fails, listing the files, when one differs.
CLANG_FORMAT ?= clang-format-14
format:
	@DISPEX_WITH_FORMAT=1 scripts/install-deps.sh
	@$(CLANG_FORMAT) -i $$(git ls-files '*.cpp' '*.h')

format-check:
	@DISPEX_WITH_FORMAT=1 scripts/install-deps.sh
	@$(CLANG_FORMAT) --dry-run --Werror $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize $(BUILD)-tsan

# libFuzzer targets for the OBJ, PLY and Ptex readers (clang; see fuzz/README.md). `fuzz`
# runs each target for FUZZ_SECONDS, one per core at a time; `fuzz-ci` runs the three side by
# side for 60 s (on 2 cores each gets two thirds of one: 40 CPU-seconds, against 60 one after
# the other in 120 s); a crash fails the run and its input is copied to tests/fuzz_regressions/.
FUZZ_SECONDS ?= 300
.PHONY: fuzz-ci

fuzz:
	@FUZZ_JOBS=$(JOBS) scripts/fuzz.sh $(FUZZ_SECONDS)

fuzz-ci:
	@FUZZ_JOBS=$(JOBS) FUZZ_PARALLEL=3 scripts/fuzz.sh 60
