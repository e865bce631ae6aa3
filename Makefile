# fricid: two commands on a fresh machine, `make demo` and `make test`.
# `make test` leaves out the tests marked slow (a few minutes on two cores); `make test-all`
# runs the whole suite, as CI (.ci/run) does; `make docs` builds the documentation site.
# Both run the tests in TEST_JOBS processes (pytest-xdist), a test file to a process so that a
# module's fixtures are built once (`make test TEST_JOBS=1` runs them in one), then the tests
# marked serial alone: they send signals at moments that the other process's load shifts.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
TEST_JOBS ?= 2
PYTEST := $(BIN)/python -m pytest
PARALLEL := -n $(TEST_JOBS) --dist loadfile
STAMP  := $(VENV)/.installed
DEVSTAMP := $(VENV)/.installed-dev
DOCSTAMP := $(VENV)/.installed-docs

.PHONY: demo test test-all lint docs bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e .
	touch $@

$(DEVSTAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP) $@

$(DOCSTAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	touch $(STAMP) $@

demo: $(STAMP)
	$(BIN)/fricid demo

test: $(DEVSTAMP)
	$(PYTEST) $(PARALLEL) -m "not slow and not serial"
	$(PYTEST) -m "serial and not slow"

test-all: $(DEVSTAMP)
	$(PYTEST) $(PARALLEL) -m "not serial"
	$(PYTEST) -m serial

lint: $(DEVSTAMP)
	$(BIN)/ruff check src tests benchmarks docs
	$(BIN)/ruff format --check src tests benchmarks docs

# The documentation site (mkdocs.yml) into site/, offline; any warning fails the build.
docs: $(DOCSTAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet

bench: $(STAMP)
	@for b in benchmarks/bench_*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) build dist site src/*.egg-info .pytest_cache fricid-demo
