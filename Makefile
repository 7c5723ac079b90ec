# cdlab: top-level driver. Two commands do all set-up on a fresh Debian 12:
#   make run    install what is missing, build Release, run the default scene
#   make test   install what is missing, build Release, run the whole suite
SHELL := /bin/bash
BUILD ?= build
JOBS  ?= $(shell nproc)
SCENE ?= configs/default.toml
# DIM=3 runs the shear campaigns and analyses with spheres (configs/shear3-*.toml,
# p in N/m^2, rho in kg/m^3) into their own folders (docs/3d.md).
DIM ?= 2
ifeq ($(filter 2 3,$(DIM)),)
$(error DIM=$(DIM): the dimension is 2 or 3)
endif
dim3 = $(filter 3,$(DIM))
CAMPAIGNS ?= outputs/campaigns$(if $(dim3),3d)
OUT   ?= outputs/default

# Debian 12 packages the build needs (what each is for: README.md, "Two commands").
DEB_PKGS := g++ cmake make pkg-config libeigen3-dev libgsl-dev libfftw3-dev \
            libvtk9-dev libgtest-dev libtoml11-dev libcli11-dev libfmt-dev \
            libbenchmark-dev gnuplot-nox libfclib-dev
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)


.PHONY: prep-overlap
.PHONY: all deps build run test bench regress accuracy-cost accuracy-shear tensile clean help analyze-inertial analyze-inertial-ladder analyze-pressure analyze-pressure-ladder analyze-cohesive analyze-angularity scene-doc figures frozen-shear

all: build

# Every target and every variable a user may set, with its current value
# (the default unless given): tests/check_help.cmake (ctest Make.HelpComplete)
# fails when a target of this Makefile, or a variable it reads with ?= or
# never sets, is missing here.
help_space := $() $()
# '$(1)', quoted for the shell (also the manifests' 'VAR=value' pairs).
help_q = '$(subst ','\'',$(1))'
help_var = @printf '  %-34s %s\n' $(call help_q,$(1)=$(if $(findstring $(help_space),$($(1))),"$($(1))",$($(1))))\
  $(call help_q,$(2))
help:
	@echo "Set-up and single runs (docs/setup.md)"
	@echo "  make deps            install the missing Debian packages (idempotent)"
	@echo "  make build (= make all)  build everything: cdsim, cdanalysis, cdproblem, tests, benchmarks"
	@echo "  make run             build cdsim only and run SCENE into OUT (SET: overrides)"
	@echo "  make test            build everything and run the test suite (ctest)"
	@echo "  make test-sanitize   the same suite built with ASan and UBSan in SANITIZE_BUILD (any report fails it;"
	@echo "                       not part of make test; tests/README.md)"
	@echo "  make clean           remove the build folder"
	@echo "  make scene-doc       regenerate docs/scene-parameters.md from cdsim --help-scene=md (test_help_scene checks it)"
	@echo "  make figures         regenerate docs/figures/ (installs ParaView's pvbatch and xvfb if missing; not part of make test)"
	@echo "  make fuzz            libFuzzer on every reader under ASan and UBSan, FUZZ_SECONDS each (clang, FUZZ_BUILD;"
	@echo "                       with -j2 two targets at once; not part of the test suite; docs/errors.md, Fuzzing)"
	@echo "  make help            this list"
	@echo "Measurements (docs/accuracy.md)"
	@echo "  make bench           the benchmarks (outputs/bench/: bench.json, runs/summary/machine.csv;"
	@echo "                       3D: outputs/bench/3d/, N = 1e3-1e4, BIG=1: to 1e5)"
	@echo "  make accuracy-cost   eps_f, dt and N against cost and error (outputs/accuracy-cost/; QUICK=1: ~30 s);"
	@echo "                       3D: polyhedral-cone Lemke against e and the exact NLGS (outputs/accuracy-cost/3d/)"
	@echo "  make accuracy-shear  solver settings against steady mu*, phi, z and cost in shear (ACC/; hours)"
	@echo "  make accuracy-shear3  3D shear settings against a tight reference over 3 samples (A3_DIR; ~2 CPU hours)"
	@echo "  make tensile         tensile strength of a cohesive aggregate against dt (outputs/tensile/; QUICK=1: ~20 s)"
	@echo "  make compare-liggghts-shear  a 1000-sphere mu(I) point by LIGGGHTS and cdsim, one thread each: CPU per"
	@echo "                       unit strain, sweeps, mu, phi, z, the ratio (CMP_DIR; QUICK=1: strain 0.3)"
	@echo "  make compare-liggghts-ladder  LIGGGHTS at each stiffness E/p of LADDER_EP beside cdsim's settings"
	@echo "                       LADDER_CD, each against the rigid reference: cost for the same mu, phi, z"
	@echo "  make compare-yade-pile  the first YCMP_T s of 1000 cubes falling (pile-polyhedra) by YADE's polyhedra"
	@echo "                       and cdsim, one thread each: CPU, steps, largest overlap, the ratio (YCMP_DIR)"
	@echo "  make prep-overlap    ratio-4 preparations (disks, hexagons, a 3/6/0 mixture at ratio 5), N = PO_N: fails if an overlap reaches 0.01 d_small"
	@echo "  make frozen-shear    steady-shear contact problems (disks, hexagons; I = 1e-2, 1e-3) into FROZEN/N_<FS_N>/"
	@echo "  make frozen-shear3   a 3D shear step at I = 1e-2 (tests/data/frozen-shear3) into FROZEN/3d/N_<FS3_N>/"
	@echo "  make regress         re-run the 2D and 3D reference campaigns, refit mu(I), compare with tests/data/regress*/"
	@echo "  make mutants         apply each deliberate physics bug of tests/mutants/ to a scratch copy, run the tests it names,"
	@echo "                       print the survivors and the score (BUILD/mutants/)"
	@echo "Shear campaigns into CAMPAIGNS/<name>/, one folder per run; make -j2 runs two at once (docs/shear.md)"
	@echo "  make campaign-inertial          mu(I): one run per I of INERTIAL_I, from a compacted sample"
	@echo "  make campaign-inertial-ladder   the same values of I from the highest down, each from the point above"
	@echo "  make campaign-cohesive          each eta of COHESIVE_ETA at each I of COHESIVE_I"
	@echo "  make campaign-angularity        each shape of ANGULAR_NS (2D) or ANGULAR_SHAPES (3D) at ANGULAR_I"
	@echo "  make campaign-walls             the same shapes between rough walls (the walls protocol, 2D)"
	@echo "  make campaign-pressure          steady shear at PRESSURE_I under each p of PRESSURE_P"
	@echo "  make campaign-pressure-ladder   the same from the lowest p up, each from the point below"
	@echo "  make campaign-volume            steady shear at imposed volume at each packing fraction of VOLUME_PHI,"
	@echo "                                  at the rate VOLUME_RATE_TP / t_p (p and I measured)"
	@echo "  make validate-angularity        the polygon study's shapes at VAL_I in the bi-periodic cell into VALIDATE"
	@echo "                                  (N = VAL_N, size ratio 4; hours a shape; docs/shear.md, Campaigns)"
	@echo "  make validate-angularity-walls  the same between rough walls (the study's protocol) into VALIDATE"
	@echo "  make validation-tables          their finished runs' rows into tests/data/validation/"
	@echo "  make validate-check             refit those tables, compare with their stored fits"
	@echo "  make campaign-status [CAMPAIGN=inertial]  each run: done / running / not started / failed / stopped,"
	@echo "                       its progress, cost (CPU, steps) and ETA (every campaign in CAMPAIGNS unless CAMPAIGN)"
	@echo "  (each campaign folder's manifest.toml holds what made it: make refuses to add runs made with another"
	@echo "   N, STRAIN, P, ... to it, naming the difference; docs/shear.md, \"What made a campaign\")"
	@echo "Analyses of CAMPAIGNS/<name> into outputs/analysis[3d]/<name>/ (docs/analysis.md)"
	@echo "  make analyze-inertial, analyze-inertial-ladder, analyze-cohesive, analyze-angularity"
	@echo "  make analyze-pressure, analyze-pressure-ladder, analyze-volume   cdanalysis report and the campaign's fits"
	@echo "Used by the targets above and by scripts"
	@echo "  make programs        build cdsim, cdanalysis and cdproblem only (what the campaigns run)"
	@echo "  make campaign-list CAMPAIGN=inertial      the run folders of a campaign (configs/cluster/job-array.sh)"
	@echo "  make campaign-prep-of RUN=<run folder>    the sample that run starts from"
	@echo "  make regress-campaign, regress3-campaign  the reference campaigns of make regress"
	@echo "  make frozen-shear-runs, accuracy-shear-runs, accuracy-shear3-runs  the runs of make frozen-shear, make accuracy-shear, make accuracy-shear3"
	@echo "  make frozen-shear3-run  the run of make frozen-shear3 (its sample, then the shear)"
	@echo "  make compare-liggghts-ladder-runs, ladder-cdsim  the runs of make compare-liggghts-ladder (all; cdsim's)"
	@echo "Variables (make TARGET VAR=value ...), with their values now"
	$(call help_var,SCENE,the scene of make run)
	$(call help_var,OUT,its output folder)
	$(call help_var,SET,scene overrides for make run: SET="--set k=v --set k2=v2")
	$(call help_var,BUILD,the build folder)
	$(call help_var,JOBS,parallel compile jobs)
	$(call help_var,SANITIZE_BUILD,make test-sanitize's build folder (ASan, UBSan))
	$(call help_var,THREADS,threads of each campaign run; empty: nproc / the -j of make)
	$(call help_var,DIM,2 (disks/polygons) or 3 (spheres) for campaigns and analyses)
	$(call help_var,CAMPAIGNS,the campaigns' folder)
	$(call help_var,N,grains per sample)
	$(call help_var,STRAIN,shear strain of each run)
	$(call help_var,LADDER_STRAIN,shear strain of each ladder point)
	$(call help_var,P,imposed pressure (2D N/m; 3D N/m^2))
	$(call help_var,SIZE_RATIO,d_max / d_min of the samples)
	$(call help_var,SIZE_DIST,size distribution (uniform_area or uniform))
	$(call help_var,SHEAR_TOL,solver.tol for every shear run (empty: by I; docs/shear.md))
	$(call help_var,SHEAR_SET,more --set options for every shear run (e.g. --set solver.anderson=5))
	$(call help_var,CMP_DIR,make compare-liggghts-shear's folder)
	$(call help_var,LADDER_DIR,make compare-liggghts-ladder's folder)
	$(call help_var,LADDER_EP,its LIGGGHTS stiffnesses E/p at I = 0.01)
	$(call help_var,LADDER_EP3,those at I = 1e-3)
	$(call help_var,LADDER_SEEDS,LIGGGHTS' samples (deck.py seed))
	$(call help_var,LADDER_CD,cdsim's settings (a3_set_<name>))
	$(call help_var,LADDER_CD3,those at I = 1e-3)
	$(call help_var,YCMP_DIR,make compare-yade-pile's folder)
	$(call help_var,YCMP_E,YADE's polyhedra stiffness (the material's young; its law's kn = E/2 in N/m^3))
	$(call help_var,YCMP_T,the simulated seconds of make compare-yade-pile)
	$(call help_var,CMP_I,its inertial number)
	$(call help_var,CMP_STRAIN,its strain (QUICK=1: 0.3))
	$(call help_var,PREP_SET,more --set options for the preparations)
	$(call help_var,INERTIAL_I,the inertial numbers of campaign-inertial[-ladder])
	$(call help_var,COHESIVE_ETA,cohesion numbers of campaign-cohesive)
	$(call help_var,COHESIVE_I,its inertial numbers)
	$(call help_var,COHESIVE_TOL,its solver.tol (empty: configs/shear-cohesive.toml's))
	$(call help_var,ANGULAR_NS,polygon sides of campaign-angularity (0: disks))
	$(call help_var,ANGULAR_SHAPES,its 3D shapes (particles.shape; sphere: spheres))
	$(call help_var,ANGULAR_I,its inertial number)
	$(call help_var,VALIDATE,make validate-angularity's folder)
	$(call help_var,VALIDATE_CHECK,make validate-check's refits)
	$(call help_var,VAL_N,its grains)
	$(call help_var,VAL_NS,its shapes (polygon sides; 0: disks))
	$(call help_var,VAL_I,its inertial number)
	$(call help_var,VAL_STRAIN,its strain)
	$(call help_var,VAL_SEED,its samples' random seed)
	$(call help_var,VAL_TOL,its solver.tol at every I (empty: the shear policy's))
	$(call help_var,PRESSURE_P,pressures of campaign-pressure[-ladder])
	$(call help_var,PRESSURE_I,their inertial number)
	$(call help_var,VOLUME_PHI,packing fractions of campaign-volume (defaults below jamming: 2D or 3D))
	$(call help_var,VOLUME_RATE_TP,its shear rate in units of 1/t_p at P (shear.rate_tp: the nominal I))
	$(call help_var,CKPT_STRAIN,checkpoint every this much strain)
	$(call help_var,CKPT_WALL,and every this many seconds of wall clock)
	$(call help_var,PROGRESS,seconds of wall clock between the progress lines of a campaign run)
	$(call help_var,WINDOW,steady window of the fits: a:b (strain) or a%:b%; empty: detected)
	$(call help_var,CAMPAIGN,campaign of make campaign-list or campaign-status (inertial inertial-ladder cohesive ...))
	$(call help_var,RUN,run folder of make campaign-prep-of)
	$(call help_var,QUICK,1: the short version of accuracy-cost, tensile and compare-liggghts-shear)
	$(call help_var,BIG,1: make bench's 3D sizes up to 1e5)
	$(call help_var,PO_N,grains of make prep-overlap)
	$(call help_var,PO_DIR,its output folder)
	$(call help_var,FROZEN,make frozen-shear's folder)
	$(call help_var,FS_N,its grains)
	$(call help_var,FS_SHAPES,its shapes (polygon sides; 0: disks))
	$(call help_var,FS_STRAIN,strain of its I = 1e-2 runs)
	$(call help_var,FS_QS_STRAIN,strain of its I = 1e-3 runs)
	$(call help_var,FS_GAP,steps between its two dumped problems)
	$(call help_var,FS3_N,spheres of make frozen-shear3)
	$(call help_var,FS3_STRAIN,its strain at I = 1e-2 (the step dumped: the last))
	$(call help_var,ACC,make accuracy-shear's folder)
	$(call help_var,A3_DIR,make accuracy-shear3's folder)
	$(call help_var,A3_N,its spheres)
	$(call help_var,A3_SEEDS,its samples' particles.seed)
	$(call help_var,A3_I,the inertial number its settings continue at)
	$(call help_var,A3_SETTINGS,its settings (a3_set_<name> in the Makefile; the first is the reference))
	$(call help_var,A3_START,the strain at I = 0.01 of the common start)
	$(call help_var,A3_STRAIN,each setting's strain from there)
	$(call help_var,A3_W0,its window: continuation strain from)
	$(call help_var,ACC_N,its grains)
	$(call help_var,ACC_SHAPES,its shapes)
	$(call help_var,ACC_I,its inertial numbers)
	$(call help_var,ACC_STRAIN,its strain)
	$(call help_var,ACC_TOLS,its settings: solver.tol values)
	$(call help_var,ACC_RTOLS,solver.residual_tol values (at tol 1e-4))
	$(call help_var,ACC_CAPS,sweep caps (at tol 1e-4))
	$(call help_var,ACC_DTX,time step factors (at tol 1e-4))
	$(call help_var,ACC_REF_TOL,solver.tol of the reference)
	$(call help_var,ACC_REF_CAP,sweep cap of the reference)
	$(call help_var,REGRESS_DIR,make regress's 2D campaign)
	$(call help_var,REGRESS3_DIR,its 3D campaign)
	$(call help_var,FUZZ_BUILD,make fuzz's build folder (clang, sanitizers))
	$(call help_var,FUZZ_SECONDS,how long make fuzz runs each target)
	$(call help_var,FUZZ_TARGETS,its targets (one per reader))
	$(call help_var,FUZZ_RSS_MB,memory limit of each target (libFuzzer -rss_limit_mb))
	$(call help_var,MUTANTS,the mutants of make mutants (empty: all of tests/mutants/))

# Idempotent: asks dpkg which packages are missing and installs only those.
# $(call install_missing,TARGET,PACKAGES)
define install_missing
	@missing=$$(for p in $(2); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "make $(1): installing $$missing"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	else echo "make $(1): all Debian packages present"; fi
endef

deps:
	$(call install_missing,deps,$(DEB_PKGS))

# Quiet builds: no "Entering directory" pair from each of CMake's nested
# gmake calls (MAKEFLAGS reaches them), CMake's configure messages only when
# something is wrong, and no "Built target" line per target (the build prints
# one line per file compiled or linked).
MAKEFLAGS += --no-print-directory
$(BUILD)/CMakeCache.txt: | deps
	@echo "make: configuring $(BUILD)/ (CMake, Release)"
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DCMAKE_TARGET_MESSAGES=OFF --log-level=WARNING
# $(call build_only,TARGETS): build these CMake targets and what they need.
build_only = cmake --build $(BUILD) -j $(JOBS) $(addprefix --target ,$(1))

# Everything: the programs, the tests and the benchmarks.
build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# `make run` builds cdsim only (a third of `make build`); SET="--set k=v ..."
# adds scene overrides (cdsim --set, docs/scenes.md).
SET ?=
run: deps $(BUILD)/CMakeCache.txt
	$(call build_only,cdsim cdanalysis)
	$(BUILD)/cd/cdsim $(SCENE) --out $(OUT) $(SET)
	@echo ""
	@echo "Outputs in $(OUT)/: series.csv (time series, columns in docs/outputs.md), scene.toml"
	@echo "(resolved scene), shapes.pvd, particles.pvd, contacts.pvd, walls.pvd (VTK collections)."
	@echo "Open in ParaView:  paraview --script=$(OUT)/view.py   (grains and force chains, as the README's picture)"
	@$(BUILD)/analysis/cdanalysis draw $(OUT) > $(OUT)/picture.log 2>&1 && \
	  echo "Without ParaView: $$(sed -n 's/^picture: //p' $(OUT)/picture.log)   (last snapshot: grains and force chains)" || \
	  echo "No picture (cdanalysis draw failed: $(OUT)/picture.log)"

# After the suite, the tree is checked again (tests/check_tree.cmake): no
# test may leave a file in the sources (they write into the build folder).
test: build
	@git ls-files --others --exclude-standard > $(BUILD)/untracked-before.txt 2>/dev/null || : > $(BUILD)/untracked-before.txt
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900
	cmake -DROOT=$(CURDIR) -DBEFORE=$(BUILD)/untracked-before.txt -P tests/check_tree.cmake

# ---- The suite under sanitizers (tests/README.md; not part of make test) ----
# The programs and every test built with AddressSanitizer and
# UndefinedBehaviorSanitizer (CDLAB_SANITIZE: -O1, assertions on, no
# recovery) in their own folder, then ctest as make test runs it: the tests
# that run cdsim, cdproblem or cdanalysis run the sanitized ones of that
# folder. Every report aborts its process (SIGABRT, exit 134), which fails
# a test that checks the exit status. An ASan or LSan report of any process
# (a test, or a program it runs, whose stderr the test may keep to itself)
# also goes to a file in SANITIZE_BUILD/sanitizer-logs/; any such file
# fails the target, which prints them. UBSan's go to stderr only (GCC's
# runtime ignores UBSAN_OPTIONS' log_path when ASan is linked in). LeakSanitizer is on (it runs here);
# tests/lsan.supp holds its suppressions. Timeouts are 4 times make test's
# (tests/CMakeLists.txt). ThreadSanitizer is not offered: Debian's libgomp
# is not built with it, so every OpenMP barrier would be reported as a race.
SANITIZE_BUILD ?= build-sanitize
san_logs = $(abspath $(SANITIZE_BUILD))/sanitizer-logs
san_common = halt_on_error=1:abort_on_error=1:print_stacktrace=1
.PHONY: test-sanitize
test-sanitize: deps
	@[ -f $(SANITIZE_BUILD)/CMakeCache.txt ] || { echo "make test-sanitize: configuring $(SANITIZE_BUILD)/ (ASan, UBSan)"; \
	  cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Debug -DCDLAB_SANITIZE=ON -DCDLAB_BENCH=OFF \
	    -DCMAKE_TARGET_MESSAGES=OFF --log-level=WARNING; }
	nice -n 10 cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	@git ls-files --others --exclude-standard > $(SANITIZE_BUILD)/untracked-before.txt 2>/dev/null || : > $(SANITIZE_BUILD)/untracked-before.txt
	@rm -rf $(san_logs) && mkdir -p $(san_logs)
	cd $(SANITIZE_BUILD) && \
	  ASAN_OPTIONS=$(san_common):detect_leaks=1:log_path=$(san_logs)/asan \
	  UBSAN_OPTIONS=$(san_common):log_path=$(san_logs)/ubsan \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	  nice -n 10 ctest --output-on-failure -j $(JOBS) --timeout 3600; rc=$$?; \
	  if [ -n "$$(ls -A $(san_logs))" ]; then echo "make test-sanitize: sanitizer reports in $(san_logs):"; \
	    head -n 60 $(san_logs)/*; exit 1; fi; exit $$rc
	cmake -DROOT=$(CURDIR) -DBEFORE=$(SANITIZE_BUILD)/untracked-before.txt -P tests/check_tree.cmake

# docs/scene-parameters.md is generated: a fixed header, then exactly what
# `cdsim --help-scene` prints (tests/test_help_scene.cpp fails when they differ).
SCENE_DOC := docs/scene-parameters.md
scene-doc: deps $(BUILD)/CMakeCache.txt
	$(call build_only,cdsim)
	{ printf '%s\n' '# Scene parameters' '' \
	    'Every key a scene file may set: default, unit, rule and meaning. How scenes are' \
	    'written, and what the generated particles are: [scenes.md](scenes.md).' '' \
	    'Generated by `make scene-doc` from `cdsim --help-scene=md`; do not edit by hand' \
	    '(`tests/test_help_scene.cpp` checks that this file is what cdsim prints).' '' \
	    '<!-- cdsim --help-scene -->'; \
	  $(BUILD)/cd/cdsim --help-scene=md; } > $(SCENE_DOC).tmp && mv $(SCENE_DOC).tmp $(SCENE_DOC)

# ---- Figures (docs/figures/; not part of make test) -------------------------
# The README's pictures: the default scene's pile with its force chains, and
# the 3D pile (configs/pile3d.toml, ~10 min) cut in half with its chains,
# rendered by ParaView's pvbatch from the run's VTK files. Debian's ParaView
# renders through GLX only, hence xvfb. Its Python package python3-paraview
# conflicts with python3-vtk9, which libvtk9-dev (the build) depends on:
# installing it would remove libvtk9-dev, so it is unpacked into the build
# folder instead (apt-get download + dpkg -x), never installed.
FIG_PKGS := paraview xvfb xauth
FIG_RUN := $(BUILD)/figures/default
FIG_RUN3 := $(BUILD)/figures/pile3d
PVPY := $(BUILD)/figure-tools/pvpy
figures: build
	$(call install_missing,figures,$(FIG_PKGS))
	@if [ ! -d $(PVPY)/usr/lib/python3/dist-packages/paraview ]; then \
	  echo "make figures: unpacking python3-paraview into $(PVPY) (not installed: see the Makefile)"; \
	  mkdir -p $(PVPY) && cd $(dir $(PVPY)) && rm -f python3-paraview_*.deb && \
	  apt-get download python3-paraview && dpkg -x python3-paraview_*.deb pvpy; fi
	$(CDSIM) configs/default.toml --out $(FIG_RUN) --quiet --fresh
	mkdir -p docs/figures
	PYTHONPATH=$(abspath $(PVPY))/usr/lib/python3/dist-packages \
	  xvfb-run -a -s "-screen 0 1600x1200x24" pvbatch docs/figures/render.py $(FIG_RUN) docs/figures/force-chains.png
	$(CDSIM) configs/pile3d.toml --out $(FIG_RUN3) --quiet --fresh
	PYTHONPATH=$(abspath $(PVPY))/usr/lib/python3/dist-packages \
	  xvfb-run -a -s "-screen 0 1600x1200x24" pvbatch docs/figures/render3d.py $(FIG_RUN3) docs/figures/pile3d.png
	@dpkg-query -W -f='$${Status}\n' libvtk9-dev 2>/dev/null | grep -q '^install ok installed' || \
	  { echo "make figures: libvtk9-dev is no longer installed: run make deps"; exit 1; }

# Timings are comparable only with the machine named: machine.csv (CPU, cores,
# compiler, flags, load average) is written next to the results.
bench: build
	mkdir -p outputs/bench
	@awk -v n=$$(nproc) '$$1 > n / 2 { printf "make bench: load average %s on %d cores: times, above all the 2-thread ones, will be noisy\n", $$1, n }' /proc/loadavg
	$(BUILD)/cd/bench/cdbench --benchmark_out=outputs/bench/bench.json --benchmark_out_format=json --csv_dir=outputs/bench
	$(BUILD)/cd/bench/cdbench3 --out outputs/bench/3d $(if $(BIG),--big)

accuracy-cost: build
	$(BUILD)/cd/bench/accuracy_cost --out outputs/accuracy-cost $(if $(QUICK),--quick)
	$(BUILD)/cd/bench/accuracy_cost3 --out outputs/accuracy-cost/3d $(if $(QUICK),--quick)

# Cohesion against the time step (docs/accuracy.md, "Cohesion and the time step").
tensile: build
	$(BUILD)/cd/bench/tensile --out outputs/tensile $(if $(QUICK),--quick)

# ---- Overlaps of the preparation (docs/shear.md) ------------------------------
# The validation beside tests/test_prep_overlap.cpp's small hard cases: full
# preparations (configs/shear-prep.toml, cell sized for the grains) at N =
# PO_N, one thread each, run by cdsim into outputs/prep-overlap/<i>/. Each
# series row's max_overlap_small is the largest over the row's steps, so the
# check against 0.01 covers every step. About 10 (disks) to 25 (hexagons)
# CPU seconds each at 1000 (each stops when jammed: shear.settle_*). The
# mixture's small triangles spin fast next to large disks: its flow near
# jamming needs dt = 0.0125 t_p, and its cell approaches them slowly, so it
# gets a longer limit (docs/shear.md, "Small polygons among large grains").
PO_N ?= 1000
PO_DIR ?= outputs/prep-overlap
prep-overlap: build
	@i=0; for set in "particles.nsides=[0] particles.size_ratio=4" "particles.nsides=[6] particles.size_ratio=4" \
	            "particles.nsides=[3,6,0] particles.size_ratio=5 shear.dt_tp=0.0125 time.duration=0.06"; do \
	  i=$$((i + 1)); echo "== $$set"; \
	  OMP_NUM_THREADS=1 $(BUILD)/cd/cdsim configs/shear-prep.toml --out $(PO_DIR)/$$i --fresh --quiet \
	    --set particles.n=$(PO_N) --set shear.width=0 --set shear.height=0 \
	    $$(for kv in $$set; do printf -- '--set %s ' "$$kv"; done) | grep 'steps in' || exit 1; \
	  awk -F, 'NR == 1 { for (j = 1; j <= NF; ++j) if ($$j == "max_overlap_small") c = j; next } \
	    $$c > m { m = $$c; t = $$2 } END { printf "largest overlap %.3g of the smaller grain (t = %s s)\n", m, t; \
	    exit !(c && m <= 0.01) }' $(PO_DIR)/$$i/series.csv || { echo "prep-overlap: above 0.01"; exit 1; }; \
	done

# ---- Campaigns (docs/shear.md) ----------------------------------------------
# Each run is a make target whose product is its folder (marked complete by
# a .done file written after cdsim succeeds), so `make -j` runs campaigns in
# parallel, finished runs are skipped, and a killed run resumes from its
# checkpoint when made again. Every shear run starts from a compacted sample
# (prep/...) made once per size and shape. Each campaign folder and prep/
# hold a manifest.toml of the variables their runs were made with
# (cd/campaign/manifest.sh): make refuses, naming the difference, to add runs
# made with another N, STRAIN, P, ... to them (use another CAMPAIGNS folder,
# or remove it), before any run starts. `make campaign-status` tells each
# run's state, cost and ETA (cd/campaign/status.sh).
N        ?= 200
STRAIN   ?= 2
# The imposed pressure: 2D per length (N/m), 3D per area (N/m^2); the 3D
# value is 2D's read as a 1 mm thick layer, and so are the scenes'
# densities, so t_p = d sqrt(rho/p) is the same.
P        ?= $(if $(dim3),1e5,100)
PREP_SCENE  := configs/shear$(if $(dim3),3)-prep.toml
SHEAR_SCENE := configs/shear$(if $(dim3),3)-inertial.toml
INERTIAL_I ?= 0.001 0.003 0.01 0.03 0.1 0.3
COHESIVE_ETA ?= 0 1 10 100
COHESIVE_I ?= 0.01 0.1
# Cohesive networks converge slowly: the cohesive runs (and their eta = 0
# references) take the solver.tol of configs/shear-cohesive.toml, where its
# measurement is, as cdsim reads it; COHESIVE_TOL=x overrides it.
COHESIVE_TOL ?=
cohesive_tol = $(or $(COHESIVE_TOL),$(shell $(BUILD)/cd/cdsim configs/shear-cohesive.toml --print-scene \
  | awk '$$1 == "tol" { print $$3; exit }'))
ANGULAR_NS ?= 0 3 4 5 6 8 10 20 60
# DIM=3: the grains' shapes (particles.shape; sphere: spheres), one run each
ANGULAR_SHAPES ?= sphere tetrahedron cube octahedron dodecahedron icosahedron irregular
ANGULAR_I ?= 0.01
# Threads of each cdsim run: `make -jJ` runs J at once, so each gets nproc/J
# threads (at least 1; plain -j: 1); THREADS=n overrides. More threads than
# free cores make the solver's spinning barriers slow every run many-fold
# (28x measured: docs/accuracy.md, "Performance of a step"); results do not depend on it.
NPROC := $(shell nproc)
run_jobs = $(if $(filter -j,$(MAKEFLAGS)),$(NPROC),$(or $(patsubst -j%,%,$(filter -j%,$(MAKEFLAGS))),1))
run_threads = $(or $(THREADS),$(shell echo $$(( $(NPROC) / $(run_jobs) > 1 ? $(NPROC) / $(run_jobs) : 1 ))))
CDSIM = OMP_NUM_THREADS=$(run_threads) $(BUILD)/cd/cdsim
# The size law of the samples (docs/scenes.md): d_max/d_min and the
# distribution (uniform_area: equal area per size class, the seeds' choice;
# uniform: uniform in d). The preparation's cell is sized by cdsim from the
# actual size law (shear.width = shear.height = 0), so any ratio works as is.
SIZE_RATIO ?= 2
SIZE_DIST  ?= uniform_area
# The settings that depend on I (solver.tol and residual_tol, shear.dt_tp,
# shear.cell_mass) are not decided here: the shear scenes give them as
# "auto", and cdsim sets them from shear.inertial_number by one policy for
# single runs and campaigns alike (cd/src/scene/shear_policy.hpp; the
# measurements behind it: docs/shear.md, "Settings by I"). What a run at I
# will use, as its scene.toml will say: $(1) I, $(2) the key (e.g. dt_tp).
resolved = $(shell $(BUILD)/cd/cdsim $(SHEAR_SCENE) --set shear.inertial_number=$(1) --print-scene \
  | awk '$$1 == "$(2)" { print $$3; exit }')
# 100 series rows per unit strain, and a contact snapshot every 0.2 strain
# (fabric: cdanalysis fabric / report), by strain: cdsim turns them into
# steps at the run's own rate.
SERIES_BY_STRAIN = --set output.series_strain=0.01
SNAPSHOTS_BY_STRAIN = --set output.snapshot_strain=0.2
# Checkpoints every CKPT_STRAIN of shear strain and at most every CKPT_WALL
# seconds of wall clock (at the next series row), so that a kill loses little
# (docs/shear.md). Preparations have no strain: the wall clock alone.
CKPT_STRAIN ?= 0.1
CKPT_WALL ?= 300
# Each run prints one line of progress every PROGRESS seconds of wall clock
# (cdsim --progress: folder, step, share done, ETA), so that a campaign of
# hours is not silent until a run ends; output.quiet drops the terminal
# progress line, which two runs of make -j2 would garble.
PROGRESS ?= 300
CAMPAIGN_SET = --progress $(PROGRESS) --set output.quiet=true --set output.checkpoint_strain=$(CKPT_STRAIN) \
	  --set output.checkpoint_wall=$(CKPT_WALL)

inertial_runs   := $(foreach i,$(INERTIAL_I),$(CAMPAIGNS)/inertial/I_$(i))
cohesive_runs   := $(foreach e,$(COHESIVE_ETA),$(foreach i,$(COHESIVE_I),$(CAMPAIGNS)/cohesive/eta_$(e)_I_$(i)))
angularity_runs := $(if $(dim3),$(foreach s,$(ANGULAR_SHAPES),$(CAMPAIGNS)/angularity/shape_$(s)),\
  $(foreach n,$(ANGULAR_NS),$(CAMPAIGNS)/angularity/ns_$(n)))
walls_runs      := $(foreach n,$(ANGULAR_NS),$(CAMPAIGNS)/walls/ns_$(n))

.PHONY: campaign-inertial campaign-cohesive campaign-angularity campaign-walls campaign-list campaign-status programs
campaign-inertial: $(addsuffix /.done,$(inertial_runs))
campaign-cohesive: $(addsuffix /.done,$(cohesive_runs))
campaign-angularity: $(addsuffix /.done,$(angularity_runs))
campaign-walls: $(addsuffix /.done,$(walls_runs))
# The run folders of a campaign, one per line, and the sample a run starts
# from (configs/cluster/job-array.sh).
.PHONY: campaign-prep-of
campaign-list:
	@for r in $($(CAMPAIGN)_runs); do echo $$r; done
# make campaign-status [CAMPAIGN=<name>]: each run's state, cost and ETA
# (cd/campaign/status.sh), of CAMPAIGN or of every campaign in CAMPAIGNS.
inertial-ladder_runs = $(ladder_runs)
pressure-ladder_runs = $(pressure_ladder_runs)
status_campaigns = $(or $(CAMPAIGN),$(foreach c,inertial inertial-ladder cohesive angularity walls pressure pressure-ladder volume,\
  $(if $(wildcard $(CAMPAIGNS)/$(c)),$(c))))
prep_runs = $(CAMPAIGNS)/prep/ns_0 $(if $(filter angularity,$(status_campaigns)),$(filter-out %/ns_0,\
  $(foreach r,$(angularity_runs),$(CAMPAIGNS)/prep/$(notdir $(r)))))
campaign-status:
	@cd/campaign/status.sh $(CAMPAIGNS) $(foreach c,prep $(status_campaigns),$(call help_q,$(c)=$($(c)_runs)))
campaign-prep-of:
	@case "$(RUN)" in */angularity/ns_*|*/angularity/shape_*) echo $(CAMPAIGNS)/prep/$(notdir $(RUN))/.done ;; \
	  */walls/ns_*) echo programs ;; \
	  *) echo $(CAMPAIGNS)/prep/ns_0/.done ;; esac

# Products, never intermediates: make must not delete a sample when done.
.PRECIOUS: $(CAMPAIGNS)/prep/ns_%/.done

# What the runs need: the programs, not the tests and benchmarks.
programs: deps $(BUILD)/CMakeCache.txt
	$(call build_only,cdsim cdanalysis cdproblem)

# ---- Manifests: what made a campaign (docs/shear.md) ------------------------
# $(CAMPAIGNS)/<c>/.manifest-check (never a file: it runs on every make)
# compares the variables of campaign c's runs with <c>/manifest.toml, or
# writes it; every run rule of c has it as an order-only prerequisite, so a
# refusal comes before any run of the campaign starts. prep/ holds the
# samples' variables; each campaign's manifest has them too (a campaign
# folder tells alone what made it). Compared: what changes a finished run
# and is not in its folder's name; recorded: the values (I, eta, shapes, p)
# run so far, the tolerance policy, and the builds.
manifest_keys_prep :=
manifest_keys_inertial := STRAIN SHEAR_TOL SHEAR_SET
manifest_record_inertial := INERTIAL_I
# A ladder's points start from each other: its values are compared.
manifest_keys_inertial-ladder := LADDER_STRAIN SHEAR_TOL SHEAR_SET INERTIAL_I
manifest_keys_cohesive := STRAIN SHEAR_TOL SHEAR_SET COHESIVE_TOL
manifest_record_cohesive := COHESIVE_ETA COHESIVE_I
manifest_keys_angularity := STRAIN SHEAR_TOL SHEAR_SET ANGULAR_I
manifest_record_angularity := $(if $(dim3),ANGULAR_SHAPES,ANGULAR_NS)
manifest_keys_walls := STRAIN SHEAR_TOL SHEAR_SET ANGULAR_I
manifest_record_walls := ANGULAR_NS
manifest_keys_pressure := STRAIN SHEAR_TOL SHEAR_SET PRESSURE_I
manifest_record_pressure := PRESSURE_P
manifest_keys_pressure-ladder := LADDER_STRAIN SHEAR_TOL SHEAR_SET PRESSURE_I PRESSURE_P
manifest_keys_volume := STRAIN SHEAR_TOL SHEAR_SET VOLUME_RATE_TP
manifest_record_volume := VOLUME_PHI
sample_keys := DIM N P SIZE_RATIO SIZE_DIST PREP_SET
tolerance_policy = $(if $(SHEAR_TOL),solver.tol = $(SHEAR_TOL) and residual_tol = 0 for every run (SHEAR_TOL),by I: cdsim's shear policy (docs/shear.md, Settings by I))
make_dry = $(if $(findstring n,$(firstword -$(MAKEFLAGS))),1,0)
# `+`: checked under make -n too (which writes nothing). A static pattern
# rule: an implicit rule's product would be an intermediate file, which make
# does not make when the runs after it are done (so no refusal then).
manifest_checks := $(foreach c,prep inertial inertial-ladder cohesive angularity walls pressure pressure-ladder volume,\
  $(CAMPAIGNS)/$(c)/.manifest-check)
$(manifest_checks): $(CAMPAIGNS)/%/.manifest-check:
	+@cd/campaign/manifest.sh $(@D)/manifest.toml $(make_dry) \
	  $(foreach v,$(sample_keys) $(manifest_keys_$*),$(call help_q,$(v)=$($(v)))) \
	  -- $(foreach v,$(manifest_record_$*),$(call help_q,$(v)=$($(v)))) \
	  $(if $(filter prep,$*),,$(call help_q,tolerance=$(tolerance_policy)))
# The campaigns asked on the command line: checked before a sample is made.
goal_manifests = $(foreach c,$(filter-out list prep-of status,$(patsubst campaign-%,%,$(filter campaign-%,$(MAKECMDGOALS)))),$(CAMPAIGNS)/$(c)/.manifest-check)

# Compacted samples: disks (ns_0) or n-gons, N grains, isotropic at P,
# compacted at 0.01 / t_p (3D: spheres, at 0.05 / t_p) until jammed at p,
# the scenes' stop rule shear.settle_*; PREP_SET adds settings.
PREP_SET ?=
$(CAMPAIGNS)/prep/ns_%/.done: | programs $(CAMPAIGNS)/prep/.manifest-check $(goal_manifests)
	$(CDSIM) $(PREP_SCENE) --out $(@D) $(CAMPAIGN_SET) --set output.checkpoint_strain=0 \
	  --set output.snapshot_interval=0 \
	  --set particles.n=$(N) --set particles.nsides=[$*] --set shear.pressure=$(P) \
	  --set particles.size_ratio=$(SIZE_RATIO) --set particles.size_dist=$(SIZE_DIST) \
	  --set shear.width=0 --set shear.height=0 $(PREP_SET)
	touch $@

# SHEAR_TOL=x sets solver.tol = x alone (no law-residual stop) for every
# shear run, instead of the policy's tolerance.
SHEAR_TOL ?=
shear_solver = $(if $(SHEAR_TOL),--set solver.tol=$(SHEAR_TOL) --set solver.residual_tol=0)
# One shear run of every campaign (fresh, ladder, pressure series): $(1) I,
# $(2) the run folder it starts from, $(3) p, $(4) strain.
shear_cmd = $(CDSIM) $(SHEAR_SCENE) --out $(@D) $(CAMPAIGN_SET) $(shear_solver) \
	  --set shear.start='"$(2)/checkpoint.bin"' --set shear.pressure=$(3) \
	  --set shear.inertial_number=$(1) --set shear.strain=$(4) \
	  $(SERIES_BY_STRAIN) $(SNAPSHOTS_BY_STRAIN) \
	  $(SHEAR_SET)
# SHEAR_SET: more --set options for every shear run (e.g. --set solver.anderson=5).
SHEAR_SET ?=
# A fresh run: $(1) I, $(2) the shape (its compacted sample).
shear_run = $(call shear_cmd,$(1),$(CAMPAIGNS)/prep/ns_$(2),$(P),$(STRAIN)) --set particles.nsides=[$(2)]

$(CAMPAIGNS)/inertial/I_%/.done: $(CAMPAIGNS)/prep/ns_0/.done | $(CAMPAIGNS)/inertial/.manifest-check
	$(call shear_run,$*,0)
	touch $@

# The ladder (make campaign-inertial-ladder): the same values of I, run from
# the highest down, each point starting from the end state of the point above
# it (shear.start on a sheared run continues it: Lees-Edwards offset and cell
# rates kept, mean flow set to the new rate), the highest from the compacted
# sample. Each point's transient is short (the structure is already sheared)
# and cdanalysis detects the steady window as for fresh runs; LADDER_STRAIN
# (default STRAIN) may be shorter. Runs in inertial-ladder/, beside the fresh
# campaign, so that the two compare (docs/shear.md).
LADDER_STRAIN ?= $(STRAIN)
ladder_runs := $(foreach i,$(INERTIAL_I),$(CAMPAIGNS)/inertial-ladder/I_$(i))
# The point above I in INERTIAL_I sorted by value ("" for the highest).
ladder_above = $(shell printf '%s\n' $(INERTIAL_I) | sort -g | awk -v i=$(1) 'f { print; exit } $$1 == i { f = 1 }')
ladder_start = $(if $(call ladder_above,$(1)),$(CAMPAIGNS)/inertial-ladder/I_$(call ladder_above,$(1)),$(CAMPAIGNS)/prep/ns_0)
.PHONY: campaign-inertial-ladder
campaign-inertial-ladder: $(addsuffix /.done,$(ladder_runs))
.SECONDEXPANSION:
$(CAMPAIGNS)/inertial-ladder/I_%/.done: $$(call ladder_start,$$*)/.done | $(CAMPAIGNS)/inertial-ladder/.manifest-check
	$(call shear_cmd,$*,$(call ladder_start,$*),$(P),$(LADDER_STRAIN))
	touch $@

# The pressure series (make campaign-pressure, campaign-pressure-ladder): steady
# shear at PRESSURE_I under each p of PRESSURE_P, the critical-state
# compaction law e(p) of `cdanalysis fit compaction` (make analyze-pressure).
# Fresh runs start from the sample compacted at P (the cell finds each p);
# the ladder runs the values from the lowest p up, each from the end state of
# the point below (a loading path), the lowest from the sample. The time step
# is dt_tp in each run's own t_p = d sqrt(rho/p), so every run takes the
# same number of steps per unit strain.
PRESSURE_P ?= 10 30 100 300 1000
PRESSURE_I ?= 0.01
pressure_runs := $(foreach p,$(PRESSURE_P),$(CAMPAIGNS)/pressure/p_$(p))
pressure_ladder_runs := $(foreach p,$(PRESSURE_P),$(CAMPAIGNS)/pressure-ladder/p_$(p))
pressure_below = $(shell printf '%s\n' $(PRESSURE_P) | sort -gr | awk -v p=$(1) 'f { print; exit } $$1 == p { f = 1 }')
pressure_start = $(if $(call pressure_below,$(1)),$(CAMPAIGNS)/pressure-ladder/p_$(call pressure_below,$(1)),$(CAMPAIGNS)/prep/ns_0)
pressure_run = $(call shear_cmd,$(PRESSURE_I),$(2),$(1),$(3))
.PHONY: campaign-pressure campaign-pressure-ladder
campaign-pressure: $(addsuffix /.done,$(pressure_runs))
campaign-pressure-ladder: $(addsuffix /.done,$(pressure_ladder_runs))
$(CAMPAIGNS)/pressure/p_%/.done: $(CAMPAIGNS)/prep/ns_0/.done | $(CAMPAIGNS)/pressure/.manifest-check
	$(call pressure_run,$*,$(CAMPAIGNS)/prep/ns_0,$(STRAIN))
	touch $@
$(CAMPAIGNS)/pressure-ladder/p_%/.done: $$(call pressure_start,$$*)/.done | $(CAMPAIGNS)/pressure-ladder/.manifest-check
	$(call pressure_run,$*,$(call pressure_start,$*),$(LADDER_STRAIN))
	touch $@

# The volume series (make campaign-volume): steady shear at imposed volume
# (shear.control = "volume": the cell's lengths held, p and I measured) at
# each packing fraction of VOLUME_PHI, every run from the sample compacted at
# P, its cell scaled to that fraction (shear.volume_fraction). The rate is
# given in units of 1/t_p, t_p = d sqrt(rho/P) (shear.rate_tp): cdsim turns
# it into 1/s and chooses the "auto" settings at the nominal I =
# VOLUME_RATE_TP, so the campaign at another P takes the same steps and
# settings. The defaults lie below jamming, where the measured phi(I) of
# the reference campaigns put I at about 0.2 (2D; 3D 0.3) down to 0.04
# (docs/shear.md, "Volume series"); VOLUME_RATE_TP is about the smallest of
# those I, so that the step (0.05 t_p at P) stays within 0.05 of the t_p of
# the pressure each run measures.
VOLUME_PHI ?= $(if $(dim3),0.55 0.56 0.57 0.58 0.59,0.76 0.77 0.78 0.79 0.8)
VOLUME_RATE_TP ?= 0.03
volume_runs := $(foreach f,$(VOLUME_PHI),$(CAMPAIGNS)/volume/phi_$(f))
.PHONY: campaign-volume
campaign-volume: $(addsuffix /.done,$(volume_runs))
$(CAMPAIGNS)/volume/phi_%/.done: $(CAMPAIGNS)/prep/ns_0/.done | $(CAMPAIGNS)/volume/.manifest-check
	$(call shear_run,0,0) --set shear.control='"volume"' --set shear.rate_tp=$(VOLUME_RATE_TP) \
	  --set shear.volume_fraction=$*
	touch $@

# eta_<eta>_I_<I>: f_a = eta p d (3D: eta p d^2); eta = 0 are the reference runs of the fit.
$(CAMPAIGNS)/cohesive/eta_%/.done: $(CAMPAIGNS)/prep/ns_0/.done | $(CAMPAIGNS)/cohesive/.manifest-check
	$(call shear_run,$(lastword $(subst _I_, ,$*)),0) --set contact.cohesion_number=$(firstword $(subst _I_, ,$*)) \
	  --set solver.tol=$(cohesive_tol)
	touch $@

$(CAMPAIGNS)/angularity/ns_%/.done: $(CAMPAIGNS)/prep/ns_%/.done | $(CAMPAIGNS)/angularity/.manifest-check
	$(if $(dim3),@echo "ns_$*: polygons are 2D; DIM=3 runs the shapes of ANGULAR_SHAPES"; exit 2)
	$(call shear_run,$(ANGULAR_I),$*)
	touch $@

# DIM=3: shape_<s> is a sample of grains of particles.shape = s (the
# sphere's: spheres), compacted as the spheres' samples are, then sheared
# at ANGULAR_I as every 3D run (the shear policy at I; the sample gives the
# shapes, so the shear names none).
shape_set = $(if $(filter-out sphere,$(1)),--set particles.shape='"$(1)"')
$(CAMPAIGNS)/prep/shape_%/.done: | programs $(CAMPAIGNS)/prep/.manifest-check $(goal_manifests)
	$(if $(dim3),,@echo "shape_$*: polyhedra are 3D (DIM=3)"; exit 2)
	$(CDSIM) $(PREP_SCENE) --out $(@D) $(CAMPAIGN_SET) --set output.checkpoint_strain=0 \
	  --set output.snapshot_interval=0 $(call shape_set,$*) \
	  --set particles.n=$(N) --set shear.pressure=$(P) \
	  --set particles.size_ratio=$(SIZE_RATIO) --set particles.size_dist=$(SIZE_DIST) \
	  --set shear.width=0 --set shear.height=0 $(PREP_SET)
	touch $@
.PRECIOUS: $(CAMPAIGNS)/prep/shape_%/.done
$(CAMPAIGNS)/angularity/shape_%/.done: $(CAMPAIGNS)/prep/shape_%/.done | $(CAMPAIGNS)/angularity/.manifest-check
	$(if $(dim3),,@echo "shape_$*: polyhedra are 3D (DIM=3)"; exit 2)
	$(call shear_cmd,$(ANGULAR_I),$(CAMPAIGNS)/prep/shape_$*,$(P),$(STRAIN))
	touch $@

# The walls protocol (docs/shear.md): N grains of each shape placed loose
# between two rough walls in a cell sized for them (shear.width = height =
# 0: about as wide as tall once compacted), the top wall at P compacting
# them as it starts to shear at ANGULAR_I; no sample to start from. The
# solver settings are the shear policy's at I, as the periodic runs' (the
# "auto" keys of configs/shear-inertial.toml; SHEAR_TOL overrides them).
walls_policy = --set solver.tol=auto --set solver.residual_tol=auto --set contact.overlap_projection=auto \
	  --set solver.anderson=auto --set shear.dt_tp=auto --set shear.cell_mass=auto
$(CAMPAIGNS)/walls/ns_%/.done: | programs $(CAMPAIGNS)/walls/.manifest-check $(goal_manifests)
	$(if $(dim3),@echo "campaign-walls is 2D only (the 3D cell has no walls protocol)"; exit 2)
	$(CDSIM) configs/shear-walls.toml --out $(@D) $(CAMPAIGN_SET) $(walls_policy) $(shear_solver) \
	  --set particles.n=$(N) --set particles.nsides=[$*] --set particles.size_ratio=$(SIZE_RATIO) \
	  --set particles.size_dist=$(SIZE_DIST) --set shear.width=0 --set shear.height=0 \
	  --set shear.pressure=$(P) --set shear.inertial_number=$(ANGULAR_I) --set shear.strain=$(STRAIN) \
	  --set time.duration=0 --set output.snapshot_interval=0 \
	  $(SERIES_BY_STRAIN) $(SNAPSHOTS_BY_STRAIN) $(SHEAR_SET)
	touch $@

# ---- Validation: the angularity study -----------------------------------------
# The polygon study of Azema, Estrada & Radjai (PRE 86, 041301, 2012):
# regular polygons of VAL_NS sides and disks (0), circumscribed diameters
# d_max/d_min = 4 with equal area per size class, mu_p = 0.4, e = 0, sheared
# at I = VAL_I to strain VAL_STRAIN in the bi-periodic Lees-Edwards cell at
# imposed p, one campaign folder per protocol under VALIDATE (prep/, the
# compacted samples; angularity/, the shear runs), resumable like every
# campaign (make -j, checkpoints, manifests, campaign-status with
# CAMPAIGNS=$(VALIDATE)). N = 1000: the smallest N the study's fits are
# read at, and what one 2-core machine shears to strain 3 at I = 1e-3 in a
# few CPU hours a shape.
VALIDATE ?= outputs/validation
VAL_N ?= 1000
VAL_NS ?= 0 6 3 4 5 7 8 10 12 20 60
VAL_I ?= 0.001
VAL_STRAIN ?= 3
# VAL_SEED: another sample of the same protocol (the sizes and positions'
# random seed; 1, the committed tables', adds no setting).
VAL_SEED ?= 1
# VAL_TOL: one solver stop at every VAL_I, solver.tol = VAL_TOL with no
# law-residual stop and the overlap projection 0.5 (0.0003: the campaign's
# at I = 1e-3, for the I probe); empty: the shear policy's stop at VAL_I.
VAL_TOL ?=
val_vars = CAMPAIGNS=$(VALIDATE) DIM=2 N=$(VAL_N) SIZE_RATIO=4 SIZE_DIST=uniform_area STRAIN=$(VAL_STRAIN) \
  ANGULAR_NS="$(VAL_NS)" ANGULAR_I=$(VAL_I) SHEAR_TOL=$(VAL_TOL) \
  SHEAR_SET="$(if $(VAL_TOL),--set contact.overlap_projection=0.5)" \
  PREP_SET="$(if $(filter-out 1,$(VAL_SEED)),--set particles.seed=$(VAL_SEED))"
.PHONY: validate-angularity validate-angularity-walls
validate-angularity: programs
	+$(MAKE) --no-print-directory $(val_vars) campaign-angularity
# The same shapes, N, I and strain under the study's own protocol, between
# rough walls (campaign-walls), into $(VALIDATE)/walls.
validate-angularity-walls: programs
	+$(MAKE) --no-print-directory $(val_vars) campaign-walls
# The committed tables of both (tests/data/validation/README.md): a row per
# finished run, the same window for every shape (strain 1 to VAL_STRAIN).
.PHONY: validation-tables
# Each table's fits of mu*(alpha) and nu*(alpha) are stored beside it
# (angularity-<protocol>-fits.toml) once it has 3 shapes.
validation-tables: programs
	for p in periodic walls; do t=$(VALIDATION_DATA)/angularity-$$p.csv; \
	  cd/campaign/validation_table.sh $(CDA) $$p $(VALIDATE) 1:$(VAL_STRAIN) > $$t.tmp && mv $$t.tmp $$t || \
	  { rm -f $$t.tmp; exit 1; }; \
	  [ $$(wc -l < $$t) -lt 4 ] || { $(CDA) fit angularity --table $$t --toml $(VALIDATION_DATA)/angularity-$$p-fits.toml \
	    > /dev/null; s=$$?; [ $$s -eq 0 ] || [ $$s -eq 5 ] || exit 1; }; done
VALIDATION_DATA := tests/data/validation
# The committed tables refitted and compared with their stored fits, as make
# regress compares its campaigns' (cdanalysis compare-fits); the same data
# refitted, a parameter fails when it moved by 1 % of its combined standard
# uncertainty. make test runs the same check (ValidationData.*).
VALIDATE_CHECK ?= outputs/validate-check
.PHONY: validate-check
validate-check: programs
	@mkdir -p $(VALIDATE_CHECK)
	@for f in $(VALIDATION_DATA)/angularity-*-fits.toml; do t=$${f%-fits.toml}.csv; \
	  echo "validate-check: $$t against $$f"; \
	  $(CDA) fit angularity --table $$t --toml $(VALIDATE_CHECK)/$$(basename $$f) > /dev/null; s=$$?; \
	  { [ $$s -eq 0 ] || [ $$s -eq 5 ]; } && \
	  $(CDA) compare-fits $$f $(VALIDATE_CHECK)/$$(basename $$f) --tol-sigma 0.01 || exit 1; done

# ---- Frozen dense-shear problems (tests/data/frozen-shear) -------------------
# Steady bi-periodic shear of N disks (ns_0) and hexagons (ns_6) at p = P,
# the campaign protocol (prep, then shear at imposed p and I), and the contact
# problems of a few steps dumped with --dump-problem (.cdp: exact replay by
# cdproblem / cd/bench/solvers). I = 1e-2 is sheared from the compacted sample
# for FS_STRAIN (steady beyond strain 0.1: mu*, nu and z without trend, see the
# README of tests/data/frozen-shear); I = 1e-3 is
# sheared for FS_QS_STRAIN only (20 000 steps per unit strain at dt = 0.05 t_p
# would take hours on 2 cores), from the compacted sample: NOT steady, the
# start of the shear. (Starting it from the I = 1e-2 sample fails the start
# check: two grains across the Lees-Edwards boundary overlap by 0.08 d > 0.05 d;
# shear.start resets the strain, probably with it the images' offset: not
# investigated here.) The steps dumped are
# the last one and the one FS_GAP steps before. N = 1000 is committed
# (tests/data/frozen-shear); make frozen-shear FS_N=10000 regenerates larger
# ones into $(FROZEN)/N_10000 (hours). The shear runs solve at tol 1e-4
# alone, cap 2000 (the settings the committed problems were dumped with, not
# the policy's), at the policy's time step: the dumped problems are theirs.
FROZEN ?= outputs/frozen-shear
FS_N ?= 1000
FS_SHAPES ?= 0 6
FS_STRAIN ?= 0.5
FS_QS_STRAIN ?= 0.02
FS_GAP ?= 50
.PHONY: frozen-shear frozen-shear-runs
frozen-shear: build
	$(MAKE) --no-print-directory -j $(JOBS) CAMPAIGNS=$(FROZEN)/N_$(FS_N) N=$(FS_N) \
	  frozen-shear-runs
	@ls -l $(FROZEN)/N_$(FS_N)/frozen/*/*/problem_*.cdp
frozen-shear-runs: $(foreach s,$(FS_SHAPES),$(foreach i,0.01 0.001,$(CAMPAIGNS)/frozen/ns_$(s)/I_$(i)/.done))
frozen_run = $(CDSIM) configs/shear-inertial.toml --out $(@D) $(CAMPAIGN_SET) --fresh \
	  --set shear.start='"$(3)"' --set shear.pressure=$(P) --set particles.nsides=[$*] \
	  --set shear.inertial_number=$(1) --set shear.strain=$(2) --set solver.tol=1e-4 --set solver.residual_tol=0 \
	  --set solver.anderson=0 $(SERIES_BY_STRAIN) --set output.snapshot_interval=0 \
	  --dump-problem last-$(FS_GAP) --dump-problem last
.PRECIOUS: $(CAMPAIGNS)/frozen/ns_%/I_0.01/.done
$(CAMPAIGNS)/frozen/ns_%/I_0.01/.done: $(CAMPAIGNS)/prep/ns_%/.done
	$(call frozen_run,0.01,$(FS_STRAIN),$(CAMPAIGNS)/prep/ns_$*/checkpoint.bin)
	touch $@
$(CAMPAIGNS)/frozen/ns_%/I_0.001/.done: $(CAMPAIGNS)/prep/ns_%/.done
	$(call frozen_run,0.001,$(FS_QS_STRAIN),$(CAMPAIGNS)/prep/ns_$*/checkpoint.bin)
	touch $@

# ---- A frozen 3D dense-shear step (tests/data/frozen-shear3) -----------------
# FS3_N spheres compacted by the 3D campaign's preparation (configs/
# shear3-prep.toml at p = 1e5 N/m^2, until jammed), then sheared at I = 1e-2
# under cdsim's own policy for that I (solver.tol 1e-3, dt 0.05 t_p: the
# steps a 3D campaign run at I = 1e-2 solves) for FS3_STRAIN, and the last
# step's contact problem dumped (.cdp3, exact replay). tests/test_frozen_shear3
# solves the committed one (gzipped; how it was made: the README there).
FS3_N ?= 500
FS3_STRAIN ?= 0.5
.PHONY: frozen-shear3 frozen-shear3-run
frozen-shear3:
	$(MAKE) --no-print-directory DIM=3 CAMPAIGNS=$(FROZEN)/3d/N_$(FS3_N) N=$(FS3_N) frozen-shear3-run
	@ls -l $(FROZEN)/3d/N_$(FS3_N)/frozen3/I_0.01/problem_*.cdp3
frozen-shear3-run: $(CAMPAIGNS)/frozen3/I_0.01/.done
$(CAMPAIGNS)/frozen3/I_0.01/.done: $(CAMPAIGNS)/prep/ns_0/.done
	$(call shear_cmd,0.01,$(CAMPAIGNS)/prep/ns_0,$(P),$(FS3_STRAIN)) --fresh --set output.snapshot_strain=0 --set output.snapshot_interval=0 \
	  --set solver.subspace=0 --dump-problem last
	touch $@

# ---- Accuracy against cost in steady shear -----------------------------------
# The campaign protocol (one compacted sample per shape, then shear at imposed
# p and I) run under several solver settings from the same sample, and a
# table of what each setting gives (steady mu* = q/p, packing fraction, z,
# with their error bars) and costs (wall and CPU time, sweeps per step, share
# of steps at the cap), each against the tightest setting of its (shape, I):
# cd/bench/accuracy_shear.sh writes $(ACC)/table.csv and table.md. Settings:
#   tol_<t>     solver.tol = t (the rms |dp|/mean|p| test), cap 2000
#   rt_<r>      solver.tol = 1e-4 and solver.residual_tol = r, cap 2000
#   cap_<n>     solver.tol = 1e-4, cap n
#   dtx_<f>     solver.tol = 1e-4, cap 2000, the campaign's time step times f
#   ref         solver.tol = ACC_REF_TOL, cap ACC_REF_CAP (the reference)
# Defaults are the affordable study (disks, N = 500, I = 1e-2 and 1e-1);
# ACC_N=1000 ACC_SHAPES="0 6" ACC_I="0.001 0.01 0.1" is the full one (days).
ACC_N ?= 500
ACC_SHAPES ?= 0
ACC_I ?= 0.01 0.1
ACC_TOLS ?= 1e-2 1e-3 1e-4
ACC_RTOLS ?= 3e-3
ACC_CAPS ?= 500
ACC_DTX ?= 0.5 2
ACC_REF_TOL ?= 1e-5
ACC_REF_CAP ?= 10000
ACC_STRAIN ?= 3
ACC ?= outputs/accuracy-shear/N_$(ACC_N)
acc_settings := $(addprefix tol_,$(ACC_TOLS)) $(addprefix rt_,$(ACC_RTOLS)) $(addprefix cap_,$(ACC_CAPS)) \
  $(addprefix dtx_,$(ACC_DTX)) ref
acc_runs := $(foreach s,$(ACC_SHAPES),$(foreach i,$(ACC_I),$(foreach k,$(acc_settings),$(ACC)/ns_$(s)/I_$(i)/$(k))))
acc_solver = $(strip --set solver.residual_tol=0 \
  $(if $(filter ref,$(2)),--set solver.tol=$(ACC_REF_TOL) --set solver.max_iter=$(ACC_REF_CAP)) \
  $(if $(filter tol_%,$(2)),--set solver.tol=$(patsubst tol_%,%,$(2))) \
  $(if $(filter rt_%,$(2)),--set solver.tol=1e-4 --set solver.residual_tol=$(patsubst rt_%,%,$(2))) \
  $(if $(filter cap_%,$(2)),--set solver.tol=1e-4 --set solver.max_iter=$(patsubst cap_%,%,$(2))) \
  $(if $(filter dtx_%,$(2)),--set solver.tol=1e-4 \
    --set shear.dt_tp=$(shell awk 'BEGIN { printf "%.4g", $(patsubst dtx_%,%,$(2)) * $(call resolved,$(1),dt_tp) }')))
.PHONY: accuracy-shear accuracy-shear-runs
accuracy-shear: build
	$(MAKE) --no-print-directory CAMPAIGNS=$(ACC) N=$(ACC_N) accuracy-shear-runs
	cd/bench/accuracy_shear.sh $(CDA) $(ACC)
accuracy-shear-runs: $(addsuffix /.done,$(acc_runs))
define acc_rule
$(ACC)/ns_$(1)/I_$(2)/$(3)/.done: $(ACC)/prep/ns_$(1)/.done
	$$(call shear_run,$(2),$(1)) --set shear.strain=$(ACC_STRAIN) $$(call acc_solver,$(2),$(3))
	touch $$@
endef
$(foreach s,$(ACC_SHAPES),$(foreach i,$(ACC_I),$(foreach k,$(acc_settings),$(eval $(call acc_rule,$(s),$(i),$(k))))))

# ---- Three samples against a tight reference, 3D ----------------------------
# make accuracy-shear3 [A3_SEEDS="11 12 13"] [A3_I=0.01] [A3_SETTINGS=...] [A3_STRAIN=1]
# For each seed: a sample of A3_N spheres (configs/shear3-prep.toml,
# particles.seed), sheared at I = 0.01 at the policy's settings to
# gamma = A3_START (the common start: the steady state every setting
# continues, so that the settings differ only in the solver); then each
# setting of A3_SETTINGS continues it at I = A3_I for A3_STRAIN, one thread.
# cd/bench/accuracy_shear3.py prints (and writes to A3_DIR/table.md) per
# setting the mean over samples of mu, phi, z over continuation strain >=
# A3_W0, +- the standard error over samples, the difference to the first
# setting in combined errors, CPU per unit strain, sweeps a step, capped
# steps, the largest overlap and law residual. Settings (a3_set_<name>):
a3_set_ref    := --set solver.tol=1e-4 --set solver.residual_tol=3e-3 --set solver.max_iter=5000 --set solver.subspace=0
a3_set_policy :=
a3_set_plain  := --set solver.subspace=0
a3_set_anderson := --set solver.subspace=0 --set solver.anderson=5
a3_set_anderson7e-4 := --set solver.subspace=0 --set solver.anderson=5 --set solver.tol=7e-4
a3_set_mid    := --set solver.tol=2e-3 --set solver.subspace=0 --set solver.anderson=5 --set contact.overlap_projection=0.5
a3_set_fast   := --set solver.tol=3e-3 --set solver.subspace=0 --set solver.anderson=5 --set contact.overlap_projection=0.5
a3_set_anderson1e-3 := --set solver.tol=1e-3 --set solver.subspace=0 --set solver.anderson=5 --set contact.overlap_projection=0.5 --set solver.max_iter=600
# ref is plain NLGS; policy is the 3D scene's own (the subspace correction
# at the band's subspace stop), plain the same policy without it, anderson
# Anderson's mixing at the band's Anderson stop. 1000 spheres, 3 seeds,
# I = 0.01, the five settings: ~2 CPU hours, most of it the reference's
# (docs/accuracy.md, "1000 spheres (make accuracy-shear3)").
A3_N ?= 1000
A3_SEEDS ?= 11 12 13
A3_I ?= 0.01
A3_SETTINGS ?= ref policy anderson plain fast
A3_START ?= 0.5
A3_STRAIN ?= 1
A3_W0 ?= 0.1
A3_DIR ?= outputs/accuracy-shear3/N_$(A3_N)
a3_cmd = OMP_NUM_THREADS=1 $(BUILD)/cd/cdsim $(1) --out $(@D) --fresh --set output.quiet=true --set output.snapshot_interval=0
# A series row every t_p: strain I ($(2)) at the run's I.
a3_shear = $(call a3_cmd,configs/shear3-inertial.toml) --set shear.start='"$(1)/checkpoint.bin"' --set shear.pressure=1e5 \
  --set output.series_strain=$(2) --set shear.inertial_number=$(2)
.PHONY: accuracy-shear3 accuracy-shear3-runs
accuracy-shear3: programs
	$(MAKE) --no-print-directory accuracy-shear3-runs
	/usr/bin/python3 cd/bench/accuracy_shear3.py $(A3_DIR)/I_$(A3_I) $(A3_W0) $(A3_SETTINGS)
accuracy-shear3-runs: $(foreach s,$(A3_SEEDS),$(foreach k,$(A3_SETTINGS),$(A3_DIR)/I_$(A3_I)/s$(s)/$(k)/.done))
.PRECIOUS: $(A3_DIR)/prep/s%/.done $(A3_DIR)/start/s%/.done
$(A3_DIR)/prep/s%/.done:
	rm -rf $(@D)
	$(call a3_cmd,configs/shear3-prep.toml) --set particles.n=$(A3_N) --set particles.seed=$*
	touch $@
$(A3_DIR)/start/s%/.done: $(A3_DIR)/prep/s%/.done
	rm -rf $(@D)
	$(call a3_shear,$(A3_DIR)/prep/s$*,0.01) --set shear.strain=$(A3_START)
	touch $@
define a3_rule
$(A3_DIR)/I_$(A3_I)/s$(1)/$(2)/.done: $(A3_DIR)/start/s$(1)/.done
	rm -rf $$(@D)
	$$(call a3_shear,$(A3_DIR)/start/s$(1),$(A3_I)) --set shear.strain=$(A3_STRAIN) $$(a3_set_$(2))
	touch $$@
endef
$(foreach s,$(A3_SEEDS),$(foreach k,$(A3_SETTINGS),$(eval $(call a3_rule,$(s),$(k)))))

# Campaign analyses: the report of outputs/campaigns/<name> (made by the
# campaign-* targets) into outputs/analysis/<name>/, plus the campaign's fits.
CDA := $(BUILD)/analysis/cdanalysis
ANALYSIS := outputs/analysis$(if $(dim3),3d)

# WINDOW=a:b (strain) or a%:b% (of each run's span, e.g. 50%:100%) fixes the
# steady window of the fits (cdanalysis --window); default: detected per run.
fit_window = $(if $(WINDOW),--window $(WINDOW))
# Each target runs the report and every fit through analysis/analyze.sh,
# whatever the others gave: runs without a steady window are left out and
# named, undetermined fits are written and flagged, and the target fails
# only when no fit could be written (docs/analysis.md, "Campaign analyses").
ANALYZE := analysis/analyze.sh
analyze-inertial: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/inertial --out $(ANALYSIS)/inertial" \
	  "$(CDA) fit mu-i $(CAMPAIGNS)/inertial $(fit_window) --out $(ANALYSIS)/inertial/mu_I --toml $(ANALYSIS)/inertial/mu_i.toml" \
	  "$(CDA) fit nu-i $(CAMPAIGNS)/inertial $(fit_window) --out $(ANALYSIS)/inertial/nu_i --toml $(ANALYSIS)/inertial/nu_i.toml" \
	  $(if $(dim3),,"$(CDA) fit dilatancy $(CAMPAIGNS)/inertial $(fit_window) --out $(ANALYSIS)/inertial/dilatancy --toml $(ANALYSIS)/inertial/dilatancy.toml")

# The eta = 0 reference runs (eta_0_I_*) must be in the cohesive campaign.
analyze-cohesive: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/cohesive --out $(ANALYSIS)/cohesive" \
	  "$(CDA) fit cohesion $(CAMPAIGNS)/cohesive $(fit_window) --out $(ANALYSIS)/cohesive/cohesion --toml $(ANALYSIS)/cohesive/cohesion.toml"

analyze-pressure analyze-pressure-ladder: analyze-%: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/$* --out $(ANALYSIS)/$*" \
	  "$(CDA) fit compaction $(CAMPAIGNS)/$* $(fit_window) --out $(ANALYSIS)/$*/compaction --toml $(ANALYSIS)/$*/compaction.toml"

# Volume series: p and I measured at each phi; mu(I) and phi(I) as from the
# pressure-controlled campaigns (fit nu-i fits phi = phi_c - a I with phi exact).
.PHONY: analyze-volume
analyze-volume: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/volume --out $(ANALYSIS)/volume" \
	  "$(CDA) fit mu-i $(CAMPAIGNS)/volume $(fit_window) --out $(ANALYSIS)/volume/mu_I --toml $(ANALYSIS)/volume/mu_i.toml" \
	  "$(CDA) fit nu-i $(CAMPAIGNS)/volume $(fit_window) --out $(ANALYSIS)/volume/nu_i --toml $(ANALYSIS)/volume/nu_i.toml"

analyze-inertial-ladder: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/inertial-ladder --out $(ANALYSIS)/inertial-ladder" \
	  "$(CDA) fit mu-i $(CAMPAIGNS)/inertial-ladder $(fit_window) --out $(ANALYSIS)/inertial-ladder/mu_I --toml $(ANALYSIS)/inertial-ladder/mu_i.toml" \
	  "$(CDA) fit nu-i $(CAMPAIGNS)/inertial-ladder $(fit_window) --out $(ANALYSIS)/inertial-ladder/nu_i --toml $(ANALYSIS)/inertial-ladder/nu_i.toml"

analyze-angularity: build
	@$(ANALYZE) "$(CDA) report $(CAMPAIGNS)/angularity --out $(ANALYSIS)/angularity" \
	  "$(CDA) fit angularity $(CAMPAIGNS)/angularity $(fit_window) --out $(ANALYSIS)/angularity/fit --toml $(ANALYSIS)/angularity/mu_alpha.toml"

# Regression of fitted curves: re-runs the small reference campaigns of
# tests/data/regress/ (2D: 100 disks) and tests/data/regress3d/ (3D: 200
# spheres, I = 0.02 ... 1) from scratch (same sizes and seed; 2D ~1 min on 2
# cores; 3D took 25 min of wall time one run at a time at load 5-6),
# fits mu(I) and compares with the stored fits: a parameter fails when it
# moved by more than 3 combined standard uncertainties (cdanalysis
# compare-fits). The simulator is deterministic, so an unchanged code gives
# the same numbers; a change of the physics or numerics shows up here.
REGRESS_DIR ?= outputs/regress
REGRESS_I := 0.01 0.02 0.05 0.1 0.2 0.3 0.4
REGRESS3_DIR ?= outputs/regress3d
REGRESS3_I := 0.02 0.05 0.1 0.2 0.3 0.5 1
.PHONY: regress regress-campaign regress3-campaign
regress: regress-campaign regress3-campaign
	$(CDA) fit mu-i $(REGRESS_DIR)/inertial --window 1:3 --toml $(REGRESS_DIR)/mu_i.toml
	$(CDA) compare-fits tests/data/regress/mu_i.toml $(REGRESS_DIR)/mu_i.toml --tol-sigma 3
	$(CDA) fit mu-i $(REGRESS3_DIR)/inertial --window 1:3 --toml $(REGRESS3_DIR)/mu_i.toml
	$(CDA) compare-fits tests/data/regress3d/mu_i.toml $(REGRESS3_DIR)/mu_i.toml --tol-sigma 3
regress-campaign: build
	rm -rf $(REGRESS_DIR)
	$(MAKE) --no-print-directory -j $(JOBS) campaign-inertial DIM=2 CAMPAIGNS=$(REGRESS_DIR) N=100 STRAIN=3 P=100 SHEAR_TOL=1e-4 \
	  INERTIAL_I="$(REGRESS_I)"
regress3-campaign: build
	rm -rf $(REGRESS3_DIR)
	$(MAKE) --no-print-directory -j $(JOBS) campaign-inertial DIM=3 CAMPAIGNS=$(REGRESS3_DIR) N=200 STRAIN=3 P=1e5 SHEAR_TOL=1e-4 \
	  INERTIAL_I="$(REGRESS3_I)"

# Mutation score (not part of make test): each tests/mutants/*.mut is a
# deliberate physics bug applied alone to a scratch copy of the sources in
# $(BUILD)/mutants/ (its own build, ccache), with the test executables it names;
# prints killed / survived / stale (anchor no longer in the code) and the
# score, fails unless every mutant is killed (tests/mutants/README.md).
MUTANTS ?=
.PHONY: mutants
mutants: deps
	nice -n 5 tests/mutants/run.sh $(BUILD)/mutants $(MUTANTS)

clean:
	rm -rf $(BUILD)

# ---- Fuzzing (docs/errors.md, "Fuzzing"; not part of make test) ------------
# Coverage-guided fuzzing of every reader under AddressSanitizer and
# UndefinedBehaviorSanitizer: libFuzzer from Debian's clang, in its own build
# folder (CDLAB_FUZZ, tests/fuzz/). Each target runs FUZZ_SECONDS on its
# corpus ($(FUZZ_BUILD)/corpus/<target>/, kept between runs), seeded from the
# repository's inputs and a short 2D and 3D run (checkpoints, dumped steps)
# and from the committed regression inputs (tests/data/fuzz/<target>/, which
# make test replays). A finding is written to $(FUZZ_BUILD)/findings/<target>/
# and stops that target with an error; its log is $(FUZZ_BUILD)/logs/<target>.log.
# make -j2 fuzz runs two targets at once. nice -n 10: long runs keep the CPU.
FUZZ_PKGS := clang libclang-rt-14-dev libomp-dev
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 600
FUZZ_TARGETS ?= scene checkpoint2 checkpoint3 cdp cdp3 dat hdf5 csv fit
# Longest input: binary files need room for a small sample or problem
# (the larger seeds are cut to it), text ones a few KB.
fuzz_max_len = $(if $(filter hdf5,$(1)),131072,$(if $(filter checkpoint2 checkpoint3 cdp cdp3 dat,$(1)),65536,16384))
FUZZ_RSS_MB ?= 4096
.PHONY: fuzz
fuzz:
	$(call install_missing,fuzz,$(DEB_PKGS) $(FUZZ_PKGS))
	@[ -f $(FUZZ_BUILD)/CMakeCache.txt ] || { echo "make fuzz: configuring $(FUZZ_BUILD)/ (clang, sanitizers)"; \
	  CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Debug -DCDLAB_FUZZ=ON \
	    -DCDLAB_TESTS=OFF -DCDLAB_BENCH=OFF -DCMAKE_TARGET_MESSAGES=OFF --log-level=WARNING; }
	nice -n 10 cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_all cdsim
	@[ -f $(FUZZ_SEEDS)/.done ] || $(MAKE) $(FUZZ_SEEDS)/.done
	$(MAKE) $(addprefix fuzz-,$(FUZZ_TARGETS))
	@echo "make fuzz: $(FUZZ_TARGETS): $(FUZZ_SECONDS) s each, nothing found; statistics in $(FUZZ_BUILD)/logs/"

# The seeds: the repository's own inputs of each kind, and the checkpoints
# and dumped steps (.cdp, .cdp3, .hdf5) of two short runs.
FUZZ_SEEDS := $(FUZZ_BUILD)/seeds
$(FUZZ_SEEDS)/.done:
	rm -rf $(FUZZ_SEEDS) && mkdir -p $(addprefix $(FUZZ_SEEDS)/,$(FUZZ_TARGETS))
	cp configs/*.toml tests/data/config/full.toml $(FUZZ_SEEDS)/scene/
	cp tests/data/regress/inertial/I_0.1/scene.toml $(FUZZ_SEEDS)/scene/resolved2.toml
	cp tests/data/regress3d/inertial/I_0.1/scene.toml $(FUZZ_SEEDS)/scene/resolved3.toml
	cp tests/data/contact-problems/*.dat $(FUZZ_SEEDS)/dat/
	cp tests/data/contact-problems/*.hdf5 $(FUZZ_SEEDS)/hdf5/
	cp tests/data/regress/inertial/I_0.1/series.csv $(FUZZ_SEEDS)/csv/series2.csv
	cp tests/data/regress3d/inertial/I_0.1/series.csv $(FUZZ_SEEDS)/csv/series3.csv
	cp tests/data/analysis/mu_i/I_0.1/series.csv $(FUZZ_SEEDS)/csv/series-synthetic.csv
	cp tests/data/validation/angularity-periodic.csv $(FUZZ_SEEDS)/csv/
	cp tests/data/analysis/mu_i/fits.toml $(FUZZ_SEEDS)/fit/fits-synthetic.toml
	cp tests/data/validation/angularity-periodic-fits.toml $(FUZZ_SEEDS)/fit/
	cp tests/data/regress/mu_i.toml $(FUZZ_SEEDS)/fit/mu_i2.toml
	cp tests/data/regress3d/mu_i.toml $(FUZZ_SEEDS)/fit/mu_i3.toml
	rm -rf $(FUZZ_SEEDS)/runs && export ASAN_OPTIONS=detect_leaks=0 && \
	  $(FUZZ_BUILD)/cd/cdsim tests/fuzz/seed2.toml -q --threads 1 --out $(FUZZ_SEEDS)/runs/2d --dump-problem last && \
	  $(FUZZ_BUILD)/cd/cdsim tests/fuzz/seed3.toml -q --threads 1 --out $(FUZZ_SEEDS)/runs/3d --dump-problem last
	cp $(FUZZ_SEEDS)/runs/2d/checkpoint.bin $(FUZZ_SEEDS)/checkpoint2/
	cp $(FUZZ_SEEDS)/runs/3d/checkpoint.bin $(FUZZ_SEEDS)/checkpoint3/
	cp $(FUZZ_SEEDS)/runs/2d/problem_*.cdp $(FUZZ_SEEDS)/cdp/
	cp $(FUZZ_SEEDS)/runs/2d/problem_*.dat $(FUZZ_SEEDS)/dat/
	cp $(FUZZ_SEEDS)/runs/3d/problem_*.cdp3 $(FUZZ_SEEDS)/cdp3/
	cp $(FUZZ_SEEDS)/runs/3d/problem_*.hdf5 $(FUZZ_SEEDS)/hdf5/
	cp $(FUZZ_SEEDS)/runs/2d/scene.toml $(FUZZ_SEEDS)/scene/run2.toml
	cp $(FUZZ_SEEDS)/runs/3d/scene.toml $(FUZZ_SEEDS)/scene/run3.toml
	cp $(FUZZ_SEEDS)/runs/2d/series.csv $(FUZZ_SEEDS)/csv/run2.csv
	cp $(FUZZ_SEEDS)/runs/3d/series.csv $(FUZZ_SEEDS)/csv/run3.csv
	@touch $@

# One target, after make fuzz has built it: fuzz-<name>. The corpus first
# (new inputs go there), then the seeds and the regression inputs (read only).
fuzz-%:
	@mkdir -p $(FUZZ_BUILD)/corpus/$* $(FUZZ_BUILD)/findings/$* $(FUZZ_BUILD)/logs
	@echo "make fuzz: $* for $(FUZZ_SECONDS) s (log: $(FUZZ_BUILD)/logs/$*.log)"
	@cd $(FUZZ_BUILD) && LSAN_OPTIONS=suppressions=$(CURDIR)/tests/fuzz/lsan.supp nice -n 10 ./tests/fuzz/fuzz_$* corpus/$* seeds/$* $(abspath $(wildcard tests/data/fuzz/$*)) \
	  -max_total_time=$(FUZZ_SECONDS) -max_len=$(call fuzz_max_len,$*) -rss_limit_mb=$(FUZZ_RSS_MB) \
	  -timeout=60 -print_final_stats=1 -artifact_prefix=findings/$*/ > logs/$*.log 2>&1; \
	  rc=$$?; grep -E '^(#[0-9]+ +DONE|stat::number_of_executed_units|Done )' logs/$*.log | sed 's/^/  $*: /'; \
	  if [ $$rc != 0 ]; then echo "make fuzz: $* found a problem (exit $$rc): $(FUZZ_BUILD)/findings/$*/, log:"; \
	    tail -40 logs/$*.log; exit 1; fi

# ---- Dense shear side by side with LIGGGHTS (docs/accuracy.md) ---------------
# make compare-yade-pile [YCMP_T=0.12] [YCMP_E=1e8]: the deposition of
# configs/pile-polyhedra.toml (1000 cubes, d in [5, 10] mm, mu = 0.4) for its
# first YCMP_T seconds by cdsim (the scene as shipped) and by YADE's
# polyhedra (Debian's yade, built with CGAL: the volumetric law, F_n = kn V,
# time step a tenth of the smallest cube's critical one), the same
# construction in cd/bench/peers/yade-polyhedra/pile.py; one after the
# other, one thread each, then the table of table.py (CPU, steps, largest
# overlap, the ratio). Redone into YCMP_DIR on each call.
YCMP_DIR ?= outputs/compare-yade
YCMP_T ?= 0.12
YCMP_E ?= 1e8
.PHONY: compare-yade-pile
compare-yade-pile: build
	$(call install_missing,compare-yade-pile,yade)
	rm -rf $(YCMP_DIR) && mkdir -p $(YCMP_DIR)
	@echo "compare-yade-pile: load average at the start $$(cut -d' ' -f1-3 /proc/loadavg)"
	$(BUILD)/cd/cdsim configs/pile-polyhedra.toml --out $(YCMP_DIR)/cdsim --threads 1 \
	  --set time.duration=$(YCMP_T) --set output.snapshot_interval=0 > $(YCMP_DIR)/cdsim.log 2>&1
	cd $(YCMP_DIR) && N=1000 T=$(YCMP_T) E=$(YCMP_E) OMP_NUM_THREADS=1 \
	  yade -n -j 1 -x $(CURDIR)/cd/bench/peers/yade-polyhedra/pile.py > yade.log 2>&1
	/usr/bin/python3 cd/bench/peers/yade-polyhedra/table.py $(YCMP_DIR)

# make compare-liggghts-shear [QUICK=1] [CMP_STRAIN=2] [CMP_I=0.01] [SHEAR_TOL=...] [SHEAR_SET=...]
# One 1000-grain mu(I) point by both codes side by side, one thread each:
# LIGGGHTS 3.8 (Debian's, installed here if missing) shearing 1000 spheres
# between rough walls at imposed p, E/p = 1e5 (cd/bench/peers/liggghts-shear/),
# and cdsim's 3D campaign point (make campaign-inertial DIM=3 N=1000: the
# preparation and shear scenes), run at the same time, then the table of
# cd/bench/peers/shear_table.py (CPU s per unit strain, steps, sweeps a step,
# mu, phi, z, the ratio; the load). Everything is redone on each call into
# CMP_DIR. QUICK=1: strain 0.3 (a try, not a steady state; ~5 CPU min).
# LIGGGHTS' recommended packages pull python3-paraview, which removes
# libvtk9-dev (the build's): installed without them, and repaired at once if
# it happened anyway.
CMP_DIR ?= outputs/compare-liggghts
CMP_I ?= 0.01
CMP_STRAIN ?= $(if $(QUICK),0.3,2)
.PHONY: compare-liggghts-shear
compare-liggghts-shear: build
	$(call install_missing,compare-liggghts-shear,liggghts time python3-numpy)
	@dpkg-query -W -f='$${Status}\n' libvtk9-dev 2>/dev/null | grep -q '^install ok installed' || \
	  { echo "compare-liggghts-shear: libvtk9-dev was removed: reinstalling it"; \
	    DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y --no-install-recommends libvtk9-dev python3-paraview-; }
	rm -rf $(CMP_DIR) && mkdir -p $(CMP_DIR)
	@echo "compare-liggghts-shear: load average at the start $$(cut -d' ' -f1-3 /proc/loadavg)"
	CDANALYSIS=$(BUILD)/analysis/cdanalysis /usr/bin/python3 cd/bench/peers/liggghts-shear/run.py $(CMP_DIR)/liggghts I=$(CMP_I) Ep=1e5 \
	  strain=$(CMP_STRAIN) > $(CMP_DIR)/liggghts.log 2>&1 & lig=$$!; \
	$(MAKE) --no-print-directory campaign-inertial DIM=3 N=1000 INERTIAL_I=$(CMP_I) THREADS=1 \
	  STRAIN=$(CMP_STRAIN) CAMPAIGNS=$(CMP_DIR)/cdsim; cd=$$?; \
	wait $$lig || { tail -5 $(CMP_DIR)/liggghts.log; exit 1; }; [ $$cd = 0 ]
	/usr/bin/python3 cd/bench/peers/shear_table.py $(CMP_DIR)

# make compare-liggghts-ladder [LADDER_EP="1e4 1e5 1e6 1e7 1e8"] [LADDER_SEEDS=...] [LADDER_CD=...]
# What each code costs for the same answer. LIGGGHTS (the deck of
# compare-liggghts-shear, its top wall a body under -p A at any stiffness)
# at each Hertz stiffness E/p of LADDER_EP at I = 0.01 (strain 2, window
# 1-2) and of LADDER_EP3 at I = 1e-3 (strain 1, window 0.5-1), each seed of
# LADDER_SEEDS; cdsim's 1000-sphere point of make accuracy-shear3 (sample
# 11, the reference's first, continued for strain 1 at I = 0.01) under
# each setting of LADDER_CD (a3_set_<name>: policy, fast, k1e4 the
# compliant contacts at the stiffness number DEM's E/p = 1e6 has) and at
# I = 1e-3 of LADDER_CD3 (continued for strain 0.25), side by side (-j2: two runs at a time, one thread each). Then
# cd/bench/peers/ladder_table.py: mu, phi, z (one estimator for both:
# cdanalysis' force-bearing network without rattlers), sigma_yy/p, CPU per
# unit strain, each against the rigid reference of make accuracy-shear3
# (cd/bench/peers/rigid_reference.csv, five samples) in combined standard
# errors; LADDER_DIR/table.md and ladder.svg (cost against the stiffness).
# About 40 CPU minutes (docs/accuracy.md, "LIGGGHTS at equal accuracy").
LADDER_DIR ?= outputs/compare-liggghts-ladder
LADDER_EP ?= 1e4 1e5 1e6 1e7 1e8
LADDER_EP3 ?= 1e5 1e6
LADDER_SEEDS ?= 1 2
LADDER_CD ?= policy fast k1e4
LADDER_CD3 ?= policy
a3_set_k1e4 := --set contact.stiffness_number=1e4
a3_set_k1e5 := --set contact.stiffness_number=1e5
ladder_lig = $(foreach s,$(LADDER_SEEDS),$(foreach e,$(LADDER_EP),$(LADDER_DIR)/liggghts/I_0.01/Ep_$(e)/s_$(s)) \
  $(foreach e,$(LADDER_EP3),$(LADDER_DIR)/liggghts/I_0.001/Ep_$(e)/s_$(s)))
.PHONY: compare-liggghts-ladder compare-liggghts-ladder-runs
compare-liggghts-ladder: programs
	$(call install_missing,compare-liggghts-ladder,liggghts python3-numpy)
	@echo "compare-liggghts-ladder: load average at the start $$(cut -d' ' -f1-3 /proc/loadavg)"
	$(MAKE) --no-print-directory compare-liggghts-ladder-runs
	/usr/bin/python3 cd/bench/peers/ladder_table.py $(LADDER_DIR) cd/bench/peers/rigid_reference.csv \
	  $(foreach k,$(LADDER_CD),$(LADDER_DIR)/cdsim/I_0.01/s11/$(k)) \
	  $(foreach k,$(LADDER_CD3),$(LADDER_DIR)/cdsim/I_0.001/s11/$(k))
compare-liggghts-ladder-runs: $(addsuffix /.done,$(ladder_lig)) ladder-cdsim
# The cdsim side: make accuracy-shear3's runs, in LADDER_DIR (sharing -j).
.PHONY: ladder-cdsim
ladder-cdsim:
	+$(MAKE) --no-print-directory accuracy-shear3-runs A3_DIR=$(LADDER_DIR)/cdsim A3_SEEDS=11 A3_I=0.01 \
	  A3_SETTINGS="$(LADDER_CD)" A3_STRAIN=1
	+$(MAKE) --no-print-directory accuracy-shear3-runs A3_DIR=$(LADDER_DIR)/cdsim A3_SEEDS=11 A3_I=0.001 \
	  A3_SETTINGS="$(LADDER_CD3)" A3_STRAIN=0.25
$(LADDER_DIR)/liggghts/%/.done:
	rm -rf $(@D) && mkdir -p $(@D)
	CDANALYSIS=$(BUILD)/analysis/cdanalysis /usr/bin/python3 cd/bench/peers/liggghts-shear/run.py $(@D) \
	  I=$(word 2,$(subst _, ,$(word 1,$(subst /, ,$*)))) Ep=$(word 2,$(subst _, ,$(word 2,$(subst /, ,$*)))) \
	  seed=$(word 2,$(subst _, ,$(word 3,$(subst /, ,$*)))) \
	  strain=$(if $(filter I_0.001/%,$*),1,2) > $(@D).log 2>&1 || { tail -5 $(@D).log; exit 1; }
	touch $@
