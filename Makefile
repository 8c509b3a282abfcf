# Entry points. Each target installs the Debian packages it needs on a fresh machine (as root).
BUILD ?= build
JOBS ?= $(shell nproc)
DEB_PACKAGES = cmake g++ make pkg-config libgtest-dev libbenchmark-dev libtomlplusplus-dev libcli11-dev \
               libfmt-dev libcairo2-dev libpng-dev nlohmann-json3-dev zlib1g-dev clang-format python3 \
               pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build python test validate demo bench clean

all: build

deps:
	@missing=""; for p in $(DEB_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing >/dev/null; fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(BUILD) -j $(JOBS)

# The Python module haet, for Debian's /usr/bin/python3 (docs/python.md): BUILD/python/haet*.so.
python: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(BUILD) -j $(JOBS) --target python

test: build
	cd $(BUILD) && ctest -L fast --output-on-failure -j $(JOBS)

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
	rm -rf $(BUILD)
