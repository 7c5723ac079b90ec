# cdlab: top-level driver. Two commands do all set-up on a fresh Debian 12:
#   make run    install what is missing, build Release, run the default scene
#   make test   install what is missing, build Release, run the whole suite
SHELL := /bin/bash
BUILD ?= build
JOBS  ?= $(shell nproc)
SCENE ?= configs/default.toml
OUT   ?= outputs/default

# Debian 12 packages the build needs (docs in README, facts in shared/docs/deps.md).
DEB_PKGS := g++ cmake make pkg-config libeigen3-dev libgsl-dev libfftw3-dev \
            libvtk9-dev libgtest-dev libtoml11-dev libcli11-dev libfmt-dev \
            libbenchmark-dev gnuplot-nox
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build run test bench accuracy-cost tensile clean help analyze-inertial analyze-cohesive analyze-angularity

all: build

help:
	@echo "make run            build and run the default scene into $(OUT)/"
	@echo "make test           build and run the test suite (ctest)"
	@echo "make bench          build and run the benchmarks (outputs/bench/: bench.json, runs/summary/machine.csv)"
	@echo "make accuracy-cost  eps_f, dt and N against cost and error (outputs/accuracy-cost/; QUICK=1: ~30 s)"
	@echo "make tensile        tensile strength of a cohesive aggregate against dt (outputs/tensile/; QUICK=1: ~20 s)"
	@echo "make deps           install the missing Debian packages (idempotent)"
	@echo "make analyze-inertial|analyze-cohesive|analyze-angularity"
	@echo "                    cdanalysis report and fits of outputs/campaigns/<name> into outputs/analysis/<name>/"

# Idempotent: asks dpkg which packages are missing and installs only those.
deps:
	@missing=$$(for p in $(DEB_PKGS); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "make deps: installing $$missing"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	else echo "make deps: all Debian packages present"; fi

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

run: build
	$(BUILD)/cd/cdsim $(SCENE) --out $(OUT)
	@echo ""
	@echo "Outputs in $(OUT)/: series.csv (time series, columns in README.md), scene.toml"
	@echo "(resolved scene), shapes.pvd, particles.pvd, contacts.pvd, walls.pvd (VTK collections)."
	@echo "Open in ParaView:  paraview $(OUT)/shapes.pvd   (grains as drawn; colour by velocity)"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900

# Timings are comparable only with the machine named: machine.csv (CPU, cores,
# compiler, flags, load average) is written next to the results.
bench: build
	mkdir -p outputs/bench
	@awk -v n=$$(nproc) '$$1 > n / 2 { printf "make bench: load average %s on %d cores: times, above all the 2-thread ones, will be noisy\n", $$1, n }' /proc/loadavg
	$(BUILD)/cd/bench/cdbench --benchmark_out=outputs/bench/bench.json --benchmark_out_format=json --csv_dir=outputs/bench

accuracy-cost: build
	$(BUILD)/cd/bench/accuracy_cost --out outputs/accuracy-cost $(if $(QUICK),--quick)

# Cohesion against the time step (README, "Cohesion and the time step").
tensile: build
	$(BUILD)/cd/bench/tensile --out outputs/tensile $(if $(QUICK),--quick)

# Campaign analyses: the report of outputs/campaigns/<name> (made by the
# campaign-* targets) into outputs/analysis/<name>/, plus the campaign's fits.
CDA := $(BUILD)/analysis/cdanalysis
CAMPAIGNS := outputs/campaigns
ANALYSIS := outputs/analysis

analyze-inertial: build
	$(CDA) report $(CAMPAIGNS)/inertial --out $(ANALYSIS)/inertial
	$(CDA) fit mu-i $(CAMPAIGNS)/inertial --toml $(ANALYSIS)/inertial/mu_i.toml
	$(CDA) fit dilatancy $(CAMPAIGNS)/inertial --out $(ANALYSIS)/inertial/dilatancy --toml $(ANALYSIS)/inertial/dilatancy.toml

# The eta = 0 reference runs (eta_0_I_*) must be in the cohesive campaign.
analyze-cohesive: build
	$(CDA) report $(CAMPAIGNS)/cohesive --out $(ANALYSIS)/cohesive
	$(CDA) fit cohesion $(CAMPAIGNS)/cohesive --out $(ANALYSIS)/cohesive/cohesion --toml $(ANALYSIS)/cohesive/cohesion.toml

analyze-angularity: build
	$(CDA) report $(CAMPAIGNS)/angularity --out $(ANALYSIS)/angularity

clean:
	rm -rf $(BUILD)
