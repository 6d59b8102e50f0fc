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

# The LiDAR tile's reflectivity column is the scanner's intensity (0.3-0.6):
# taken as mirror weight it would blend every voxel with the empty sky, so
# the demo pictures draw first hits only (--bounces 0).
DEMO_DATA = Data/Particles/lidar_simple.particles
demo: build
	$(BUILD)/bin/octoray stats $(DEMO_DATA)
	$(BUILD)/bin/octoray render $(DEMO_DATA) -o $(BUILD)/demo-phong.png --mode phong --shadows --bounces 0 --zoom 1.3
	$(BUILD)/bin/octoray render $(DEMO_DATA) -o $(BUILD)/demo-surface.png --mode surface --bounces 0 --zoom 1.3

# --verbose: the benchmarks' tables are the output wanted, pass or fail.
bench: build
	cd $(BUILD) && ctest --verbose -L bench

clean:
	rm -rf $(BUILD)
