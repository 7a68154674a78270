# Entry points. `make demo` and `make test` install the Debian packages they need,
# configure a Release build with ccache, build, and run.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
DEMO_OUT ?= out/demo

.PHONY: deps configure build test demo format bench clean sanitize check-blender

deps:
	bash scripts/install-deps

$(BUILD_DIR)/build.ninja:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache $(CMAKE_FLAGS)

configure: deps $(BUILD_DIR)/build.ninja

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

demo: build
	bash scripts/demo $(BUILD_DIR) $(DEMO_OUT)

bench: build
	bash scripts/run-benchmarks $(BUILD_DIR)

# Opt-in: a 20-frame glb export imported by Blender (skipped without `blender`; not in
# `make test` or CI; docs/exports.md).
check-blender: build
	bash scripts/check-blender-glb $(BUILD_DIR)/apps/handlabel

format:
	git ls-files '*.h' '*.cc' | xargs clang-format -i

# AddressSanitizer + UndefinedBehaviorSanitizer build in its own folder, then the test
# suite under it (docs/reliability.md). -O1 -g1: the optimisation ASan's documentation
# recommends and the line tables a report needs, both to keep the long build shorter.
# SANITIZE_TARGETS limits the build (ctest then runs only what was built: not the
# placeholders of unbuilt test binaries, nor the tests of the installed binary, MediaPipe,
# the browser, the docs' options and the program's link line, which need the program).
# SANITIZE_TESTS is a ctest -R filter. The environment applies to the build too: it
# runs each test binary to list its tests. sanitizers/*.supp: system libraries only.
SANITIZE_DIR ?= build-sanitize
SANITIZE_TARGETS ?= all
SANITIZE_TESTS ?= .
SANITIZE_FLAGS = -fsanitize=address,undefined -fno-sanitize-recover=undefined \
  -fno-omit-frame-pointer
SANITIZE_EXCLUDE = _NOT_BUILT$$
ifneq ($(SANITIZE_TARGETS),all)
SANITIZE_EXCLUDE := $(SANITIZE_EXCLUDE)|^installed_binary$$|^mediapipe_parity$$|^browser_report$$
SANITIZE_EXCLUDE := $(SANITIZE_EXCLUDE)|^doc_examples_use_real_options$$|^program_links_no_atlas$$
endif
SANITIZE_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/sanitizers/lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:suppressions=$(CURDIR)/sanitizers/ubsan.supp

sanitize: deps
	cmake -S . -B $(SANITIZE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DHANDLABEL_BUILD_BENCH=OFF \
	  "-DCMAKE_CXX_FLAGS=$(SANITIZE_FLAGS)" "-DCMAKE_C_FLAGS=$(SANITIZE_FLAGS)" \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
	  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
	  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" $(CMAKE_FLAGS)
	$(SANITIZE_ENV) cmake --build $(SANITIZE_DIR) -j $(JOBS) --target $(SANITIZE_TARGETS)
	$(SANITIZE_ENV) ctest --test-dir $(SANITIZE_DIR) --output-on-failure -j $(JOBS) \
	  -R '$(SANITIZE_TESTS)' -E '$(SANITIZE_EXCLUDE)' --no-tests=error

clean:
	rm -rf $(BUILD_DIR)
