# Two user-facing targets: `make run` (the main job) and `make test` (every check and test).
# Both set everything up from a fresh clone: a virtual environment in .venv with the pinned
# tools of requirements-dev.txt, and the compiled extension built into it by maturin.

PYTHON ?= python3
VENV := .venv
VENV_STAMP := $(VENV)/.installed

.PHONY: run test build docs .venv

## run: build, then run the main job (the buoy study; tables, figures and summary go to output/)
run: build
	$(VENV)/bin/vinculo buoy --output output

## test: formatting, lints, Rust tests, build, Python lint, the strict docs build, Python tests,
## in that order (pytest last, so that its summary closes the output)
test: $(VENV_STAMP)
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	cargo test -p vinculo
	$(MAKE) build
	$(VENV)/bin/ruff check python tests examples tools
	$(MAKE) docs
	$(VENV)/bin/pytest

## docs: build the documentation site into site/ in strict mode (any warning fails the build):
## runs every example for the gallery and generates the command-line reference (see mkdocs.yml)
docs: build
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site

# Build the extension in release mode and install the package (editable) into .venv.
# maturin and cargo rebuild incrementally, so this is quick when nothing changed.
build: $(VENV_STAMP)
	VIRTUAL_ENV=$(CURDIR)/$(VENV) $(VENV)/bin/maturin develop --release --quiet

.venv: $(VENV_STAMP)

# The stamp file makes the installation happen once (and again when the pins change).
$(VENV_STAMP): requirements-dev.txt
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements-dev.txt
	touch $@
