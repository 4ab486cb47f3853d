# fpdtw: two commands do everything on a machine with python3 and make:
#   make figures   environment, data, every notebook, figures/ and tables
#   make test      environment, data, lint, the test suite (incl. smoke notebooks)
# Offline? Point FPDTW_MIRROR at a folder or base URL holding a copy of the data.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp

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
LIB_SRC   := $(wildcard fpdtw/*.py fpdtw/*/*.py)
# smoke runs write their figures and results under build/smoke, never over figures/
SMOKE_ENV := FPDTW_FIGURES_DIR=$(CURDIR)/$(SMOKE_DIR)/figures FPDTW_RESULTS_DIR=$(CURDIR)/$(SMOKE_DIR)/results

.PHONY: env data test lint format figures bench clean distclean help

help:
	@echo "make figures  - build env, fetch data, run every notebook, write figures/"
	@echo "make test     - build env, fetch data, lint and run the test suite"
	@echo "make data     - fetch and verify the data listed in data_manifest/"
	@echo "make bench    - per-frame latency benchmark (results/bench.json)"
	@echo "Set FPDTW_MIRROR=/path/or/url to fetch from a mirror instead of upstream."

env: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --upgrade pip
	$(PY) -m pip install -e ".[test,notebooks]"
	$(PY) -m ipykernel install --sys-prefix --name fpdtw --display-name "fpdtw (.venv)"
	touch $@

data: $(DATA_STAMP)

$(NUMBA_STAMP): $(LIB_SRC)
	rm -rf $(NUMBA_CACHE_DIR)
	mkdir -p $(NUMBA_CACHE_DIR) && touch $@

$(DATA_STAMP): $(STAMP) $(wildcard data_manifest/*.toml)
	$(PY) -m fpdtw.data fetch
	mkdir -p $(dir $@) && touch $@

lint: $(STAMP)
	$(VENV)/bin/ruff check fpdtw tests tools
	$(VENV)/bin/ruff format --check fpdtw tests tools

format: $(STAMP)
	$(VENV)/bin/ruff format fpdtw tests tools
	$(VENV)/bin/ruff check --fix fpdtw tests tools

# the test suite, then the smoke notebooks re-executed under nbval (lax: only cells
# marked NBVAL_CHECK_OUTPUT are compared with the papermill run's outputs)
test: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) lint $(SMOKE_NBS)
	$(VENV)/bin/pytest -q
	$(SMOKE_ENV) $(VENV)/bin/pytest -q -p no:cacheprovider --nbval-lax $(SMOKE_NBS)

$(SMOKE_DIR)/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	mkdir -p $(dir $@)
	$(SMOKE_ENV) $(PY) -m papermill --kernel fpdtw --cwd notebooks -p SMOKE True $< $(@:.ipynb=.part.ipynb)
	mv $(@:.ipynb=.part.ipynb) $@

bench: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP)
	$(PY) -m fpdtw.bench

# every notebook is executed by papermill into build/notebooks (sources never edited
# in place), with an explicit kernel and the notebooks folder as working directory
figures: $(EXECUTED)

build/notebooks/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	mkdir -p $(dir $@)
	$(PY) -m papermill --kernel fpdtw --cwd notebooks -p SMOKE False $< $(@:.ipynb=.part.ipynb)
	mv $(@:.ipynb=.part.ipynb) $@

clean:
	rm -rf build .pytest_cache

distclean: clean
	rm -rf $(VENV) data_cache results
