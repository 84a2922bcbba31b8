# spur_cad developer tasks. `make test`: the fast tier, before every commit (ruff, mypy + the tests not marked
# slow/freecad/linuxcnc/browser, a few minutes). `make test-all`: everything (what CI runs through .ci/run).

VENV        := .venv
PYTHON      := $(VENV)/bin/python
STAMP       := $(VENV)/.installed
PYTEST_ARGS ?=

FAST_TIER   := not slow and not freecad and not linuxcnc and not browser
# The markers `make test` selects; CI's FreeCAD 1.0 / 1.1 tiers add the FreeCAD tests (.ci/tier)
MARKS       ?= $(FAST_TIER)
# Tests not marked freecad run on up to 4 workers (pytest-xdist), a test file each at a time (its module fixtures
# computed once): every test writes under its own tmp_path. The FreeCAD tests (their GUI tests start Xvfb servers and
# FreeCAD's own windows) run afterwards in one process. `make test PARALLEL=` runs everything in one process.
PARALLEL    ?= -n auto --maxprocesses=4 --dist loadfile

.PHONY: venv demo test test-all run-tests lint bench clean

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

# `make test` with MARKS naming FreeCAD tests (CI's FreeCAD 1.0 / 1.1 tiers) runs them after the others.
WITH_FREECAD = $(if $(subst $(FAST_TIER),,$(MARKS)),yes,)

# Both parts run even when the first fails (every failure is seen in one run); pytest's exit 5 ("no tests
# selected": MARKS that select only FreeCAD tests, or none of them) counts as success for either part.
run-tests: venv
	@status=0; \
	$(PYTHON) -m pytest -q $(PARALLEL) -m "($(MARKS)) and not freecad" $(PYTEST_ARGS) || [ $$? -eq 5 ] || status=1; \
	if [ -n "$(WITH_FREECAD)" ]; then \
	    $(PYTHON) -m pytest -q -m "($(MARKS)) and freecad" $(PYTEST_ARGS) || [ $$? -eq 5 ] || status=1; \
	fi; \
	exit $$status

test: lint
	@$(MAKE) --no-print-directory run-tests

test-all: lint
	@$(MAKE) --no-print-directory run-tests MARKS="slow or not slow"

bench: venv
	$(VENV)/bin/pip install -q -e '.[test,bench]'
	$(PYTHON) -m benchmarks.run_benchmarks

clean:
	rm -rf out/ build/ dist/ test-artifacts/ .pytest_cache/ *.egg-info
	find . -path ./$(VENV) -prune -o -type d -name __pycache__ -prune -exec rm -rf {} +
