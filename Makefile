# The two commands: `make demo` and `make test`. Each installs missing Debian packages,
# configures and builds in Release into build/, then runs the demo or the whole test suite.
BUILD       ?= build
JOBS        ?= $(shell nproc)
WERROR      ?= OFF
CMAKE_FLAGS ?=

.PHONY: all deps build demo test test-sanitize bench fuzz format clean

all: build

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DDISPEX_BUILD_BENCH=ON \
	  -DDISPEX_WERROR=$(WERROR) $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD) -j$(JOBS)

demo: build
	@scripts/demo.sh $(BUILD)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j$(JOBS) --timeout 900

# The production-scale benchmark (bench/run): assets generated on first use in
# $$DISPEX_BENCH_CACHE (default ~/.cache/dispex/bench), table on stdout, JSON in out/bench/.
bench: build
	@DISPEX_BUILD=$(BUILD) bench/run $(BENCH_ARGS)

# Unit tests built with AddressSanitizer and UndefinedBehaviorSanitizer.
test-sanitize: deps
	@cmake -S . -B $(BUILD)-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDISPEX_SANITIZE=ON \
	  -DDISPEX_BUILD_BENCH=OFF -DDISPEX_WERROR=$(WERROR) $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD)-sanitize -j$(JOBS)
	@cd $(BUILD)-sanitize && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j$(JOBS) -L unit --timeout 900

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize

# libFuzzer targets for the OBJ, PLY and Ptex readers (clang; see fuzz/README.md). `fuzz`
# runs each target for FUZZ_SECONDS, `fuzz-ci` for 60 s; a crash fails the run and its input
# is copied to tests/fuzz_regressions/.
FUZZ_SECONDS ?= 300
.PHONY: fuzz-ci

fuzz:
	@FUZZ_JOBS=$(JOBS) scripts/fuzz.sh $(FUZZ_SECONDS)

fuzz-ci:
	@FUZZ_JOBS=$(JOBS) scripts/fuzz.sh 60
