# cdlab: top-level driver. Two commands do all set-up on a fresh Debian 12:
#   make run    install what is missing, build Release, run the default scene
#   make test   install what is missing, build Release, run the whole suite
SHELL := /bin/bash
BUILD ?= build
JOBS  ?= $(shell nproc)
SCENE ?= configs/default.toml
CAMPAIGNS ?= outputs/campaigns
OUT   ?= outputs/default

# Debian 12 packages the build needs (what each is for: README.md, "Two commands").
DEB_PKGS := g++ cmake make pkg-config libeigen3-dev libgsl-dev libfftw3-dev \
            libvtk9-dev libgtest-dev libtoml11-dev libcli11-dev libfmt-dev \
            libbenchmark-dev gnuplot-nox
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build run test bench regress accuracy-cost tensile clean help analyze-inertial analyze-cohesive analyze-angularity

all: build

help:
	@echo "make run            build and run the default scene into $(OUT)/"
	@echo "make test           build and run the test suite (ctest)"
	@echo "make bench          build and run the benchmarks (outputs/bench/: bench.json, runs/summary/machine.csv)"
	@echo "make accuracy-cost  eps_f, dt and N against cost and error (outputs/accuracy-cost/; QUICK=1: ~30 s)"
	@echo "make tensile        tensile strength of a cohesive aggregate against dt (outputs/tensile/; QUICK=1: ~20 s)"
	@echo "make deps           install the missing Debian packages (idempotent)"
	@echo "make campaign-inertial|campaign-cohesive|campaign-angularity [N=200 STRAIN=2 P=100 ...]"
	@echo "                    shear campaigns into $(CAMPAIGNS)/<name>/ (one folder per run; make -j2 runs two at once)"
	@echo "make regress        re-run the reference campaign, refit mu(I), compare with tests/data/regress/"
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

# ---- Campaigns (README, "Shear protocols and campaigns") -------------------
# Each run is a make target whose product is its folder (marked complete by
# a .done file written after cdsim succeeds), so `make -j` runs campaigns in
# parallel, finished runs are skipped, and a killed run resumes from its
# checkpoint when made again. Every shear run starts from a compacted sample
# (prep/...) made once per size and shape. Changing N or STRAIN does not
# invalidate finished runs: use another CAMPAIGNS folder (or remove it).
N        ?= 200
STRAIN   ?= 2
P        ?= 100
INERTIAL_I ?= 0.001 0.003 0.01 0.03 0.1 0.3
COHESIVE_ETA ?= 0 1 10 100
COHESIVE_I ?= 0.01 0.1
# Cohesive networks converge slowly: at eta = 10, 1e-4 hit the sweep cap on
# every step (configs/shear-cohesive.toml); the eta = 0 references use it too.
COHESIVE_TOL ?= 1e-3
ANGULAR_NS ?= 0 3 4 5 6 8 10 20 60
ANGULAR_I ?= 0.01
CDSIM := $(BUILD)/cd/cdsim
# Loose square cell for N grains (lattice pitch 1.47 mm for d_mean = 1 mm,
# size ratio 2), and the time step in t_p = d sqrt(rho/p): at most 0.05 t_p,
# and at most 0.005 d of relative sliding per step (dt <= 0.005 t_p / I).
cell_side = $(shell awk 'BEGIN { printf "%.6g", 1.5e-3 * int(sqrt($(N)) + 1) }')
dt_tp = $(shell awk 'BEGIN { x = 0.005 / $(1); printf "%.4g", x < 0.05 ? x : 0.05 }')
# 100 series rows per unit strain: 0.01 / shear rate = 0.01 t_p / I.
series_dt = $(shell awk 'BEGIN { printf "%.6g", 0.01e-3 * sqrt(2.6 / $(P)) / $(1) }')
# A contact snapshot every 0.2 strain (fabric, cdanalysis fabric / report).
snapshot_dt = $(shell awk 'BEGIN { printf "%.6g", 0.2e-3 * sqrt(2.6 / $(P)) / $(1) }')
CAMPAIGN_SET = --set output.quiet=true --set output.checkpoint_interval=0.05

inertial_runs   := $(foreach i,$(INERTIAL_I),$(CAMPAIGNS)/inertial/I_$(i))
cohesive_runs   := $(foreach e,$(COHESIVE_ETA),$(foreach i,$(COHESIVE_I),$(CAMPAIGNS)/cohesive/eta_$(e)_I_$(i)))
angularity_runs := $(foreach n,$(ANGULAR_NS),$(CAMPAIGNS)/angularity/ns_$(n))

.PHONY: campaign-inertial campaign-cohesive campaign-angularity campaign-list
campaign-inertial: $(addsuffix /.done,$(inertial_runs))
campaign-cohesive: $(addsuffix /.done,$(cohesive_runs))
campaign-angularity: $(addsuffix /.done,$(angularity_runs))
# The run folders of a campaign, one per line, and the sample a run starts
# from (configs/cluster/job-array.sh).
.PHONY: campaign-prep-of
campaign-list:
	@for r in $($(CAMPAIGN)_runs); do echo $$r; done
campaign-prep-of:
	@case "$(RUN)" in */angularity/ns_*) echo $(CAMPAIGNS)/prep/$(notdir $(RUN))/.done ;; \
	  *) echo $(CAMPAIGNS)/prep/ns_0/.done ;; esac

# Products, never intermediates: make must not delete a sample when done.
.PRECIOUS: $(CAMPAIGNS)/prep/ns_%/.done

# Compacted samples: disks (ns_0) or n-gons, N grains, isotropic at P.
$(CAMPAIGNS)/prep/ns_%/.done: | build
	$(CDSIM) configs/shear-prep.toml --out $(@D) $(CAMPAIGN_SET) --set output.checkpoint_interval=1 \
	  --set output.snapshot_interval=0 \
	  --set particles.n=$(N) --set particles.nsides=[$*] --set shear.pressure=$(P) \
	  --set shear.width=$(cell_side) --set shear.height=$(cell_side)
	touch $@

shear_run = $(CDSIM) configs/shear-inertial.toml --out $(@D) $(CAMPAIGN_SET) \
	  --set shear.start='"$(CAMPAIGNS)/prep/ns_$(2)/checkpoint.bin"' --set shear.pressure=$(P) \
	  --set shear.inertial_number=$(1) --set shear.strain=$(STRAIN) --set shear.dt_tp=$(call dt_tp,$(1)) \
	  --set output.series_interval=$(call series_dt,$(1)) --set output.snapshot_interval=$(call snapshot_dt,$(1))

$(CAMPAIGNS)/inertial/I_%/.done: $(CAMPAIGNS)/prep/ns_0/.done
	$(call shear_run,$*,0)
	touch $@

# eta_<eta>_I_<I>: f_a = eta p d; eta = 0 are the reference runs of the fit.
$(CAMPAIGNS)/cohesive/eta_%/.done: $(CAMPAIGNS)/prep/ns_0/.done
	$(call shear_run,$(lastword $(subst _I_, ,$*)),0) --set contact.cohesion_number=$(firstword $(subst _I_, ,$*)) \
	  --set solver.tol=$(COHESIVE_TOL)
	touch $@

$(CAMPAIGNS)/angularity/ns_%/.done: $(CAMPAIGNS)/prep/ns_%/.done
	$(call shear_run,$(ANGULAR_I),$*)
	touch $@

# Campaign analyses: the report of outputs/campaigns/<name> (made by the
# campaign-* targets) into outputs/analysis/<name>/, plus the campaign's fits.
CDA := $(BUILD)/analysis/cdanalysis
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

# Regression of fitted curves: re-runs the small reference campaign of
# tests/data/regress/ from scratch (same sizes and seed, ~1 min on 2 cores),
# fits mu(I) and compares with the stored fit: a parameter fails when it
# moved by more than 3 combined standard uncertainties (cdanalysis
# compare-fits). The simulator is deterministic, so an unchanged code gives
# the same numbers; a change of the physics or numerics shows up here.
REGRESS_DIR ?= outputs/regress
REGRESS_I := 0.01 0.02 0.05 0.1 0.2 0.3 0.4
.PHONY: regress regress-campaign
regress: regress-campaign
	$(CDA) fit mu-i $(REGRESS_DIR)/inertial --window 1:3 --toml $(REGRESS_DIR)/mu_i.toml
	$(CDA) compare-fits tests/data/regress/mu_i.toml $(REGRESS_DIR)/mu_i.toml --tol-sigma 3
regress-campaign: build
	rm -rf $(REGRESS_DIR)
	$(MAKE) --no-print-directory -j $(JOBS) campaign-inertial CAMPAIGNS=$(REGRESS_DIR) N=100 STRAIN=3 P=100 \
	  INERTIAL_I="$(REGRESS_I)"

clean:
	rm -rf $(BUILD)
