# gearte — the two set-up commands of the README live here.
#   make demo   creates .venv, installs gearte, runs the bundled RV-80E case and writes out/demo/report.html
#   make test   creates .venv, installs gearte with its test tools, runs lint and the test suite
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
DEMO_CASE ?= hu2020_rv80e_initial

.PHONY: demo test test-slow lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	rm -f $(VENV)/.installed-*
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/gearte run $(DEMO_CASE) --out out/demo
	@echo "report: out/demo/report.html"

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test $(BIN)/python -m pytest -q

test-slow: $(STAMP)
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test $(BIN)/python -m pytest -q -m slow

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) out .numba_cache_test .pytest_cache
