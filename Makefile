# The README's two commands: `make demo` and `make test`. Each creates or refreshes
# .venv, installs the project with its test extra, builds the FMUs into dist/ and runs.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test build docs lint format clean

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
	$(BIN)/python -m mkdocs build --strict --quiet
	$(BIN)/python -m pytest

docs: $(STAMP)
	$(BIN)/python -m mkdocs build --strict

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

clean:
	rm -rf dist reports build .site .docs-src *.egg-info .pytest_cache .ruff_cache
