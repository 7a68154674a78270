# Entry points. `make demo` and `make test` install the Debian packages they need,
# configure a Release build with ccache, build, and run.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
DEMO_OUT ?= out/demo

.PHONY: deps configure build test demo format bench clean sanitize

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

format:
	git ls-files '*.h' '*.cc' | xargs clang-format -i

# AddressSanitizer + UndefinedBehaviorSanitizer build in its own folder, then the test
# suite under it (docs/reliability.md). SANITIZE_TARGETS limits the build (and ctest
# runs only what was built); SANITIZE_TESTS is a ctest -R filter.
SANITIZE_DIR ?= build-sanitize
SANITIZE_TARGETS ?= all
SANITIZE_TESTS ?= .
SANITIZE_FLAGS = -fsanitize=address,undefined -fno-sanitize-recover=undefined \
  -fno-omit-frame-pointer

sanitize: deps
	cmake -S . -B $(SANITIZE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DHANDLABEL_BUILD_BENCH=OFF \
	  "-DCMAKE_CXX_FLAGS=$(SANITIZE_FLAGS)" "-DCMAKE_C_FLAGS=$(SANITIZE_FLAGS)" \
	  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" $(CMAKE_FLAGS)
	cmake --build $(SANITIZE_DIR) -j $(JOBS) --target $(SANITIZE_TARGETS)
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --test-dir $(SANITIZE_DIR) --output-on-failure -j $(JOBS) \
	  -R '$(SANITIZE_TESTS)' --no-tests=error

clean:
	rm -rf $(BUILD_DIR)
