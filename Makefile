# fpdtw: two commands do everything on a machine with python3 and make:
#   make figures   environment, data, every notebook, figures/ and tables, the book
#   make test      environment, data, lint, the test suite (incl. smoke notebooks and the
#                  smoke book in a headless browser); make test-all adds the one-hour
#                  long-input check and the fuzz tests' larger budget (before a release)
# Offline? Point FPDTW_MIRROR at a folder or base URL holding a copy of the data.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

# The environment. By default `make env` (and so every target) builds .venv afresh from
# requirements.lock: exact versions, every file hash-checked by pip, for CPython 3.11 on
# Linux x86_64 (the platform the figures are made on), then the package itself without
# dependencies. LOCKED=0 (`make test LOCKED=0`, or export LOCKED=0) installs the version
# ranges of pyproject.toml instead, for other platforms. `make lock` refreshes the lock
# (UPGRADE=1: to the newest versions the ranges allow) with uv, installed from PyPI into a
# throwaway venv. Each mode has its own stamp, rebuilt when pyproject.toml (or the lock)
# changes.
LOCKED ?= 1
LOCK   := requirements.lock
EXTRAS := paper,live,cluster,book,test,notebooks,view
LOCK_PYTHON   := 3.11
LOCK_PLATFORM := x86_64-unknown-linux-gnu
UV_VERSION    := 0.13.9
LOCK_VENV     := build/lock-tool
ifeq ($(LOCKED),1)
STAMP  := $(VENV)/.installed-locked
else
STAMP  := $(VENV)/.installed-ranges
endif
comma  := ,

export PYTHONHASHSEED := 0
export FPDTW_DATA_DIR ?= $(CURDIR)/data_cache
DATA_STAMP := $(FPDTW_DATA_DIR)/.fetched-stamp

NOTEBOOKS := $(sort $(wildcard notebooks/[0-9]*.ipynb))
EXECUTED  := $(patsubst notebooks/%.ipynb,build/notebooks/%.ipynb,$(NOTEBOOKS))
# numba's on-disk cache does not notice when a kernel it inlined from another module
# changes: keep it in build/ and start it afresh whenever a library source changes
export NUMBA_CACHE_DIR := $(CURDIR)/build/numba-cache
NUMBA_STAMP := $(NUMBA_CACHE_DIR)/.sources-stamp
SMOKE_DIR := build/smoke
SMOKE_NBS := $(patsubst notebooks/%.ipynb,$(SMOKE_DIR)/%.ipynb,$(NOTEBOOKS))
# the book's tools (site, browser check, notebook runner) change no notebook's result
BOOK_SRC  := fpdtw/app/book.py fpdtw/app/browser.py fpdtw/app/execute.py
LIB_SRC   := $(filter-out $(BOOK_SRC),$(wildcard fpdtw/*.py fpdtw/*/*.py fpdtw/*/*/*.py))
RUNNER_SRC := $(wildcard fpdtw/paper/runner/*.py)
# smoke runs write their figures and results under build/smoke, never over figures/
SMOKE_ENV := FPDTW_FIGURES_DIR=$(CURDIR)/$(SMOKE_DIR)/figures FPDTW_RESULTS_DIR=$(CURDIR)/$(SMOKE_DIR)/results
SMOKE_BOOK := $(SMOKE_DIR)/book/index.html
BOOK       := build/book/index.html
# the pages of docs/ (each also a page of the book) and the files with generated blocks
DOCS       := $(sort $(wildcard docs/*.md))
READMES    := README.md ARTIFACT.md $(DOCS)
# every notebook is executed by papermill through fpdtw.app.execute (kernel fpdtw, the
# notebooks folder as working directory, parameter SMOKE), which prints when each starts
# and ends and how long it took
EXECUTE := $(PY) -m fpdtw.app.execute --kernel fpdtw --cwd notebooks

.PHONY: env lock data test test-all fuzz lint format figures check-figures book book-check \
	smoke-book bench bench-peers readme-results dist clean distclean help

help:
	@echo "make figures  - build env, fetch data, run every notebook, write figures/, the book"
	@echo "make check-figures - after make figures: figures/ byte-identical to the commit?"
	@echo "make book     - the book (build/book/index.html) from the executed notebooks"
	@echo "make book-check - open the book in headless Chromium: console errors, images, links"
	@echo "make smoke-book - the book of the smoke notebooks (build/smoke/book), as make test builds it"
	@echo "make test     - build env, fetch data, lint, the test suite, the smoke notebooks and book"
	@echo "make test-all - make test, the one-hour long-input check and make fuzz: before a release"
	@echo "make fuzz     - the fuzz tests with a 15x budget (FUZZ_SEED=0 by default)"
	@echo "make lint     - ruff check and ruff format --check;  make format - apply them"
	@echo "make data     - fetch and verify the data listed in data_manifest/"
	@echo "make bench    - per-frame latency benchmark (results/bench.json)"
	@echo "make bench-peers - OLTW against pymatchmaker, own venv (results/bench_peers.json)"
	@echo "make env      - .venv from requirements.lock (LOCKED=0: pyproject's version ranges)"
	@echo "make lock     - refresh requirements.lock with uv (UPGRADE=1: newest versions)"
	@echo "make dist     - sdist and wheel in dist/ (python -m build), checked with twine"
	@echo "make readme-results - the generated blocks of README.md, ARTIFACT.md, docs/*.md from figures/"
	@echo "make figures/<name>.pdf - one figure or table and what it needs (figures/ lists them)"
	@echo "make clean    - remove build/;  make distclean - also .venv, data_cache, results"
	@echo "make help     - this list"
	@echo "Set FPDTW_MIRROR=/path/or/url to fetch from a mirror instead of upstream."

env: $(STAMP)

# from the lock: a fresh venv (nothing left over from an older lock), every pinned file
# hash-checked (pip refuses a lock that misses a dependency), the package without
# dependencies, then pip check
$(VENV)/.installed-locked: pyproject.toml $(LOCK)
	@$(PYTHON) -c 'import platform, sys; \
	  have = "CPython %d.%d on %s %s" % (*sys.version_info[:2], sys.platform, platform.machine()); \
	  have = have if sys.implementation.name == "cpython" else sys.implementation.name + " " + have; \
	  want = "CPython $(LOCK_PYTHON) on linux x86_64"; \
	  sys.exit(0 if have == want else f"$(LOCK) is for {want}, but $(PYTHON) is {have}: " \
	    "run make with PYTHON=python$(LOCK_PYTHON), or with LOCKED=0 to install the version " \
	    "ranges of pyproject.toml instead (see docs/environment.md)")'
	$(PYTHON) -m venv --clear $(VENV)
	$(PY) -m pip install --upgrade pip
	$(PY) -m pip install --require-hashes -r $(LOCK)
	$(PY) -m pip install --no-deps -e .
	$(PY) -m pip check
	$(PY) -m ipykernel install --sys-prefix --name fpdtw --display-name "fpdtw (.venv)"
	touch $@

# from pyproject.toml's version ranges (any platform); updates an existing .venv in place
$(VENV)/.installed-ranges: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	rm -f $(VENV)/.installed-locked
	$(PY) -m pip install --upgrade pip
	$(PY) -m pip install -e ".[$(EXTRAS)]"
	$(PY) -m ipykernel install --sys-prefix --name fpdtw --display-name "fpdtw (.venv)"
	touch $@

# refresh requirements.lock from pyproject.toml (and the extras above): exact versions and
# the SHA-256 of every file PyPI has of them (wheels and sdists), resolved for
# $(LOCK_PLATFORM) and Python $(LOCK_PYTHON) whatever machine runs it. Pins already in the
# lock are kept where pyproject.toml still allows them; UPGRADE=1 takes the newest.
# Needs PyPI only (uv never downloads a Python here).
lock:
	test -x $(LOCK_VENV)/bin/python || $(PYTHON) -m venv $(LOCK_VENV)
	$(LOCK_VENV)/bin/python -m pip install --quiet --disable-pip-version-check uv==$(UV_VERSION)
	UV_PYTHON_DOWNLOADS=never $(LOCK_VENV)/bin/uv pip compile pyproject.toml \
		$(foreach e,$(subst $(comma), ,$(EXTRAS)),--extra $(e)) \
		--generate-hashes --python-version $(LOCK_PYTHON) --python-platform $(LOCK_PLATFORM) \
		--python $(LOCK_VENV)/bin/python $(if $(filter 1,$(UPGRADE)),--upgrade) -o $(LOCK) >/dev/null

data: $(DATA_STAMP)

$(NUMBA_STAMP): $(LIB_SRC)
	rm -rf $(NUMBA_CACHE_DIR)
	mkdir -p $(NUMBA_CACHE_DIR) && touch $@

$(DATA_STAMP): $(STAMP) $(wildcard data_manifest/*.toml)
	$(PY) -m fpdtw.app.cli data fetch
	mkdir -p $(dir $@) && touch $@

# The notebooks get ruff's checks (imports, unused names, line length) but not its
# formatter: their cells keep the compact layout a reader follows beside the paper.
lint: $(STAMP)
	$(VENV)/bin/ruff check fpdtw tests tools notebooks
	$(VENV)/bin/ruff format --check fpdtw tests tools

format: $(STAMP)
	$(VENV)/bin/ruff format fpdtw tests tools
	$(VENV)/bin/ruff check --fix fpdtw tests tools notebooks

# make test on 2 cores, two jobs at a time (make -j2): the test suite, except the tests
# that read the smoke run's outputs, runs beside the smoke notebooks, the smoke book and
# then those tests (its results: tests/test_results_smoke.py; the book in a browser:
# tests/test_book_browser.py); after them the smoke notebooks are re-executed under nbval,
# in two halves that take whichever job is free (lax: only cells marked
# NBVAL_CHECK_OUTPUT are compared with the papermill run's outputs). Tests marked `long`
# (the one-hour input of tests/test_long_input.py) are left to make test-all; tests marked
# `slow` (the whole-grid plain check, half an hour) run only when asked (pytest -m slow).
SMOKE_TESTS := tests/test_results_smoke.py tests/test_book_browser.py
PYTEST      := $(VENV)/bin/pytest -q -p no:cacheprovider -m "not long and not slow"
NBVAL       := $(SMOKE_ENV) $(VENV)/bin/pytest -q -p no:cacheprovider --nbval-lax
TEST_JOBS   ?= 2
test: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) lint
	$(MAKE) --no-print-directory -j$(TEST_JOBS) -Oline test-suite test-nbval-1 test-nbval-2

# the parts of make test (not meant to be run alone)
.PHONY: test-suite test-smoke test-nbval-1 test-nbval-2
test-suite:
	$(PYTEST) $(addprefix --ignore=,$(SMOKE_TESTS))
test-smoke: $(SMOKE_NBS) $(SMOKE_BOOK)
	$(PYTEST) $(SMOKE_TESTS)
test-nbval-1: test-smoke
	$(NBVAL) $(wordlist 1,8,$(SMOKE_NBS))
test-nbval-2: test-smoke
	$(NBVAL) $(wordlist 9,99,$(SMOKE_NBS))

# before a release: everything make test runs, then the tests marked long (the one-hour
# input through Method C w40 and OLTW) and the fuzz tests with make fuzz's budget
test-all: test
	$(VENV)/bin/pytest -q -p no:cacheprovider -m long
	$(MAKE) fuzz

# the fuzz tests of make test (mutated BVH, ASF/AMC, FBX files through the readers and
# fpdtw align) with the larger budget of the hypothesis profile "fuzz" (tests/conftest.py),
# random examples from a fixed seed: make fuzz FUZZ_SEED=7 explores other ones
FUZZ_SEED ?= 0
fuzz: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP)
	$(VENV)/bin/pytest -q -p no:cacheprovider tests/test_fuzz.py --hypothesis-profile=fuzz \
		--hypothesis-seed=$(FUZZ_SEED) --hypothesis-show-statistics

$(SMOKE_DIR)/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	@$(SMOKE_ENV) $(EXECUTE) --smoke $< $@

# the smoke book: the site of the smoke notebooks, which the browser test opens
smoke-book: $(SMOKE_BOOK)
$(SMOKE_BOOK): $(SMOKE_NBS) fpdtw/app/book.py $(DOCS)
	$(SMOKE_ENV) $(PY) -m fpdtw.app.book --mode smoke --notebooks $(SMOKE_DIR) --out $(@D)

bench: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP)
	$(PY) -m fpdtw.app.bench

# OLTW against pymatchmaker's OLTW-Dixon (optional). pymatchmaker needs numpy < 2, so it
# gets its own venv, build/peers-venv, NEVER the project's .venv: the project's half
# exports the bench pairs and our OLTW's times, the peers' half (run with -P: no fpdtw on
# its path) times pymatchmaker on them and writes results/bench_peers.json, which
# `make bench` shows next to our numbers
PEERS_VENV := build/peers-venv
PEERS_PY   := $(PEERS_VENV)/bin/python
PEERS_REQS := "numpy<2" "pymatchmaker==0.3.0"

$(PEERS_VENV)/.installed:
	@test "$(abspath $(PEERS_VENV))" != "$(abspath $(VENV))" || { echo "the peers' venv must not be $(VENV)"; exit 1; }
	$(PYTHON) -m venv --clear $(PEERS_VENV)
	$(PEERS_PY) -m pip install --quiet --disable-pip-version-check $(PEERS_REQS)
	touch $@

bench-peers: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(PEERS_VENV)/.installed
	$(PY) -m fpdtw.app.bench_peers export build/peers/oltw_pairs.npz
	$(PEERS_PY) -P fpdtw/app/bench_peers.py peer build/peers/oltw_pairs.npz

# Table 2's notebook shows the single-core benchmark next to the runner's timings
results/bench.json: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	$(PY) -m fpdtw.app.bench
build/notebooks/09_table2_timing.ipynb: results/bench.json
# notebook 16 shows the band's per-frame cost (Q3) from the same benchmark
build/notebooks/16_open_questions.ipynb: results/bench.json

# every notebook is executed by papermill into build/notebooks (sources never edited
# in place), with an explicit kernel and the notebooks folder as working directory; the
# book comes last
figures: $(EXECUTED) figures/ENVIRONMENT.md readme-results $(BOOK)

# the generated blocks of README.md, ARTIFACT.md and the pages of docs/, from figures/
# (fpdtw.app.readme; tests keep them in step); ARTIFACT.md's times and memory come from
# tools/measure_steps.py. After figures/ENVIRONMENT.md: it records whether the checkout had
# uncommitted changes, and these files are about to change
readme-results: $(EXECUTED) | figures/ENVIRONMENT.md
	$(PY) -m fpdtw.app.readme $(READMES) --update

# did this run reproduce the committed figures? Every deterministic file byte for byte
# (the timing outputs, fpdtw.app.publish.TIMING_OUTPUTS, may differ)
check-figures:
	$(PY) -m fpdtw.app.publish --compare-figures

# what made the figures: package versions, Python, commit, CPU (fpdtw.app.publish)
figures/ENVIRONMENT.md: $(EXECUTED)
	$(PY) -m fpdtw.app.publish --markdown $@

build/notebooks/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	@$(EXECUTE) $< $@

# The experiment grids run first, in the terminal, where the runner's progress bar shows:
# notebooks 05 (the full grid) and 15 (the study grid) then find them done and only load
# them (the runner is resumable; a re-run with nothing changed computes nothing). One grid
# at a time (order-only prerequisite), as when the notebooks ran them.
GRID_DEPS := $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC) $(RUNNER_SRC)
build/grids/%.done: $(GRID_DEPS)
	$(PY) -m fpdtw.app.cli experiments run --mode $*
	@mkdir -p $(@D) && touch $@
$(SMOKE_DIR)/grids/%.done: $(GRID_DEPS)
	$(SMOKE_ENV) $(PY) -m fpdtw.app.cli experiments run --mode $*
	@mkdir -p $(@D) && touch $@
build/grids/study.done: | build/grids/full.done
$(SMOKE_DIR)/grids/smoke-study.done: | $(SMOKE_DIR)/grids/smoke.done
build/notebooks/05_run_experiments.ipynb: build/grids/full.done
build/notebooks/15_readings_of_algorithm_3.ipynb: build/grids/study.done
$(SMOKE_DIR)/05_run_experiments.ipynb: $(SMOKE_DIR)/grids/smoke.done
$(SMOKE_DIR)/15_readings_of_algorithm_3.ipynb: $(SMOKE_DIR)/grids/smoke-study.done
# notebook 17 rescores the study grid's stored maps under each reading of eq. 2
build/notebooks/17_similarity_level.ipynb: build/grids/study.done
$(SMOKE_DIR)/17_similarity_level.ipynb: $(SMOKE_DIR)/grids/smoke-study.done
# the open questions' grid (notebook 16; its Q rows are in notebook 12's claims table)
build/grids/open.done: | build/grids/study.done
$(SMOKE_DIR)/grids/smoke-open.done: | $(SMOKE_DIR)/grids/smoke-study.done
build/notebooks/16_open_questions.ipynb build/notebooks/12_claims.ipynb: build/grids/open.done
$(SMOKE_DIR)/16_open_questions.ipynb $(SMOKE_DIR)/12_claims.ipynb: $(SMOKE_DIR)/grids/smoke-open.done
# the notebooks that print claims decide them on both grids too (the paper-shaped selection
# is the study grid's; notebook 12 rescores it under every reading): both grids come first
CLAIM_NBS := 01_data_and_motions 02_fig1_oedtw 05_run_experiments 06_fig5_fig6_scores 07_table1_60hz 09_table2_timing \
	10_fig8_walk_pair 12_claims 13_opw_fig4 14_opw_fig5_fig6 15_readings_of_algorithm_3
$(patsubst %,build/notebooks/%.ipynb,$(CLAIM_NBS)): build/grids/full.done build/grids/study.done
$(patsubst %,$(SMOKE_DIR)/%.ipynb,$(CLAIM_NBS)): $(SMOKE_DIR)/grids/smoke.done \
	$(SMOKE_DIR)/grids/smoke-study.done

# the book: one static site of the executed notebooks (outputs as they ran, nothing
# executed again) with the claims table, the data used and missing and how to rerun on its
# front page (fpdtw.app.book: Sphinx + MyST-NB); open build/book/index.html
book: $(BOOK)
$(BOOK): $(EXECUTED) figures/ENVIRONMENT.md fpdtw/app/book.py $(DOCS)
	$(PY) -m fpdtw.app.book --mode full --notebooks build/notebooks --out $(@D)

# the book in headless Chromium (Debian's chromium and chromium-driver, through Selenium):
# every page without a console error, every image loaded, every internal link resolving; a
# screenshot of every page in build/book/screenshots
book-check: $(BOOK)
	$(PY) -m fpdtw.app.browser build/book --screenshots build/book/screenshots

# notebook order and one target per figure or table (`make figures/fig5_similarity.pdf` runs
# its notebook and what that needs): generated from the one map, fpdtw/app/figure_map.py
define FIGURE_RULE
figures/$(1).%: build/notebooks/$(2).ipynb
	@test -f $$@ || { echo "$(2) did not write $$@"; exit 1; }
endef
build/figure_map.mk: fpdtw/app/figure_map.py
	mkdir -p $(dir $@)
	$(PYTHON) fpdtw/app/figure_map.py makefile > $@.part && mv $@.part $@
-include build/figure_map.mk

# a release's files: the sdist (every file of the repository: MANIFEST.in) and the wheel
# (the package), built by python -m build in a fresh isolated environment (setuptools from
# PyPI), then checked by twine (metadata, README rendering)
dist: $(STAMP)
	rm -rf dist
	$(PY) -m build --outdir dist .
	$(VENV)/bin/twine check --strict dist/*

clean:
	rm -rf build .pytest_cache

distclean: clean
	rm -rf $(VENV) data_cache results
