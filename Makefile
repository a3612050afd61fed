# Developer and CI commands. `make run` and `make test` work on a fresh machine with Python >= 3.11
# and a Rust toolchain: they create .venv, install the pinned dependencies and build the engine.

SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
LOCK := requirements/lock.txt
CARGO ?= cargo

# Everything that changes the compiled extension hexadyn._core.
RUST_SOURCES := Cargo.toml Cargo.lock $(shell find crates -name '*.rs' -o -name Cargo.toml 2>/dev/null)

# Stamps inside .venv: removing .venv resets them.
DEPS_STAMP := $(VENV)/.hexadyn-deps
BUILD_STAMP := $(VENV)/.hexadyn-build

.PHONY: help setup chromium run test docs lint test-rust test-python bench bench-peer bench-urdf bench-montecarlo terrains lock clean

help:
	@echo "make run    set everything up, then run hexadyn on the default scenario"
	@echo "make test   set everything up, then run clippy and the Rust and Python tests"
	@echo "make docs   build the documentation site into site/ (mkdocs-material, warnings as errors)"
	@echo "make lint   clippy on every crate and target, warnings as errors"
	@echo "make setup  create .venv, install pinned dependencies, build the engine (release)"
	@echo "make bench  run the engine benchmarks (release)"
	@echo "make bench-peer  the 75 s AMRU5 walk and the PhantomX tripod in hexadyn and in MuJoCo, timed in the same run"
	@echo "make bench-urdf  a URDF hexapod's mass matrix and nonlinear effects in hexadyn and in Pinocchio"
	@echo "make bench-montecarlo [MC_ARGS=\"--runs 50\"]  time a Monte Carlo campaign on every core (long)"
	@echo "make terrains  regenerate the shipped terrain PLY files (python/hexadyn/scenarios/terrains)"
	@echo "make lock   re-resolve requirements/lock.txt"
	@echo "make clean  remove .venv and the Cargo target directory"

setup: $(BUILD_STAMP)

# The viewer's browser tests drive Debian's chromium (Playwright cannot download its own here);
# `make test` installs it where it is missing (as root, the CI machine), `make run` does not need it.
chromium:
	@command -v chromium >/dev/null || { apt-get update -qq && apt-get install -y -qq chromium; }

$(PY):
	$(PYTHON) -m venv $(VENV)

# Pinned dependencies and the editable install (pip runs maturin, which builds _core in release).
$(DEPS_STAMP): $(LOCK) pyproject.toml | $(PY)
	$(PY) -m pip install --quiet --disable-pip-version-check -c $(LOCK) maturin
	PATH="$(abspath $(VENV))/bin:$$PATH" \
	  $(PY) -m pip install --quiet --disable-pip-version-check -c $(LOCK) --no-build-isolation -e '.[test]'
	touch $@

# Rebuild the extension in place after a Rust change (the editable install already points here).
$(BUILD_STAMP): $(DEPS_STAMP) $(RUST_SOURCES)
	VIRTUAL_ENV=$(abspath $(VENV)) $(VENV)/bin/maturin develop --release --skip-install --quiet
	touch $@

run: setup
	$(VENV)/bin/hexadyn simulate

test: setup chromium lint test-rust test-python

# The documentation site (mkdocs.yml over docs/): the `docs` extra, part of the `test` extra that
# setup installs. --strict: a broken link or any other warning fails the build, as it fails
# tests/python/test_docs.py.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

# Clippy with the workspace's lint settings (Cargo.toml [workspace.lints]); rustup adds the
# component where it is missing.
lint:
	@$(CARGO) clippy --version >/dev/null 2>&1 || rustup component add clippy
	$(CARGO) clippy --workspace --all-targets --quiet -- -D warnings

test-rust:
	$(CARGO) test --workspace --release --exclude hexadyn-py

test-python: setup
	$(PY) -m pytest -q tests/python

bench:
	$(CARGO) run --release -p hexadyn-benches --bin engine
	$(CARGO) run --release -p hexadyn-benches --bin robot
	$(CARGO) run --release -p hexadyn-benches --bin gait
	$(CARGO) run --release -p hexadyn-benches --bin walk
	$(CARGO) run --release -p hexadyn-benches --bin link
	$(CARGO) run --release -p hexadyn-benches --bin watchdog
	$(CARGO) run --release -p hexadyn-benches --bin terrain
	$(CARGO) run --release -p hexadyn-benches --bin terrain_classes
	$(CARGO) run --release -p hexadyn-benches --bin free_gait_cases

# The shipped terrains are generated, never drawn: physics::terrain::generate, written as PLY.
terrains:
	$(CARGO) run --release -p hexadyn --example make_terrains -- python/hexadyn/scenarios/terrains

# The peer benchmark against MuJoCo (installed here, from the lock, as the `bench` extra: not a
# dependency of hexadyn or of its tests).
bench-peer: setup
	$(PY) -m pip install --quiet --disable-pip-version-check -c $(LOCK) mujoco
	$(PY) benches/peer_mujoco.py
	$(PY) benches/peer_mujoco_phantomx.py

# Rigid-body evaluation of a serial hexapod from URDF, against Pinocchio (a test dependency).
bench-urdf: setup
	$(PY) benches/urdf_rigid_body.py

# Optional: the full campaign (1000 runs x 4 velocities x 2 variants) takes hours on a laptop.
bench-montecarlo: setup
	$(PY) benches/montecarlo.py $(MC_ARGS)

# Resolve the lock in a throw-away venv (needs PyPI); review the diff before committing.
lock:
	rm -rf .lock-venv
	$(PYTHON) -m venv .lock-venv
	.lock-venv/bin/pip install --quiet maturin -e '.[test,bench]'
	{ sed -n '/^#/p' requirements/lock.txt; .lock-venv/bin/pip freeze --exclude-editable | grep -v '^hexadyn'; } > requirements/lock.txt.new
	mv requirements/lock.txt.new requirements/lock.txt
	rm -rf .lock-venv

clean:
	rm -rf $(VENV) target
