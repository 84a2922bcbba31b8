# spur_cad developer tasks. `make test`: the fast tier, before every commit (ruff, mypy + the tests not marked
# slow/freecad/linuxcnc/browser, a few minutes). `make test-all`: everything (what CI runs through .ci/run).

VENV        := .venv
PYTHON      := $(VENV)/bin/python
STAMP       := $(VENV)/.installed
PYTEST_ARGS ?=

FAST_TIER   := not slow and not freecad and not linuxcnc and not browser
# The markers `make test` selects; CI's FreeCAD 1.0 / 1.1 tiers add the FreeCAD tests (.ci/tier)
MARKS       ?= $(FAST_TIER)
# The fast tier runs on up to 4 workers (pytest-xdist), a test file each at a time (its module fixtures computed
# once): every test writes under its own tmp_path. Other MARKS (the FreeCAD GUI tests start Xvfb servers) run in one
# process. `make test PARALLEL=` runs the fast tier in one process too.
PARALLEL    ?= $(if $(subst $(FAST_TIER),,$(MARKS)),,-n auto --maxprocesses=4 --dist loadfile)

.PHONY: venv demo test test-all lint bench clean

venv: $(STAMP)

# Create the virtual environment only when it is missing.
$(PYTHON):
	python3 -m venv $(VENV)

# The flavour a checkout installs: CadQuery 2.8 and build123d 0.12 (both on OCP 7.9), and the test tools.
# `make venv EXTRAS=build123d,test` makes the build123d 0.13 flavour (OCP 8.0) instead.
EXTRAS      ?= cadquery,build123d,test

# (Re)install the project and its extras when pyproject.toml is newer than the stamp.
$(STAMP): pyproject.toml | $(PYTHON)
	$(VENV)/bin/pip install -e '.[$(EXTRAS)]'
	touch $(STAMP)

demo: venv
	$(VENV)/bin/spur-cad run resources/examples/reference_gear.toml --out out/

lint: venv
	$(VENV)/bin/ruff check .
	$(VENV)/bin/mypy

test: lint
	$(PYTHON) -m pytest -q $(PARALLEL) -m "$(MARKS)" $(PYTEST_ARGS)

test-all: lint
	$(PYTHON) -m pytest -q $(PYTEST_ARGS)

bench: venv
	$(VENV)/bin/pip install -q -e '.[test,bench]'
	$(PYTHON) -m benchmarks.run_benchmarks

clean:
	rm -rf out/ build/ dist/ test-artifacts/ .pytest_cache/ *.egg-info
	find . -path ./$(VENV) -prune -o -type d -name __pycache__ -prune -exec rm -rf {} +
