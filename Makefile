# The two commands of the README, on a fresh Debian 12 machine:
#   make demo   install what is missing, fetch the data, build, run the main job on bundled data
#   make test   install what is missing, fetch the data, build, run every test
# and `make bench` for the benchmarks (JSON into build/bench-results.json),
# `make report` for Benchmarks/RESULTS.md with its CSV files and plots.

BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps data configure build test test-asan demo bench report clean

all: build

deps:
	./scripts/install-deps.sh

# Real third-party data by Debian package name (head CT, laser scans, range
# scans; Data/README.md) into Data/External/, which is not committed: the
# packages are downloaded and unpacked, never installed. A second run checks
# Data/External/MANIFEST.tsv and stops.
data: deps
	./scripts/fetch-data.sh

configure: deps
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# Without a display, the whole test run shares one Xvfb (the OpenGL tests
# find DISPLAY set; see Testing/with-display.sh). -noreset: by default Xvfb
# resets when its last client leaves, and a test connecting during that
# reset fails with "bad X server connection".
XVFB = $(if $(DISPLAY),,xvfb-run -a -s "-screen 0 1280x1024x24 -noreset")

test: build data
	cd $(BUILD) && $(XVFB) ctest --output-on-failure -j $(JOBS) -LE bench
	$(MAKE) test-asan

# Issue 8: a second build folder with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer (any report fails: -fno-sanitize-recover=all,
# LeakSanitizer on at exit) for the project's own code (CPU engine without
# CUDA, readers, and the mappers where they exist); ParaView's libraries are
# not instrumented. It runs the C++ tests of the engine, the command-line
# tool's test, the readers' and the reliability tests, and each libFuzzer target for FUZZ_SECONDS; and the
# Python reader suites (python.particle_reader, .pcd_reader,
# .slice_stack_reader, .depth_and_normals) with the instrumented `octoray`
# modules: python3 and ParaView's libraries are not instrumented, so the ASan
# runtime is preloaded into python3 (LD_PRELOAD, set per test by
# Testing/Python/CMakeLists.txt), with LeakSanitizer off there (the
# interpreter leaks by design).
ASAN_BUILD ?= build-asan
FUZZ_SECONDS ?= 30
FUZZ_SEED ?= 1
ASAN_FLAGS = -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
# Coverage for libFuzzer in the project's code (the readers the fuzz targets
# call), not only in the targets themselves.
ASAN_CXX_FLAGS = $(ASAN_FLAGS) -fsanitize=fuzzer-no-link
ASAN_TARGETS = octoray_engine_tests octoray octorayIOParticlesCxxTests octorayIOImageStackCxxTests \
  octorayFiltersPCLCxxTests TestReaderRobustness TestSceneLeaks octoray_fuzz_ParticleHeader \
  octoray_fuzz_ParticleText octoray_fuzz_PCD octoray_fuzz_SliceStackMetadata \
  octorayIOParticlesPython octorayIOImageStackPython octorayFiltersPCLPython \
  octorayRenderingVolumePython
test-asan: deps
	CC=clang-14 CXX=clang++-14 cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DOCTORAY_ENABLE_CUDA=OFF -DOCTORAY_FUZZ_SECONDS=$(FUZZ_SECONDS) -DOCTORAY_FUZZ_SEED=$(FUZZ_SEED) \
	  -DOCTORAY_PYTHON_ASAN_PRELOAD=$$(clang++-14 -print-file-name=libclang_rt.asan-x86_64.so) \
	  -DCMAKE_C_FLAGS="$(ASAN_FLAGS)" -DCMAKE_CXX_FLAGS="$(ASAN_CXX_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(ASAN_FLAGS)" -DCMAKE_SHARED_LINKER_FLAGS="$(ASAN_FLAGS)" $(CMAKE_FLAGS)
	cmake --build $(ASAN_BUILD) -j $(JOBS) --target $(ASAN_TARGETS)
	cd $(ASAN_BUILD) && \
	  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/Testing/Reliability/lsan.supp:print_suppressions=0 \
	  ctest --output-on-failure -j $(JOBS) \
	  -R '^(deps\.|engine\.(cpu|tool)|octoray::(IOParticles|IOImageStack|FiltersPCL)Cxx-|reliability\.|fuzz\.|python\.(particle_reader|pcd_reader|slice_stack_reader|depth_and_normals)$$)'

# The demo (Wrapping/Python/octoray/demo.py): the head CT (DICOM, bone and
# skin presets, and side by side with vtkSmartVolumeMapper), the PCL laser
# scan and the thesis's LiDAR file, Phong with shadows, into $(BUILD)/demo/,
# printing what each step cost. About a minute on 2 cores without a GPU; a
# quarter-size run of it is the test python.demo. DEMO_ARGS, e.g.
# --backend cpu, --scale 0.5, --thumbnails Testing/Data.
PYTHON = /usr/bin/python3
DEMO_ARGS ?=
demo: build data
	PYTHONPATH=$(abspath $(BUILD))/lib/python3/dist-packages VTK_LOGGING_LEVEL=ERROR \
	  $(XVFB) $(PYTHON) -m octoray.demo --data Data --out $(BUILD)/demo $(DEMO_ARGS)

# --verbose: the benchmarks' tables are the output wanted, pass or fail.
bench: build
	cd $(BUILD) && $(XVFB) ctest --verbose -L bench

# Issue 7: regenerates Benchmarks/RESULTS.md, its CSV files and plots
# (Benchmarks/report/) and the README's summary table from scratch on this
# machine; GPU rows come from the committed GPU run in Benchmarks/gpu/.
# REPORT_ARGS, e.g. --only quality, to redo some sections.
REPORT_ARGS ?=
report: build
	/usr/bin/python3 Benchmarks/Report/make_report.py --build $(BUILD) $(REPORT_ARGS)

clean:
	rm -rf $(BUILD)
