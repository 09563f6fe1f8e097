# Two user-facing targets: `make run` (the main job) and `make test` (every check and test).
# Both set everything up from a fresh clone: a virtual environment in .venv with the pinned
# tools of requirements-dev.txt, and the compiled extension built into it by maturin.
#
# Compile work is shared: the release build (maturin) compiles the dependencies once, in the
# release profile, and the Rust tests then run in that profile with both crates selected, so
# cargo resolves the same dependency features and reuses those compiled dependencies instead of
# building them again (a plain `cargo test -p vinculo` builds them a second time, in the dev
# profile and with other features). clippy type-checks after the build, also in the release
# profile, so that it reuses the build's compiled proc-macros and build scripts (1.5 instead of
# 4.5 minutes from a fresh clone), with the environment maturin gives pyo3's build scripts
# (`RUST_LOG=maturin=debug maturin develop` shows it): without it clippy would rerun them, and
# the next `make build` would recompile pyo3 and the binding crate (15 s).

PYTHON ?= python3

# An x86-64 machine with the instructions of x86-64-v3 (AVX2, FMA, BMI2, F16C, MOVBE, LZCNT:
# processors since about 2013-2015) gets code for that level: the mooring lines' steps take 4
# to 8 % less CPU time (the benchmark's chain on the seabed of 20, 100 and 1,000 segments,
# least of three or four runs), the pendulum's and the 10^6-particle chain's the same. Other machines
# get the default level. A RUSTFLAGS of the environment is used as it is (`RUSTFLAGS= make
# build` for the baseline level: valgrind 3.19 does not decode some x86-64-v3 instructions).
# Every cargo and maturin command below runs with the same flags, so that they share their
# compiled work.
X86_64_V3 := $(shell f=/proc/cpuinfo; [ "$$(uname -m)" = x86_64 ] && \
	for x in avx2 fma bmi2 f16c movbe abm; do grep -qw $$x $$f 2>/dev/null || exit 1; done && \
	echo yes)
ifeq ($(X86_64_V3),yes)
RUSTFLAGS ?= -C target-cpu=x86-64-v3
endif
export RUSTFLAGS
VENV := .venv
VENV_STAMP := $(VENV)/.installed
# pip is told to be quiet through the environment, so that the pip run inside `maturin develop`
# does not list every requirement that is already satisfied.
QUIET_PIP := PIP_QUIET=1 PIP_DISABLE_PIP_VERSION_CHECK=1

.PHONY: run test build rust-test clippy docs .venv

## run: build, then run the main job (the buoy study; tables, figures and summary go to output/)
run: build
	$(VENV)/bin/vinculo buoy --output output

## test: formatting, build, Rust lints, Rust tests, Python lint, the strict docs build, Python
## tests, in that order (pytest last, so that its summary closes the output)
test: $(VENV_STAMP)
	cargo fmt --all --check
	$(MAKE) clippy
	$(MAKE) rust-test
	$(VENV)/bin/ruff check python tests examples tools
	$(MAKE) docs
	$(VENV)/bin/pytest

# The Rust tests, in the release profile with both crates selected (see the top of this file).
# The binding crate has no test targets of its own (its behaviour is tested through pytest).
rust-test:
	cargo test --release -p vinculo -p vinculo-python

# Build, then lint in the release profile with maturin's pyo3 environment (see the top of this
# file); a target of its own so that the configuration file maturin writes is found.
clippy: build
	PYO3_BUILD_EXTENSION_MODULE=1 \
	PYO3_CONFIG_FILE="$(firstword $(wildcard $(CURDIR)/target/maturin/pyo3-config-*.txt))" \
	PYO3_ENVIRONMENT_SIGNATURE="$$($(VENV)/bin/python -c 'import struct, sys; print("cpython-%d.%d-%dbit" % (*sys.version_info[:2], 8 * struct.calcsize("P")))')" \
	PYO3_PYTHON=$(CURDIR)/$(VENV)/bin/python VIRTUAL_ENV=$(CURDIR)/$(VENV) \
	cargo clippy --workspace --all-targets --release -- -D warnings

## docs: build the documentation site into site/ in strict mode (any warning fails the build):
## runs every example for the gallery and generates the command-line reference (see mkdocs.yml)
docs: build
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site

# Build the extension in release mode and install the package (editable) into .venv, showing
# cargo's progress (compiling the dependencies takes minutes the first time; see the README).
# maturin and cargo rebuild incrementally, so this is quick when nothing changed.
build: $(VENV_STAMP)
	@echo "building the extension (release; first build compiles the dependencies: minutes)"
	VIRTUAL_ENV=$(CURDIR)/$(VENV) $(QUIET_PIP) $(VENV)/bin/maturin develop --release

.venv: $(VENV_STAMP)

# The stamp file makes the installation happen once (and again when the pins change).
$(VENV_STAMP): requirements-dev.txt
	@echo "setting up $(VENV): the pinned tools of requirements-dev.txt (about a minute the first time)"
	$(PYTHON) -m venv $(VENV)
	$(QUIET_PIP) $(VENV)/bin/python -m pip install -r requirements-dev.txt
	touch $@
