# Two commands for a new user: `make demo` and `make test`. Everything they need is installed here.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
LIB := target/release/libactuator_fmus.so
SOURCES := $(shell find src modelDescription -type f) Cargo.toml build.rs

.PHONY: all fmus demo scene figures test test-rust test-fmpy bench report clean deps py-deps scene-schema

all: fmus

## The Python tools, pinned (FMPy is the importer the tests and the demo drive).
$(VENV)/.installed: tests/fmpy/requirements.txt
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -r tests/fmpy/requirements.txt
	touch $@

## libclang for the `fmi` crate's bindgen (a dev-dependency: the Rust tests import our FMUs with it).
deps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libclang\(-[0-9.]*\)\?\.so'; then \
	  echo "installing libclang-dev (needed by the fmi crate's bindgen)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq libclang-dev; \
	fi

## Debian packages the FMPy suite needs: libtbb12 for ecospy's native library
## (recipes/importers_ssp_libcosim_ecos.py) and chromium for the FMU pages' screenshot test.
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

$(LIB) target/release/package_fmus: $(SOURCES)
	cargo build --release --lib --bin package_fmus

## target/fmu/<Model>.fmu for every model in modelDescription/.
fmus: $(LIB) target/release/package_fmus
	target/release/package_fmus $(LIB) target/fmu

DEFAULT_SCENE := scenes/fig2_3_ideal_mckibben.json

## Builds the FMUs and runs the default scene under FMPy: out/fig2_3_ideal_mckibben.{csv,png}.
demo: fmus $(VENV)/.installed
	$(PY) scenes/run.py $(DEFAULT_SCENE) --out out

## scenes/schema/scene.schema.json, the JSON Schema of scene files, from the Rust types in src/scene.rs.
scene-schema:
	cargo run --release --quiet --example run_scene -- --schema > scenes/schema/scene.schema.json

## Any scene: make scene SCENE=scenes/<name>.json
scene: fmus $(VENV)/.installed
	$(PY) scenes/run.py $(SCENE) --out out

## Every scene at full length, and docs/figures.md with the plots beside the dissertation's statements.
figures: fmus $(VENV)/.installed
	$(PY) scenes/catalogue.py

test-rust: deps fmus
	cargo test --release

test-fmpy: fmus $(VENV)/.installed py-deps
	$(PY) -m pytest tests/fmpy -q

## All Rust tests and the FMPy suite.
test: test-rust test-fmpy

## Native cost per FMI step (criterion), through the packaged FMU's C ABI.
bench: deps fmus
	cargo bench --bench fmi_step
	cargo bench --bench knitted_shape

## docs/accuracy-cost.md: error against a converged reference and native time per step for every
## fidelity knob, work-precision plots, and the cost under FMPy beside the PassThrough FMU.
report: deps fmus $(VENV)/.installed
	cargo bench --bench accuracy_cost
	$(PY) benches/report.py

clean:
	cargo clean
	rm -rf out $(VENV)

## Robot joint: an antagonistic McKibbenMuscle pair on a pulley under PD pressure control,
## co-simulated with FMPy (out/robot_joint.{csv,png}) and with the fmi crate (out/robot_joint_fmi.csv).
robot-joint: deps fmus $(VENV)/.installed
	$(PY) examples/robot_joint.py --out out
	cargo run --release --example robot_joint

## FMI cross-check files crosscheck/<Model>/<Model>_{in,ref}.csv, _ref.opt and the plots
## docs/fmu/<Model>.png, then the FMUs again so that each documentation/ carries its plot.
crosscheck: fmus $(VENV)/.installed
	$(PY) crosscheck/generate.py
	target/release/package_fmus $(LIB) target/fmu

## The robot joint as a system: out/systems/RobotJoint.ssp (fmpy simulate_ssp) and the container
## FMU out/systems/RobotJoint.fmu (fmu-manipulation-toolbox), both run and plotted against the
## two-FMU co-simulation: out/systems/robot_joint_systems.png.
systems: fmus $(VENV)/.installed
	$(PY) systems/build.py --run

## Design sweep on Dask (not part of `make test`): bladder pre-strain x wall thickness -> net work per
## stroke of the McKibbenMuscle FMU, out/sweep.{csv,png}. Local cluster by default; any running
## scheduler with `make sweep SCHEDULER=tcp://host:8786`.
sweep: fmus $(VENV)/.installed
	$(PY) examples/sweep_dask.py --out out $(if $(SCHEDULER),--scheduler $(SCHEDULER))

## ---- Reliability jobs (issue 8): longer runs, not part of `make test`. ----
.PHONY: fuzz memcheck

FUZZ_SECONDS ?= 120
## Fuzzes random FMI call sequences on both models for FUZZ_SECONDS (cargo-fuzz, nightly Rust).
## The committed seeds in fuzz/corpus/call_sequences are only read; new inputs go to the ignored
## fuzz/corpus-run/, crashes to fuzz/artifacts/. Nothing is committed.
fuzz:
	@command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
	@rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
	mkdir -p fuzz/corpus-run/call_sequences
	cargo +nightly fuzz run call_sequences $(CURDIR)/fuzz/corpus-run/call_sequences \
	  $(CURDIR)/fuzz/corpus/call_sequences -- -max_total_time=$(FUZZ_SECONDS) -timeout=10 \
	  -rss_limit_mb=2048 -print_final_stats=1

## The FMPy suite under valgrind memcheck: any memory error, or a leak allocated outside CPython
## and NumPy, fails. PYTHONMALLOC=malloc lets valgrind see every Python allocation.
MEMCHECK_TESTS ?= tests/fmpy
memcheck: fmus $(VENV)/.installed
	@command -v valgrind >/dev/null || { \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq valgrind; }
	PYTHONMALLOC=malloc valgrind --tool=memcheck --error-exitcode=1 \
	  --suppressions=tests/valgrind-python.supp --leak-check=full \
	  --errors-for-leak-kinds=definite --show-leak-kinds=definite --num-callers=30 \
	  $(PY) -m pytest -q -p no:cacheprovider $(MEMCHECK_TESTS)
