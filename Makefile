# Two entry points that work on a fresh machine with Python 3.11:
#   make run   - set up .venv and run the main job (softbend reproduce) end to end
#   make test-full - set up .venv and run the test suite that CI runs (all but the slow physics)
#   make test  - the quick loop between edits (about 5 minutes on 2 cores; `make test-all`: every test)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= results/reproduce

.PHONY: setup run test test-full test-all lint typecheck docs bench clean

$(BIN)/.softbend-installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[all,dev,docs]"
	touch $@

setup: $(BIN)/.softbend-installed

run: setup
	$(BIN)/softbend reproduce --out $(OUT)
	@echo "report: $(OUT)/index.html; documentation: docs/index.md (make docs builds docs/_build/html)"

# The quick loop: units and one end-to-end case per stage (tests/thorough.txt lists the rest).
test: setup
	$(BIN)/python -m pytest -q -m "not slow and not thorough"

# What CI runs: every test but the slow physics cases.
test-full: setup
	$(BIN)/python -m pytest -q -m "not slow" --durations=25

test-all: setup
	$(BIN)/python -m pytest -q

lint: setup
	$(BIN)/ruff check src tests benchmarks examples docs
	$(BIN)/ruff format --check src tests benchmarks examples docs

# mypy on the whole package with [tool.mypy] of pyproject.toml (about 20 s cold, 1 s cached).
typecheck: setup
	$(BIN)/mypy

# The documentation site (Sphinx + MyST) into docs/_build/html, warnings as errors. The generated
# pages are written first: the command-line reference, the performance page (from the benchmarks'
# JSON in benchmarks/results/), the names-and-ranges page (from the declarations in the code) and, after a `make run`, the validation page from its summary.json.
# Each generated page holds only what a rerun repeats (the validation page leaves off the run's
# dates and wall time), so `make docs` leaves the tracked pages unchanged unless a figure changed.
docs: setup
	$(BIN)/python docs/gen_cli_reference.py
	$(BIN)/python docs/gen_performance.py
	$(BIN)/python docs/gen_ranges.py
	@if [ -f $(OUT)/summary.json ]; then $(BIN)/python docs/gen_validation.py $(OUT)/summary.json; \
	else echo "docs/validation.md kept: make run writes $(OUT)/summary.json"; fi
	rm -rf docs/api/_generated  # the API pages anew: a renamed module leaves no stale page
	$(BIN)/sphinx-build -j auto -W --keep-going -q -b html docs docs/_build/html
	@echo "docs/_build/html/index.html"

bench: setup
	$(BIN)/python benchmarks/bench_identification.py

clean:
	rm -rf $(VENV) results .pytest_cache .ruff_cache .mypy_cache docs/_build docs/api/_generated
