# wheelins: the README's two quick-start commands are `make demo` and `make test`.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
WHEELINS_WERROR ?= OFF
DEMO_DIR ?= out/demo
WHEELINS := $(BUILD)/wheelins

.PHONY: all setup configure build build-cli demo test bench clean format

all: build

setup:
	@scripts/setup.sh

# Ninja for a new build directory: the targets of `make test` build as one graph, both cores
# busy to the end (a directory configured before keeps its generator).
GENERATOR := $(if $(wildcard $(BUILD)/CMakeCache.txt),,-G Ninja)

configure: setup
	@cmake -S . -B $(BUILD) $(GENERATOR) -DCMAKE_BUILD_TYPE=Release -DWHEELINS_WERROR=$(WHEELINS_WERROR) >/dev/null

build: configure
	@cmake --build $(BUILD) -j$(JOBS)

# The CLI and the Python module (build/python: PYTHONPATH=build/python /usr/bin/python3).
build-cli: configure
	@cmake --build $(BUILD) -j$(JOBS) --target wheelins wheelins_python

# Simulate the built-in default scenario, then run the main job on it.
demo: build-cli
	@scripts/demo.sh $(WHEELINS) $(DEMO_DIR)

# Everything the tests run (the CLI, the test binary, the Python module), not the benchmarks.
test: configure
	@cmake --build $(BUILD) -j$(JOBS) --target wheelins wheelins_tests wheelins_python
	@ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

bench: build
	@$(BUILD)/wheelins_bench

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	@rm -rf $(BUILD)
