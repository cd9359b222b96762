# nlobs — two commands: `make demo` (the main job) and `make test`.
# Both install missing Debian packages (scripts/ensure-deps.sh), configure (Release), build, run.
# `make demo` builds only the CLI and the libraries it links; `make test` builds everything.
# ccache is used when installed (`make demo CMAKE_ARGS=-DNLOBS_CCACHE=OFF` turns it off).
BUILD      ?= build
BUILD_TYPE ?= Release
WERROR     ?= OFF
JOBS       ?= 2
CMAKE_ARGS ?=

.PHONY: all deps configure build build-cli test demo bench sanitize fuzz format format-check clean \
        compile-cost

all: build

deps:
	@./scripts/ensure-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DNLOBS_WERROR=$(WERROR) $(CMAKE_ARGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

build-cli: configure
	cmake --build $(BUILD) -j $(JOBS) --target nlobs

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

demo: build-cli
	$(BUILD)/cli/nlobs run chua-fp --out $(BUILD)/demo
	@echo "plots: $(BUILD)/demo/states.png errors.png first_window.png (summary.json, trajectories.csv beside them)"

bench: build
	$(BUILD)/bench/nlobs_bench --benchmark_min_time=0.2

# AddressSanitizer + UndefinedBehaviorSanitizer, warnings as errors, separate build directory.
# The benchmarks are left out there (make test runs their smoke test; a bench build under ASan
# times nothing and costs CI minutes).
sanitize: deps
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DNLOBS_SANITIZE=ON -DNLOBS_WERROR=ON \
	      -DNLOBS_BUILD_BENCH=OFF $(CMAKE_ARGS)
	cmake --build build-asan -j $(JOBS)
	ctest --test-dir build-asan --output-on-failure -j $(JOBS)

# libFuzzer (clang) on the scenario and --data readers and the plugin loader's ELF checks,
# FUZZ_SECONDS per target, seeded, from tests/fuzz/corpus; ASan + UBSan on; a finding fails the
# target (docs/fuzzing.md).
FUZZ_SECONDS ?= 300
fuzz:
	@./scripts/ensure-deps.sh fuzz
	cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++ -DNLOBS_FUZZ=ON \
	      -DNLOBS_SANITIZE=ON -DNLOBS_BUILD_TESTS=OFF -DNLOBS_BUILD_BENCH=OFF $(CMAKE_ARGS)
	cmake --build build-fuzz -j $(JOBS) --target fuzz_scenario fuzz_data_csv fuzz_plugin_file \
	      fuzz_suite_report
	./scripts/run-fuzz build-fuzz $(FUZZ_SECONDS)

format: deps
	find common solvers observers models registry runs reference bench cli tests examples -name '*.hpp' -o -name '*.cpp' -o -name '*.inc' | xargs clang-format -i

format-check: deps
	find common solvers observers models registry runs reference bench cli tests examples -name '*.hpp' -o -name '*.cpp' -o -name '*.inc' | xargs clang-format --dry-run --Werror

# Per-translation-unit wall time and peak memory of a from-scratch build (docs/architecture.md).
compile-cost: deps
	./scripts/compile-cost --jobs $(JOBS)

clean:
	rm -rf $(BUILD) build-asan build-cost build-fuzz
