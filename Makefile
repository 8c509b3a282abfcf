# Entry points. Each target installs the Debian packages it needs on a fresh machine (as root).
BUILD ?= build
SAN_BUILD ?= build-san
FUZZ_BUILD ?= build-fuzz
JOBS ?= $(shell nproc)
DEB_PACKAGES = cmake g++ make pkg-config libgtest-dev libbenchmark-dev libtomlplusplus-dev libcli11-dev \
               libfmt-dev libcairo2-dev libpng-dev nlohmann-json3-dev zlib1g-dev clang-format python3 \
               pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib \
               libopenmpi-dev openmpi-bin
# make fuzz: clang with libFuzzer and its sanitizer runtimes, LLVM's OpenMP.
FUZZ_DEB_PACKAGES = clang libclang-rt-14-dev libomp-dev
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# Sanitizer reports: leaks too (but those tests/lsan.supp names), stop at the first report, with its stack.
SANITIZE_ENV = ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=1:print_stacktrace=1 \
               LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
               UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1

.PHONY: all deps fuzz-deps build python test test-sanitize fuzz validate demo bench clean

all: build

deps:
	@missing=""; for p in $(DEB_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing >/dev/null; fi

fuzz-deps:
	@$(MAKE) --no-print-directory deps DEB_PACKAGES="$(DEB_PACKAGES) $(FUZZ_DEB_PACKAGES)"

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(BUILD) -j $(JOBS)

# The Python module haet, for Debian's /usr/bin/python3 (docs/python.md): BUILD/python/haet*.so.
python: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(BUILD) -j $(JOBS) --target python

test: build
	cd $(BUILD) && ctest -L fast --output-on-failure -j $(JOBS)

# The fast tests built with AddressSanitizer and UndefinedBehaviorSanitizer (GCC, -O1): only the test programs
# and haet, which the command line's tests run (not the Python module: the interpreter is not instrumented).
# Tests labelled nosanitize are left out.
# Without MPI: Open MPI keeps allocations past MPI_Finalize (some in components it has unloaded by then, which no
# suppression can name), and LeakSanitizer would stop every run across ranks.
test-sanitize: deps
	cmake -S . -B $(SAN_BUILD) -DCMAKE_BUILD_TYPE=Release -DHAET_SANITIZE=ON -DHAET_PYTHON=OFF -DHAET_MPI=OFF >/dev/null
	cmake --build $(SAN_BUILD) -j $(JOBS) --target haet haet_tests
	cd $(SAN_BUILD) && $(SANITIZE_ENV) ctest -L fast -LE nosanitize --output-on-failure -j $(JOBS)

# The libFuzzer targets of tests/fuzz/ (clang), each run for FUZZ_SECONDS (default: one hour in all), FUZZ_JOBS
# at a time; tests/fuzz/run.sh says where crashes go.
fuzz: fuzz-deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Release -DHAET_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ >/dev/null
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzzers
	tests/fuzz/run.sh $(FUZZ_BUILD)

validate: build
	cd $(BUILD) && ctest -L validate --output-on-failure -j $(JOBS)

demo: build
	$(BUILD)/haet run examples/silo2d.toml --out runs/demo
	$(BUILD)/haet plot runs/demo/series.csv -x time -y orifice_rate -y drain_rate \
	    --title "silo2d: discharge rate through the orifice and off the floor [kg/(m s)]" -o runs/demo/discharge.png
	@echo "demo: runs/demo/final.png (blue: time-driven, orange: event-driven), discharge.png, series.csv, particles.pvd, walls.pvd, zones.pvd, run.json"

bench: build
	bench/run_all.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(SAN_BUILD) $(FUZZ_BUILD)
