# Thin wrapper over CMake. `make` builds into build/ (Release), `make demo`
# runs the main job, `make test` builds and runs every test.
BUILD ?= build
JOBS ?= 2
CMAKE_FLAGS ?=
# Lets ccache reuse objects across checkouts in different folders.
export CCACHE_BASEDIR := $(CURDIR)

.PHONY: all build demo test setup bench format clean sanitize-test fuzz docs

all: build

# Runs scripts/setup only when a needed package is missing.
setup:
	@bash scripts/setup

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: setup $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	bash scripts/demo $(BUILD)/pneumid

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

bench: build
	bash bench/run_all.sh $(BUILD)

# Unit tests under AddressSanitizer and UndefinedBehaviorSanitizer.
sanitize-test: setup
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DPNEUMID_SANITIZE=ON \
	  -DPNEUMID_BUILD_BENCHMARKS=OFF -DPNEUMID_BUILD_PYTHON=OFF
	cmake --build build-asan -j$(JOBS) --target pneumid_unit_tests
	cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	  ctest --output-on-failure -j$(JOBS) -L unit

# API reference: C++ (Doxygen, with search) and Python (pydoc) HTML in
# $(BUILD)/docs/api; fails on Doxygen warnings and below the documented share
# of docs/api/coverage_floor.txt (scripts/api_docs.py).
docs: build
	/usr/bin/python3 scripts/api_docs.py $(BUILD)/docs/api --python-path $(BUILD)/python

# libFuzzer targets of the parsers (clang), each run FUZZ_SECONDS (default 30).
fuzz: setup
	JOBS=$(JOBS) bash tests/fuzz/run.sh

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) build-asan build-fuzz
