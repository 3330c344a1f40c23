# The README's two commands: `make demo` and `make test`. Each creates or refreshes
# .venv, installs the project with its test extra, builds the FMUs into dist/ and runs.
# `make check` is the quick loop while developing: ruff and the fast tier of the tests.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test check build docs lint format clean

# The docs check: strict mode fails on any warning (a broken link, an unknown reference).
# Never add --quiet: it drops the warnings strict mode counts, and a broken link passes
# (tests/test_docs.py runs this very command on a copy of the docs with a broken link).
MKDOCS := $(BIN)/python -m mkdocs build --strict

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

build: $(STAMP)
	$(BIN)/arcosim build --out dist

demo: build
	$(BIN)/arcosim reproduce --fmus dist --force

test: build
	$(BIN)/arcosim validate dist/*.fmu
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(MKDOCS)
	$(BIN)/python -m pytest

# The fast tier: every test not marked slow (over ~5 s) or system (runs a host, a
# command over FMUs, valgrind, other Pythons, mkdocs …); markers in pyproject.toml.
check: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest -m "not slow and not system"

docs: $(STAMP)
	$(MKDOCS)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

clean:
	rm -rf dist reports build .site *.egg-info .pytest_cache .ruff_cache
