# Two commands for a new user: `make demo` and `make test`. Everything they need is installed here.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
AF := $(VENV)/bin/actuator-fmus
## The linux64 binary the FMUs ship (see "Linux binaries for every maintained distribution" below).
LIB := target/glibc/x86_64-unknown-linux-gnu/release/libactuator_fmus.so
# The MuJoCo actuator plugin (see "MuJoCo" below).
MUJOCO_PLUGIN := target/mujoco-plugin/release/libactuator_fmus_mujoco.so
SOURCES := $(shell find src modelDescription build tools/src -type f) Cargo.toml tools/Cargo.toml build.rs .cargo/config.toml

.PHONY: mujoco-plugin mujoco-arm mujoco-docs
.PHONY: all fmus zig-tools demo scene figures test test-rust test-new-model test-fmpy bench report clean deps cross-deps interop-deps calibrate calibrate-festo motor-docs knitted-bag-docs slack-docs linearized chapter2-claims py-deps scene-schema

all: fmus

## The Python tools, pinned (FMPy is the importer the tests and the demo drive), and this project's
## package (pyproject.toml, python/actuator_fmus/), editable, with its command `actuator-fmus`.
$(VENV)/.installed: tests/fmpy/requirements.txt pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -r tests/fmpy/requirements.txt
	$(VENV)/bin/pip install --quiet --no-deps -e .
	touch $@

## libclang for the `fmi` crate's bindgen (a dev-dependency: the Rust tests import our FMUs with it).
deps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libclang\(-[0-9.]*\)\?\.so'; then \
	  echo "installing libclang-dev (needed by the fmi crate's bindgen)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq libclang-dev; \
	fi

## Debian packages the FMPy suite needs: chromium for the FMU pages' screenshot test
## (tests/fmpy/test_fmu_pages.py) and libtbb12 for ecospy (recipes/importers_ssp_libcosim_ecos.py).
py-deps:
	@missing=""; \
	ldconfig -p 2>/dev/null | grep -q 'libtbb\.so\.12' || missing="$$missing libtbb12"; \
	command -v chromium >/dev/null || missing="$$missing chromium"; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq \
	    --no-install-recommends $$missing; \
	fi

## One recipe for both tools (`&:`): under `make -j` it must run once, not once per file.
## `+`: cargo shares make's job slots (it also makes `make -n` run these lines).
## `deps`: the tools link the fmi crate, whose bindgen needs libclang (a fresh `make demo` too).
target/release/package_fmus target/release/package_fmi3 target/release/calibrate target/release/festo_law &: $(SOURCES) | deps
	+cargo build --release -p actuator-fmus-tools --bin package_fmus --bin package_fmi3 --bin calibrate --bin festo_law

## Linux binaries for every maintained distribution: linked against glibc 2.17 (the manylinux2014
## baseline: RHEL/Rocky 7-9, Ubuntu 18.04+, Debian 10+) by cargo-zigbuild with zig as the linker,
## whatever glibc this machine has. Both tools are pinned and installed here, under target/tools/,
## when missing (zig from PyPI's `ziglang` wheel, in its own venv). tests/all/glibc_versions.rs
## fails if a shipped .so needs a newer symbol version.
GLIBC := 2.17
ZIGLANG_VERSION := 0.17.1
ZIGBUILD_VERSION := 0.24.1
TOOLS := target/tools
ZIGBUILD := $(TOOLS)/bin/cargo-zigbuild
ZIG_VENV := $(TOOLS)/zig
# cargo-zigbuild finds zig as `python3 -m ziglang` first: the tool venv's python3 leads the PATH.
ZIG_ENV := PATH=$(CURDIR)/$(ZIG_VENV)/bin:$(CURDIR)/$(TOOLS)/bin:$$PATH
$(ZIG_VENV)/.installed:
	$(PYTHON) -m venv $(ZIG_VENV)
	$(ZIG_VENV)/bin/pip install --quiet ziglang==$(ZIGLANG_VERSION)
	touch $@
$(ZIGBUILD):
	cargo install cargo-zigbuild --locked --version $(ZIGBUILD_VERSION) --root $(TOOLS)
zig-tools: $(ZIG_VENV)/.installed $(ZIGBUILD)

## Its own target directory, so that it runs beside the host build under `make -j`.
GLIBC_TARGET_DIR := target/glibc
$(LIB): $(SOURCES) | zig-tools
	+$(ZIG_ENV) cargo zigbuild --release --lib -p actuator-fmus --target-dir $(GLIBC_TARGET_DIR) \
	  --target x86_64-unknown-linux-gnu.$(GLIBC)

## Cross toolchains for the win64 and aarch64-linux binaries, and the emulators the tests run them
## under (wine, qemu-user); each installed only when missing.
CROSS_DEBS := gcc-mingw-w64-x86-64 gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user wine64
CROSS_TARGETS := x86_64-pc-windows-gnu aarch64-unknown-linux-gnu
cross-deps:
	@missing=$$(for p in $(CROSS_DEBS); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "installing $$missing (cross builds and their emulators)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	fi
	@installed=$$(rustup target list --installed); for t in $(CROSS_TARGETS); do \
	  echo "$$installed" | grep -qx $$t || rustup target add $$t; done

## Both cross targets in one cargo run, in their own target directory: cargo locks its target
## directory for a whole run, so in target/ they would wait for the host build (and the Rust tests'
## build) instead of running beside it under `make -j`. The price is compiling the build script's
## host dependencies once more.
CROSS_TARGET_DIR := target/cross
WIN_DLL := $(CROSS_TARGET_DIR)/x86_64-pc-windows-gnu/release/actuator_fmus.dll
ARM_SO := $(GLIBC_TARGET_DIR)/aarch64-unknown-linux-gnu/release/libactuator_fmus.so

$(WIN_DLL): $(SOURCES) | cross-deps
	+cargo build --release --lib --target-dir $(CROSS_TARGET_DIR) --target x86_64-pc-windows-gnu

## aarch64-linux as linux64: zig links it against glibc 2.17 (no cross gcc needed for the build;
## the tests' C harness still uses it).
$(ARM_SO): $(SOURCES) $(LIB) | zig-tools cross-deps
	+$(ZIG_ENV) cargo zigbuild --release --lib -p actuator-fmus --target-dir $(GLIBC_TARGET_DIR) \
	  --target aarch64-unknown-linux-gnu.$(GLIBC)

## target/fmu/<Model>.fmu (FMI 2.0) for every model in modelDescription/, with binaries for linux64,
## win64 and aarch64-linux (`make fmus CROSS=0`: linux64 only, no cross toolchains needed), and
## target/fmu-fmi3/<Model>.fmu, the FMI 3.0 FMUs with the same binaries (one library exports both
## APIs) under x86_64-linux, x86_64-windows and aarch64-linux.
CROSS ?= 1
ifeq ($(CROSS),1)
CROSS_BINARIES := $(WIN_DLL) $(ARM_SO)
CROSS_ARGS := win64=$(WIN_DLL) aarch64-linux=$(ARM_SO)
endif
fmus: $(LIB) target/release/package_fmus target/release/package_fmi3 $(CROSS_BINARIES)
	target/release/package_fmus $(LIB) target/fmu $(CROSS_ARGS)
	target/release/package_fmi3 target/fmu target/fmu-fmi3

DEFAULT_SCENE := scenes/fig2_3_ideal_mckibben.json

## Builds the FMUs and runs the default scene under FMPy: out/fig2_3_ideal_mckibben.{csv,png}.
demo: fmus $(VENV)/.installed
	$(AF) scene $(DEFAULT_SCENE) --out out

## scenes/schema/scene.schema.json, the JSON Schema of scene files, from the Rust types in src/scene.rs.
scene-schema:
	cargo run --release --quiet -p actuator-fmus-tools --example run_scene -- --schema > scenes/schema/scene.schema.json

## Any scene: make scene SCENE=scenes/<name>.json
scene: fmus $(VENV)/.installed
	$(AF) scene $(SCENE) --out out

## Every scene at full length, and docs/figures.md with the plots beside the dissertation's statements.
figures: fmus $(VENV)/.installed
	$(AF) figures

## Fits McKibbenMuscle to a datasheet (CSV pressure_kpa,contraction,force_n) with the FMU's own
## physics, checks the result through the FMU: OUT/{params.json,params.ssv,report.md,fit.png}.
## STARTS: starting points of the search (fewer is faster, e.g. 4 in the tests).
DATA ?= data/festo/festo_dmsp40.csv
LENGTH ?= 0.4
DIAMETER ?= 0.04
FIT ?= 0,600
OUT ?= out/calibrate
STARTS ?= 24
calibrate: fmus target/release/calibrate $(VENV)/.installed
	$(AF) calibrate $(DATA) --length $(LENGTH) --diameter $(DIAMETER) --fit-kpa $(FIT) --out $(OUT) --starts $(STARTS)

## The Festo fits (src/physics/festo.rs) and their reports, docs/calibration/dmsp{40,10}/; the
## DMSP scaling law's page and figure with leave-one-out, docs/calibration/scaling.{md,png}.
calibrate-festo: fmus target/release/calibrate target/release/festo_law $(VENV)/.installed
	$(AF) calibrate data/festo/festo_dmsp40.csv --length 0.4 --diameter 0.04 --fit-kpa 0,600 --out docs/calibration/dmsp40
	$(AF) calibrate data/festo/festo_dmsp10.csv --length 0.25 --diameter 0.01 --fit-kpa 0,600 --out docs/calibration/dmsp10
	target/release/festo_law --out docs/calibration
	$(VENV)/bin/python -m actuator_fmus.festo_scaling docs/calibration

test-rust: deps fmus
	+cargo test --release --workspace

## docs/adding-a-model.md's trivial model added to a scratch copy of the repository, built and put
## through the Rust suites that cover every model (tests/all/new_model.rs; builds the crate again
## in target/new-model, minutes).
test-new-model: deps
	+cargo test --release --test all new_model -- --ignored --nocapture

## ecos (ecospy, tests/fmpy/test_interop.py) needs Debian's libtbb12.
interop-deps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libtbb\.so\.12'; then \
	  echo "installing libtbb12 (needed by ecospy)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq libtbb12; \
	fi

## PYTEST_WORKERS processes (pytest-xdist); a test file stays in one worker (`--dist loadfile`), so
## that its module fixtures are built once and files that share a scratch directory (wine's
## prefix) never run beside themselves. PYTEST_WORKERS=0: one process.
PYTEST_WORKERS ?= 2
test-fmpy: fmus $(VENV)/.installed interop-deps py-deps $(MUJOCO_PLUGIN)
	$(PY) -m pytest tests/fmpy -q $(if $(filter-out 0,$(PYTEST_WORKERS)),-n $(PYTEST_WORKERS) --dist loadfile)

## All Rust tests and the FMPy suite. The apt checks run first, one at a time (dpkg has one lock);
## then everything else runs TEST_JOBS wide: the host build beside the cross builds and the venv,
## then the Rust tests beside the FMPy suite (CONTRIBUTING.md, "Tests").
TEST_JOBS ?= 3
test:
	@$(MAKE) --no-print-directory deps cross-deps interop-deps py-deps
	+@$(MAKE) --no-print-directory -j$(TEST_JOBS) test-rust test-fmpy
	+@$(MAKE) --no-print-directory test-report

## Every configuration `make report` measures, run once each and nothing written (criterion's test
## mode, the motor and wall CPU-time bench, `benches/report.py --smoke`): a configuration an FMU
## refuses fails here, not in the next report.
.PHONY: test-report
test-report: fmus $(VENV)/.installed
	cargo bench --bench accuracy_cost -- --test
	cargo bench --bench cpu_time
	$(PY) benches/report.py --smoke

## The C pass-through FMU (FMI 2.0 Co-Simulation) that benches/parity.rs holds our FMI layer against.
C_PASSTHROUGH := target/c_passthrough/PassThroughC.so
$(C_PASSTHROUGH): benches/c_passthrough/passthrough.c
	mkdir -p $(@D)
	cc -O2 -shared -fPIC -o $@ $< -lm

## Native cost per FMI step (criterion), through the packaged FMU's C ABI; then the FMI layer
## against a C pass-through FMU and the performance goals, interleaved in one run (benches/parity.rs).
bench: deps fmus $(C_PASSTHROUGH)
	cargo bench --bench fmi_step
	cargo bench --bench knitted_shape
	cargo bench --bench directional_derivative
	cargo bench --bench model_exchange
	cargo bench --bench cpu_time
	cargo bench --bench parity

.PHONY: worst-case
## The cost of a step and of initialization anywhere in each FMU's declared space: every bound
## alone, every option combination and 10,000 log-uniform random points per FMU (median, p99,
## max; benches/worst_case.rs). WORST_CASE_POINTS and WORST_CASE_MODELS narrow it.
worst-case: fmus
	cargo bench --bench worst_case

.PHONY: parity
## benches/parity.rs alone: the FMI layer against C, the walls, the motor and the knitted table;
## then docs/performance.md's FMI-layer table from that run.
parity: deps fmus $(VENV)/.installed $(C_PASSTHROUGH)
	cargo bench --bench parity
	$(PY) benches/report.py --parity

## The motor's step in CPU time (stepping scene, large load torques; benches/cpu_time.rs), its
## Model Exchange calls (right-hand side, exact partials) against a Co-Simulation step, and its
## Model Exchange runs under FMPy's default settings.
.PHONY: bench-motor
bench-motor: deps fmus $(VENV)/.installed
	cargo bench --bench cpu_time
	cargo bench --bench motor_model_exchange
	$(PY) benches/motor_me_fmpy.py
	$(PY) benches/motor_me_fmpy.py --defaults

## docs/accuracy-cost.md: error against a converged reference and native time per step for every
## fidelity knob, work-precision plots, and the cost under FMPy beside the PassThrough FMU.
report: deps fmus $(VENV)/.installed $(C_PASSTHROUGH)
	cargo bench --bench accuracy_cost
	cargo bench --bench cpu_time
	cargo bench --bench parity
	$(PY) benches/report.py

## docs/linearized-muscle.md: stiffness dF/dL and pressure gain dF/dP over the stroke of Table 2.1's
## muscles through fmi2GetDirectionalDerivative, and chapter 2's linear-spring proposal tested.
linearized: fmus $(VENV)/.installed
	$(AF) linearized > /dev/null

## Chapter 2's claims re-run with the dissertation's walls and the exact wall: docs/chapter2-claims.md.
chapter2-claims: fmus $(VENV)/.installed
	$(AF) chapter2-claims

clean:
	cargo clean
	rm -rf out $(VENV)

## docs/motor.md and docs/img/motor_*.png: holding, pull-in and pull-out torque, section 3.2.3's
## densities, strain drive and onion reorientation of the MultiferroicMotor FMU.
motor-docs: fmus $(VENV)/.installed
	$(AF) motor

## docs/knitted-bag.md and docs/img/knitted_bag.png: the section 1.4 prototype's polyethylene bag
## and its stroke against the measured 42% and 51%.
knitted-bag-docs: fmus $(VENV)/.installed
	$(AF) knitted-bag

## ---- MuJoCo (docs/mujoco.md) ----
## The actuator plugin that runs an FMU inside MuJoCo (mujoco_plugin/, its own crate and target
## directory so that it builds beside the Rust tests). It compiles against the headers and links the
## libmujoco.so of the pinned `mujoco` wheel in the venv.
MUJOCO_PLUGIN_SOURCES := $(shell find mujoco_plugin/src -type f) mujoco_plugin/Cargo.toml mujoco_plugin/build.rs
$(MUJOCO_PLUGIN): $(MUJOCO_PLUGIN_SOURCES) $(VENV)/.installed
	+cargo build --release --manifest-path mujoco_plugin/Cargo.toml --target-dir target/mujoco-plugin
	@touch $@
mujoco-plugin: $(MUJOCO_PLUGIN)

## The antagonistic arm in MuJoCo (examples/mujoco/arm.xml): position control, then co-contraction
## at a fixed angle, with torque pulses that show the stiffness; out/mujoco/arm.{csv,png} and, when
## offscreen rendering works, out/mujoco/arm.gif.
mujoco-arm: fmus $(MUJOCO_PLUGIN)
	$(PY) examples/mujoco_arm.py --out out/mujoco

## docs/mujoco.md's figures (the arm, rendered if EGL or OSMesa works) and docs/mujoco-comparison.md:
## the plugin against MuJoCo's <muscle> fitted at one pressure, and the cost per step.
mujoco-docs: fmus $(MUJOCO_PLUGIN)
	$(PY) examples/mujoco_arm.py --out out/mujoco --gif --stiffness
	cp out/mujoco/arm.png docs/img/mujoco_arm.png
	cp out/mujoco/arm_stiffness.png docs/img/mujoco_stiffness.png
	if [ -f out/mujoco/arm.gif ]; then cp out/mujoco/arm.gif docs/img/mujoco_arm.gif; fi
	$(PY) examples/mujoco_vs_native_muscle.py --out docs/img --report docs/mujoco-comparison.md

## docs/img/slack_and_max_length.png: force against length of the DMSP-10 through its free
## contraction (slack) and through max_length (the stretching strands).
slack-docs: fmus $(VENV)/.installed
	$(PY) examples/slack_and_max_length.py

## Robot joint: an antagonistic McKibbenMuscle pair on a pulley under PD pressure control,
## co-simulated with FMPy (out/robot_joint.{csv,png}) and with the fmi crate (out/robot_joint_fmi.csv).
robot-joint: deps fmus $(VENV)/.installed
	$(AF) robot-joint --out out
	cargo run --release -p actuator-fmus-tools --example robot_joint

## FMI cross-check files crosscheck/<Model>/<Model>_{in,ref}.csv, _ref.opt and the plots
## docs/fmu/<Model>.png, then the FMUs again so that each documentation/ carries its plot.
crosscheck: fmus $(VENV)/.installed
	$(AF) crosscheck
	target/release/package_fmus $(LIB) target/fmu $(CROSS_ARGS)
	target/release/package_fmi3 target/fmu target/fmu-fmi3

## The robot joint as a system: out/systems/RobotJoint.ssp (fmpy simulate_ssp) and the container
## FMU out/systems/RobotJoint.fmu (fmu-manipulation-toolbox), both run and plotted against the
## two-FMU co-simulation: out/systems/robot_joint_systems.png.
systems: fmus $(VENV)/.installed
	$(AF) systems --run

## Design sweep on Dask (not part of `make test`): bladder pre-strain x wall thickness -> net work per
## stroke of the McKibbenMuscle FMU, out/sweep.{csv,png}. Local cluster by default; any running
## scheduler with `make sweep SCHEDULER=tcp://host:8786`.
sweep: fmus $(VENV)/.installed
	$(AF) sweep --out out $(if $(SCHEDULER),--scheduler $(SCHEDULER))

## ---- Reliability jobs: longer runs, not part of `make test`. ----
.PHONY: fuzz fuzz-cmin memcheck load

## tests/load.rs with its 10,000-cycle heap test of every FMU in both interfaces (ignored by
## `make test`: a minute of CPU, most of it the motor).
load: fmus
	cargo test --release --test load -- --include-ignored --nocapture

FUZZ_SECONDS ?= 120
## Stop after this many sequences instead (libFuzzer's -runs), whichever limit comes first.
FUZZ_RUNS ?=
## Fuzzing processes side by side (libFuzzer's -jobs and -workers), one per core for volume, e.g.
## `make fuzz SANITIZER=none FUZZ_JOBS=2 FUZZ_RUNS=5000000 FUZZ_SECONDS=36000` for 10 million on
## 2 cores. They share fuzz/corpus-run/; FUZZ_RUNS and FUZZ_SECONDS hold for each; each keeps its
## log as fuzz/logs/$(SANITIZER)-job-N.log, and the summary line adds up all of them.
FUZZ_JOBS ?= 1
# Non-empty when several jobs run; libFuzzer then writes each job's output to ./fuzz-N.log.
FUZZ_PARALLEL = $(filter-out 1,$(FUZZ_JOBS))
## address (the default: AddressSanitizer, ~15x slower) or none (the plain build, for volume).
SANITIZER ?= address
## Per-sequence limit in wall-clock seconds: the longest sequences take ~0.3 s of CPU, but a
## niced run on a loaded machine waits many times that for a core.
FUZZ_TIMEOUT ?= 120
# Each sanitizer builds in its own target directory, so that switching does not rebuild.
FUZZ_TARGET_DIR = $(if $(filter none,$(SANITIZER)),,--target-dir fuzz/target-$(SANITIZER))
## Fuzzes random FMI call sequences (Co-Simulation and Model Exchange) on all seven models for
## FUZZ_SECONDS (cargo-fuzz, nightly Rust),
## with the harness of tests/fuzz_driver/ (tests/all/fuzz_corpus.rs replays the committed corpus in
## `make test`). The committed seeds in fuzz/corpus/call_sequences and the past findings in
## fuzz/regressions/call_sequences are only read; new inputs go
## to the ignored fuzz/corpus-run/, findings to the ignored fuzz/artifacts/. The summary line
## counts the sequences run ("stat::number_of_executed_units"). The tracked fuzz/Cargo.lock must
## come out unchanged (a dependency change shows here, to be committed).
fuzz:
	@command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
	@rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
	mkdir -p fuzz/corpus-run/call_sequences fuzz/logs
	rm -f fuzz/logs/$(SANITIZER)-job-*.log
	cargo +nightly fuzz run -s $(SANITIZER) $(FUZZ_TARGET_DIR) call_sequences $(CURDIR)/fuzz/corpus-run/call_sequences \
	  $(CURDIR)/fuzz/corpus/call_sequences $(CURDIR)/fuzz/regressions/call_sequences \
	  -- -max_total_time=$(FUZZ_SECONDS) $(if $(FUZZ_RUNS),-runs=$(FUZZ_RUNS)) -timeout=$(FUZZ_TIMEOUT) \
	  -rss_limit_mb=2048 -print_final_stats=1 $(if $(FUZZ_PARALLEL),-jobs=$(FUZZ_JOBS) -workers=$(FUZZ_JOBS)) \
	  2>&1 | tee fuzz/logs/$(SANITIZER).log | grep -v '^#[0-9]' ; status=$${PIPESTATUS[0]}; \
	  for log in fuzz-[0-9]*.log; do [ ! -e "$$log" ] || mv "$$log" "fuzz/logs/$(SANITIZER)-job-$${log#fuzz-}"; done; \
	  test $$status = 0
	@grep -h 'stat::number_of_executed_units' \
	  $(if $(FUZZ_PARALLEL),fuzz/logs/$(SANITIZER)-job-*.log,fuzz/logs/$(SANITIZER).log) \
	  | awk '{n += $$2} END {print "make fuzz SANITIZER=$(SANITIZER): " n " sequences without a finding"}'
	@git diff --exit-code --stat -- fuzz/Cargo.lock

## Rewrites fuzz/corpus/call_sequences as the smallest set of inputs libFuzzer's greedy set cover
## finds with the edge coverage of the committed corpus and the run corpus (fuzz/corpus-run/)
## together: -set_cover_merge over edges only (-use_counters=0, hit counts do not count), plain
## build. The past findings in fuzz/regressions/ stay as they are. Commit the result.
fuzz-cmin:
	@command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
	@rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
	rm -rf fuzz/corpus-min && mkdir -p fuzz/corpus-min/call_sequences fuzz/corpus-run/call_sequences
	cargo +nightly fuzz run -s none call_sequences $(CURDIR)/fuzz/corpus-min/call_sequences \
	  $(CURDIR)/fuzz/corpus/call_sequences $(CURDIR)/fuzz/corpus-run/call_sequences \
	  -- -set_cover_merge=1 -use_counters=0 -timeout=$(FUZZ_TIMEOUT) -rss_limit_mb=2048 \
	  2>&1 | grep -E '^MERGE-OUTER: [0-9]+ new files'; test $${PIPESTATUS[0]} = 0
	rm -rf fuzz/corpus/call_sequences && mv fuzz/corpus-min/call_sequences fuzz/corpus/call_sequences
	rmdir fuzz/corpus-min
	@echo "fuzz/corpus/call_sequences: $$(ls fuzz/corpus/call_sequences | wc -l) inputs"
	@git diff --exit-code --stat -- fuzz/Cargo.lock

## Valgrind memcheck, two halves, each with its whole log kept in out/memcheck/ and its summary
## printed; any error in either fails:
## - native: tools/examples/memcheck_native.rs loads every FMU through its C ABI (no Python), runs
##   each with default parameters and with all effects on in both interfaces (Model Exchange with
##   states, events and directional derivatives), and every scene; definite and indirect leaks
##   count as errors and nothing is suppressed.
## - fmpy: FMPy tests (MEMCHECK_TESTS) with memory errors checked, not leaks (the Python
##   process's own); tests/valgrind-python.supp names only CPython, _json, lxml and ld.so. The
##   default set drives every FMU: every scene and every cross-check input through a strict
##   master, FMU states, threads and 20 load/unload cycles, and validation of every FMU; and Model
##   Exchange under FMPy (MEMCHECK_ME_TESTS): every scene through CVode, the checked calls,
##   state round trips, Jacobians, the motor's events, all but the four longest runs (2-5 s each
##   without valgrind). The whole suite under valgrind takes hours on 2 cores:
##   `make memcheck MEMCHECK_TESTS=tests/fmpy`.
MEMCHECK_ME_TESTS := tests/fmpy/test_model_exchange.py tests/fmpy/test_motor_model_exchange.py \
  $(addprefix --deselect ,'tests/fmpy/test_motor_model_exchange.py::test_motor_scene_model_exchange_matches_co_simulation[motor_stepping]' \
  tests/fmpy/test_model_exchange.py::test_pulley_model_exchange_matches_co_simulation_under_varying_forces \
  tests/fmpy/test_model_exchange.py::test_pulley_model_exchange_matches_co_simulation_under_constant_forces)
MEMCHECK_TESTS ?= tests/fmpy/test_strict_master.py tests/fmpy/test_fmi_behaviour.py \
  tests/fmpy/test_validation.py $(MEMCHECK_ME_TESTS)
MEMCHECK_DIR := out/memcheck
VALGRIND := valgrind --tool=memcheck --error-exitcode=1 --num-callers=30
memcheck: fmus $(VENV)/.installed
	@command -v valgrind >/dev/null || { \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq valgrind; }
	cargo build --release -p actuator-fmus-tools --example memcheck_native
	mkdir -p $(MEMCHECK_DIR)
	@start=$$(date +%s); \
	$(VALGRIND) --leak-check=full --errors-for-leak-kinds=definite,indirect \
	  --show-leak-kinds=definite,indirect --log-file=$(MEMCHECK_DIR)/native.log \
	  target/release/examples/memcheck_native > $(MEMCHECK_DIR)/native.out 2>&1; native=$$?; \
	tail -n $$( [ $$native = 0 ] && echo 1 || echo 20 ) $(MEMCHECK_DIR)/native.out; \
	echo "native: $$(grep -h 'ERROR SUMMARY' $(MEMCHECK_DIR)/native.log)"; \
	grep -h 'definitely lost\|indirectly lost\|All heap blocks were freed' $(MEMCHECK_DIR)/native.log; \
	FMI_BEHAVIOUR_LOAD_CYCLES=20 PYTHONMALLOC=malloc $(VALGRIND) --leak-check=no --suppressions=tests/valgrind-python.supp \
	  --log-file=$(MEMCHECK_DIR)/fmpy.log \
	  $(PY) -m pytest -q -p no:cacheprovider $(MEMCHECK_TESTS) > $(MEMCHECK_DIR)/fmpy.out 2>&1; fmpy=$$?; \
	tail -n $$( [ $$fmpy = 0 ] && echo 1 || echo 20 ) $(MEMCHECK_DIR)/fmpy.out; \
	echo "fmpy: $$(grep -h 'ERROR SUMMARY' $(MEMCHECK_DIR)/fmpy.log)"; \
	echo "make memcheck: $$(( $$(date +%s) - start )) s; logs in $(MEMCHECK_DIR)/"; \
	test $$native = 0 -a $$fmpy = 0

.PHONY: compliance
## The FMU Compliance Checker (modelica-tools/FMUComplianceChecker) on every FMU, XML and both
## interfaces, driven by crosscheck/<Model>/ inputs: `make compliance FMUCHECKER=path/to/fmuCheck.linux64`.
## Not on crates.io, PyPI or Debian: build it once from its repository (docs/compatibility.md, "FMU Compliance Checker").
compliance: fmus
	@test -n "$(FMUCHECKER)" || { echo "set FMUCHECKER=path/to/fmuCheck.linux64 (docs/compatibility.md: FMU Compliance Checker)"; exit 2; }
	FMUCHECKER="$(FMUCHECKER)" tools/compliance.sh

.PHONY: fmusim
## fmusim (modelica/fmusim, the Modelica Association's FMI 2.0/3.0 simulator) on every FMU under
## target/, FMI 2.0 and 3.0 told apart by each modelDescription's fmiVersion: `fmusim validate`
## reports nothing, `fmusim simulate` runs each interface with default settings, Co-Simulation
## equals Model Exchange at the end time: `make fmusim FMUSIM=path/to/fmusim` (FMUSIM_FMUS= other
## FMUs or directories). Built once from its repository (docs/compatibility.md, "fmusim").
fmusim: fmus
	@test -n "$(FMUSIM)" || { echo "set FMUSIM=path/to/fmusim (docs/compatibility.md: fmusim)"; exit 2; }
	FMUSIM="$(FMUSIM)" tools/fmusim.sh $(FMUSIM_FMUS)

.PHONY: omsimulator
## OMSimulator (OpenModelica's FMI simulator, built from source: docs/compatibility.md,
## "OMSimulator") on every FMU in Co-Simulation and Model Exchange at its default settings, and the
## motor as Model Exchange (quasi-static and Gilbert onion) against FMPy:
## `make omsimulator OMSIMULATOR=<prefix>/bin/OMSimulator` (tests/fmpy/test_omsimulator.py, which
## `make test` skips unless OMSIMULATOR is set or OMSimulator is on PATH).
omsimulator: fmus $(VENV)/.installed
	@test -n "$(OMSIMULATOR)" || { echo "set OMSIMULATOR=<prefix>/bin/OMSimulator (docs/compatibility.md: OMSimulator)"; exit 2; }
	OMSIMULATOR="$(OMSIMULATOR)" $(PY) -m pytest -q -rs tests/fmpy/test_omsimulator.py

## ---- The documentation site and `make help` ----
.PHONY: docs help

## The documentation site (mkdocs.yml, docs/, each FMU's own page from target/fmu/) into site/, with
## `mkdocs build --strict`: a broken link or anchor fails. tests/fmpy/test_docs_site.py builds it the
## same way in `make test` and opens every page in headless Chromium.
docs: fmus $(VENV)/.installed
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet
	@echo "site/index.html: $$(find site -name '*.html' | wc -l) pages"

## The user targets, one line each. The README points here instead of listing them, and
## tests/fmpy/test_make_help.py checks that each name is a target of this Makefile. Internal
## targets (deps, py-deps, cross-deps, interop-deps, test-rust, test-fmpy, scene-schema) stay out.
define HELP_TEXT
Start here
  demo              build the FMUs and run the default scene under FMPy: out/fig2_3_ideal_mckibben.{csv,png}
  test              all Rust tests, the FMPy suite and the documentation site's checks
  help              this list
Build
  fmus              target/fmu/<Model>.fmu (FMI 2.0) and target/fmu-fmi3/<Model>.fmu (FMI 3.0) (CROSS=0: x86-64 Linux only)
  docs              the documentation site into site/ (mkdocs build --strict)
Run the models
  scene             one scene under FMPy: make scene SCENE=scenes/<name>.json
  figures           every scene of the catalogue, and docs/figures.md
  calibrate         fit McKibbenMuscle to a datasheet: DATA= LENGTH= DIAMETER= FIT= OUT= STARTS=
  calibrate-festo   refit the Festo presets, rewrite docs/calibration/dmsp{10,40}/ and scaling.md
  robot-joint       an antagonistic muscle pair on a pulley, co-simulated: out/robot_joint.{csv,png}
  systems           the robot joint as an SSP and as a container FMU: out/systems/
  crosscheck        FMI cross-check files crosscheck/<Model>/ and the FMU pages' plots
  sweep             a design sweep on Dask: out/sweep.{csv,png} (SCHEDULER=tcp://host:port)
  motor-docs        docs/motor.md: the motor's holding, pull-in and pull-out torque
  knitted-bag-docs  docs/knitted-bag.md: the knitted prototype's bag against its measured stroke
  linearized        docs/linearized-muscle.md: stiffness and pressure gain over the stroke
Measure and check (not part of make test)
  bench             native cost per step, derivatives, Model Exchange, the FMI layer against C
  bench-motor       the motor's step and its Model Exchange calls
  parity            the FMI layer against a C pass-through FMU: docs/performance.md's table
  report            docs/accuracy-cost.md and the tables of docs/performance.md
  compliance        the FMU Compliance Checker on every FMU: FMUCHECKER=path/to/fmuCheck.linux64
  fmusim            fmusim validate and simulate (CS, ME) on every FMU, FMI 2.0 and 3.0: FMUSIM=path/to/fmusim
  omsimulator       OMSimulator on every FMU (CS, ME) and the motor's Model Exchange: OMSIMULATOR=.../bin/OMSimulator
  fuzz              random FMI call sequences (cargo-fuzz): FUZZ_SECONDS= FUZZ_JOBS= SANITIZER=
  fuzz-cmin         the committed fuzz corpus cut to a set cover of its and fuzz/corpus-run's edges
  memcheck          every FMU under valgrind, natively and through FMPy
  load              10,000 instantiate-run-free cycles per FMU with the heap counted
  test-new-model    docs/adding-a-model.md's trivial model in a scratch copy, through the Rust suites
  clean             remove build output, out/ and the .venv
endef
export HELP_TEXT
help:
	@echo "$$HELP_TEXT"
