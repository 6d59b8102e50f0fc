# The two commands of the README, on a fresh Debian 12 machine:
#   make demo   install what is missing, build, run the main job on bundled data
#   make test   install what is missing, build, run every test
# and `make bench` for the benchmarks (JSON into build/bench-results.json).

BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test demo bench clean

all: build

deps:
	./scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE bench

demo: build
	$(BUILD)/bin/octoray stats Data/Particles/lidar_simple.particles

# --verbose: the benchmarks' tables are the output wanted, pass or fail.
bench: build
	cd $(BUILD) && ctest --verbose -L bench

clean:
	rm -rf $(BUILD)
