# gearte — the two set-up commands of the README live here.
#   make demo   creates .venv, installs gearte (runtime dependencies only), compiles its numba kernels
#               (`gearte warm-cache`), runs the bundled RV-80E case and writes out/demo/report.html
#   make test   creates .venv, installs gearte with its test tools, runs lint, type checks and tests
# Both install the exact releases of requirements/constraints.txt, so a red run is told apart from
# upstream drift. `make test-latest` tests the newest releases in a separate venv (.venv-latest);
# `make lock` rewrites the constraints from a fresh resolve.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
CONSTRAINTS := requirements/constraints.txt
HASH   := $(shell cat pyproject.toml $(CONSTRAINTS) | cksum | cut -d' ' -f1)
RUN_STAMP := $(VENV)/.installed-run-$(HASH)
DEV_STAMP := $(VENV)/.installed-dev-$(HASH)
PIP    := $(BIN)/python -m pip install --disable-pip-version-check -c $(CONSTRAINTS)
DEMO_CASE ?= hu2020_rv80e_initial
# pytest workers (pytest-xdist): one per core; TEST_WORKERS=0 runs the suite in one process
TEST_WORKERS ?= auto
PYTEST := $(BIN)/python -m pytest -q -n $(TEST_WORKERS)

.PHONY: demo test test-slow test-latest lint typecheck bench lock clean fuzz fuzz-extremes docs \
	release-check signal-stress

$(VENV)/bin/python:
	@echo "==> creating $(VENV) with $(PYTHON)"
	$(PYTHON) -m venv $(VENV)

# --no-compile: pip byte-compiles every installed module otherwise (~24 s of CPU for scipy,
# matplotlib, numba...); Python compiles the few that gearte imports on first use instead.
$(RUN_STAMP): pyproject.toml $(CONSTRAINTS) | $(VENV)/bin/python
	@echo "==> installing gearte and its runtime dependencies (pinned by $(CONSTRAINTS))"
	$(PIP) --progress-bar on --no-compile -e .
	rm -f $(VENV)/.installed-run-*
	touch $(RUN_STAMP)

$(DEV_STAMP): $(RUN_STAMP)
	@echo "==> installing the test tools (pytest, hypothesis, ruff, mypy, dask)"
	$(PIP) --progress-bar on -e ".[dev]"
	rm -f $(VENV)/.installed-dev-*
	touch $(DEV_STAMP)

# numba compiles each kernel on its first use and caches it (keyed by source path and mtime):
# compile them all once now, with progress, so that the first run of any kind loads them.
WARM_STAMP := $(VENV)/.numba-warm
$(WARM_STAMP): $(RUN_STAMP) $(shell find src/gearte -name '*.py')
	$(BIN)/gearte warm-cache
	touch $(WARM_STAMP)

demo: $(RUN_STAMP) $(WARM_STAMP)
	$(BIN)/gearte run $(DEMO_CASE) --out out/demo
	@echo "report: out/demo/report.html"

test: $(DEV_STAMP)
	@echo "==> ruff"
	$(BIN)/ruff check src tests benchmarks
	@echo "==> mypy (pydantic plugin; config in pyproject.toml)"
	$(BIN)/mypy src/gearte
	@echo "==> pytest"
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test $(PYTEST)

# The docs site (mkdocs.yml) into site/, offline and strict (a broken link or reference fails);
# the gallery runs the paper cases once per source tree (cached in .docs_cache/);
# GEARTE_DOCS_GALLERY=0 leaves it out.
docs: $(DEV_STAMP)
	NO_MKDOCS_2_WARNING=1 NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test $(BIN)/mkdocs build --strict
	@echo "docs: site/index.html"

# The long fuzzing job (issue 13): FUZZ_COUNT mutants of the bundled cases through validation,
# the accepted ones also through `gearte run` (FUZZ_RUNS of them; -1: every one) in children of
# a warm fork server (one per core), FUZZ_EQUIVALENCE of them also as real `gearte run`
# processes, and FUZZ_FILES mutated measurement files through their readers (docs/errors.md,
# "Fuzzing"). Every mutant and run is recorded in out/fuzz.jsonl.
FUZZ_COUNT ?= 10000
FUZZ_FILES ?= 10000
FUZZ_RUNS ?= -1
FUZZ_EQUIVALENCE ?= 20
FUZZ_RUN_CPU ?= 60
fuzz: $(DEV_STAMP)
	mkdir -p out
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test nice -n 10 $(BIN)/python tests/fuzzing.py \
		--count $(FUZZ_COUNT) --files $(FUZZ_FILES) --runs $(FUZZ_RUNS) \
		--run-cpu-limit $(FUZZ_RUN_CPU) --run-timeout 600 \
		--equivalence $(FUZZ_EQUIVALENCE) --record out/fuzz.jsonl

# The systematic sweep of extreme values (docs/errors.md, "The extreme-value sweep"): every
# positive number of every bundled case = 1e-300, x 1e-9 and x 1e9 in turn (~2 600 case files),
# validated, and the accepted ones run as in `make fuzz`; ~8 min on 2 cores. Recorded in
# out/fuzz_extremes.jsonl.
fuzz-extremes: $(DEV_STAMP)
	mkdir -p out
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test nice -n 10 $(BIN)/python tests/fuzzing.py \
		--count -1 --runs -1 --run-cpu-limit $(FUZZ_RUN_CPU) --run-timeout 600 \
		--record out/fuzz_extremes.jsonl

# The release check (docs/release.md): build the sdist and the wheel, check their metadata, install
# the wheel alone (no source tree) in a fresh venv from the constraints and run the demo case with
# it, outside the clone. ~1 min with pip's download cache filled; not part of `make test`.
RELEASE_VENV := .venv-release
release-check: $(DEV_STAMP)
	rm -rf dist $(RELEASE_VENV) out/release-check
	$(BIN)/python -m build
	$(BIN)/twine check --strict dist/*
	$(PYTHON) -m venv $(RELEASE_VENV)
	$(RELEASE_VENV)/bin/python -m pip install --disable-pip-version-check --no-compile \
		-c $(CONSTRAINTS) dist/gearte-*.whl
	mkdir -p out/release-check
	cd out/release-check && ../../$(RELEASE_VENV)/bin/python -c \
		"import gearte, importlib.resources as r; \
		assert r.files('gearte').joinpath('py.typed').is_file(), 'py.typed missing'; \
		assert 'site-packages' in gearte.__file__, gearte.__file__; print('gearte', gearte.__version__, 'from', gearte.__file__)"
	cd out/release-check && ../../$(RELEASE_VENV)/bin/gearte run $(DEMO_CASE) --out demo
	@echo "release check passed: dist/ holds the sdist and the wheel"

# SIGNAL_COUNT SIGINT and SIGNAL_COUNT SIGTERM at random times to real `gearte run` processes
# (a Monte-Carlo, a planetary Monte-Carlo, a yield run with an allocation search; threads and
# processes) beside two busy processes: no hang, no traceback, partial results as documented
# (docs/errors.md, "Signals"); ~15 min on 2 cores. Recorded in out/signals.jsonl.
SIGNAL_COUNT ?= 50
signal-stress: $(DEV_STAMP)
	mkdir -p out
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test nice -n 10 $(BIN)/python tests/signal_stress.py \
		--count $(SIGNAL_COUNT) --load 2 --record out/signals.jsonl

test-slow: $(DEV_STAMP)
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_test $(PYTEST) -m slow

# The newest releases of every dependency, resolved now (no constraints): tells upstream drift apart.
test-latest:
	rm -rf .venv-latest
	$(PYTHON) -m venv .venv-latest
	.venv-latest/bin/python -m pip install --disable-pip-version-check --upgrade -e ".[dev]"
	.venv-latest/bin/ruff check src tests benchmarks
	NUMBA_CACHE_DIR=$(CURDIR)/.numba_cache_latest .venv-latest/bin/python -m pytest -q -n $(TEST_WORKERS)

lock:
	rm -rf .venv-lock
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --disable-pip-version-check --upgrade -e ".[dev]"
	{ sed -n '1,3p' $(CONSTRAINTS); .venv-lock/bin/pip freeze --exclude-editable | grep -vi '^gearte' | sort -f; } > $(CONSTRAINTS).new
	mv $(CONSTRAINTS).new $(CONSTRAINTS)
	rm -rf .venv-lock

lint: $(DEV_STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks

typecheck: $(DEV_STAMP)
	$(BIN)/mypy src/gearte

bench: $(DEV_STAMP)
	for b in benchmarks/bench_*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) .venv-latest $(RELEASE_VENV) dist out .numba_cache_test .numba_cache_latest .pytest_cache site .docs_cache
