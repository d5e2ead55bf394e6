# Two entry points that work on a fresh machine with Python 3.11:
#   make run   - set up .venv and run the main job (softbend reproduce) end to end
#   make test  - set up .venv and run the test suite (fast subset; `make test-all` adds slow cases)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= results/reproduce

.PHONY: setup run test test-all lint typecheck docs bench clean

$(BIN)/.softbend-installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[all,dev]"
	touch $@

setup: $(BIN)/.softbend-installed

run: setup
	$(BIN)/softbend reproduce --out $(OUT)

test: setup
	$(BIN)/python -m pytest -q -m "not slow"

test-all: setup
	$(BIN)/python -m pytest -q

lint: setup
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples

# mypy on the whole package with [tool.mypy] of pyproject.toml (about 20 s cold, 1 s cached).
typecheck: setup
	$(BIN)/mypy

# The generated pages of docs/ (the command-line reference); a test checks they are current.
docs: setup
	$(BIN)/python docs/gen_cli_reference.py
	@if [ -f $(OUT)/summary.json ]; then $(BIN)/python docs/gen_validation.py $(OUT)/summary.json; \
	else echo "docs/validation.md kept: make run writes $(OUT)/summary.json"; fi

bench: setup
	$(BIN)/python benchmarks/bench_identification.py

clean:
	rm -rf $(VENV) results .pytest_cache .ruff_cache .mypy_cache
