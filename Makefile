# The README's two commands: `make demo` and `make check`. CMake does the building underneath.
BUILD_DIR ?= build
ASAN_DIR ?= build-asan
RELEASE_DIR ?= build-release
OPTIONAL_DIR ?= build-optional
JOBS ?= $(shell nproc)
PREFIX ?= /usr/local

.PHONY: all deps build demo check test test-asan build-release test-release build-release-clang test-optional pipeline-doc architecture-doc install clean

all: build

deps:
	./scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGDR_WERROR=ON -DCMAKE_INSTALL_PREFIX=$(PREFIX)
	cmake --build $(BUILD_DIR) -j $(JOBS)

# Renders the built-in scene to demo.png and prints the statistics.
demo: build
	$(BUILD_DIR)/tools/gdr/gdr render demo --out demo.png --stats demo.json

# The whole suite: every test on lavapipe with validation on, then the unit tests and the GPU paths
# (test_gpu_sanitized) under ASan+UBSan, then the Release configuration users build, compiled, and
# its unit tests (-O3 vectorises what -O0 does not: a cluster sphere short by an ulp hid there),
# then a build without the optional modules.
check: build test test-asan build-release test-release test-optional

test:
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-asan: deps
	cmake -S . -B $(ASAN_DIR) -DCMAKE_BUILD_TYPE=Debug -DGDR_WERROR=ON -DGDR_SANITIZE=ON
	cmake --build $(ASAN_DIR) -j $(JOBS)
	cd $(ASAN_DIR) && ctest --output-on-failure -j $(JOBS) -L 'unit|sanitize'

# docs/PIPELINE.md's printout of every frame configuration, regenerated from `gdr info --passes`.
pipeline-doc: build
	./scripts/update-pipeline-doc.sh $(BUILD_DIR)/tools/gdr/gdr

# docs/architecture.svg, the module graph of docs/ARCHITECTURE.md, drawn again from the includes
# (needs Graphviz, Debian's graphviz; not needed to build or test).
architecture-doc:
	./scripts/check-layers.sh --dot | grep -v '"umbrella"' | tred | dot -Tsvg >docs/architecture.svg

# The Release build type with warnings as errors: gcc warns at -O3 where it does not at -O2.
# build-release-clang does the same with clang (CI runs both).
build-release: deps
	cmake -S . -B $(RELEASE_DIR) -DCMAKE_BUILD_TYPE=Release -DGDR_WERROR=ON -DGDR_BUILD_FUZZ=OFF
	cmake --build $(RELEASE_DIR) -j $(JOBS)

test-release: build-release
	cd $(RELEASE_DIR) && ctest --output-on-failure -j $(JOBS) -L unit

build-release-clang: deps
	CC=clang cmake -S . -B $(RELEASE_DIR)-clang -DCMAKE_BUILD_TYPE=Release -DGDR_WERROR=ON -DGDR_BUILD_FUZZ=OFF
	cmake --build $(RELEASE_DIR)-clang -j $(JOBS)

# The library and the program built without the optional modules (cull, present) in a tree of their
# own, linked, installed and run beside the full build's program (docs/ARCHITECTURE.md, "Optional
# modules"): only the library, gdr and render_demo are built, so it adds well under a minute.
test-optional: build
	JOBS=$(JOBS) ./tests/optional/test_optional_modules.sh . $(OPTIONAL_DIR) $(BUILD_DIR)/tools/gdr/gdr

install: build
	cmake --install $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR) $(ASAN_DIR) $(RELEASE_DIR) $(RELEASE_DIR)-clang $(OPTIONAL_DIR)
