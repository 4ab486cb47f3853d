# fpdtw: two commands do everything on a machine with python3 and make:
#   make figures   environment, data, every notebook, figures/ and tables
#   make test      environment, data, lint, the test suite (incl. smoke notebooks)
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
EXTRAS := test,notebooks
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
LIB_SRC   := $(wildcard fpdtw/*.py fpdtw/*/*.py)
# smoke runs write their figures and results under build/smoke, never over figures/
SMOKE_ENV := FPDTW_FIGURES_DIR=$(CURDIR)/$(SMOKE_DIR)/figures FPDTW_RESULTS_DIR=$(CURDIR)/$(SMOKE_DIR)/results

.PHONY: env lock data test fuzz lint format figures bench clean distclean help

help:
	@echo "make figures  - build env, fetch data, run every notebook, write figures/"
	@echo "make test     - build env, fetch data, lint and run the test suite"
	@echo "make fuzz     - the fuzz tests with a 15x budget (FUZZ_SEED=0 by default)"
	@echo "make data     - fetch and verify the data listed in data_manifest/"
	@echo "make bench    - per-frame latency benchmark (results/bench.json)"
	@echo "make env      - .venv from requirements.lock (LOCKED=0: pyproject's version ranges)"
	@echo "make lock     - refresh requirements.lock with uv (UPGRADE=1: newest versions)"
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
	    "ranges of pyproject.toml instead (see README, Reproducible environment)")'
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
	$(PY) -m fpdtw.paper.datasets fetch
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

# the fuzz tests of make test (mutated BVH, ASF/AMC, FBX files through the readers and
# fpdtw align) with the larger budget of the hypothesis profile "fuzz" (tests/conftest.py),
# random examples from a fixed seed: make fuzz FUZZ_SEED=7 explores other ones
FUZZ_SEED ?= 0
fuzz: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP)
	$(VENV)/bin/pytest -q -p no:cacheprovider tests/test_fuzz.py --hypothesis-profile=fuzz \
		--hypothesis-seed=$(FUZZ_SEED) --hypothesis-show-statistics

$(SMOKE_DIR)/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	mkdir -p $(dir $@)
	$(SMOKE_ENV) $(PY) -m papermill --kernel fpdtw --cwd notebooks -p SMOKE True $< $(@:.ipynb=.part.ipynb)
	mv $(@:.ipynb=.part.ipynb) $@

bench: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP)
	$(PY) -m fpdtw.paper.bench

# Table 2's notebook shows the single-core benchmark next to the runner's timings
results/bench.json: $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	$(PY) -m fpdtw.paper.bench
build/notebooks/09_table2_timing.ipynb: results/bench.json

# every notebook is executed by papermill into build/notebooks (sources never edited
# in place), with an explicit kernel and the notebooks folder as working directory
figures: $(EXECUTED)

build/notebooks/%.ipynb: notebooks/%.ipynb $(STAMP) $(DATA_STAMP) $(NUMBA_STAMP) $(LIB_SRC)
	mkdir -p $(dir $@)
	$(PY) -m papermill --kernel fpdtw --cwd notebooks -p SMOKE False $< $(@:.ipynb=.part.ipynb)
	mv $(@:.ipynb=.part.ipynb) $@

# notebook order: the result notebooks read what 05 computes; the claims table reads
# every other notebook's facts
RESULT_NBS := 06_fig5_fig6_scores 07_table1_60hz 08_fig7_fig10_heatmaps 09_table2_timing \
              15_readings_of_algorithm_3
CLAIMS_NB  := 12_claims
$(patsubst %,build/notebooks/%.ipynb,$(RESULT_NBS)): build/notebooks/05_run_experiments.ipynb
$(patsubst %,$(SMOKE_DIR)/%.ipynb,$(RESULT_NBS)): $(SMOKE_DIR)/05_run_experiments.ipynb
build/notebooks/$(CLAIMS_NB).ipynb: $(filter-out %/$(CLAIMS_NB).ipynb %/20_align_a_live_performance.ipynb,$(EXECUTED))
$(SMOKE_DIR)/$(CLAIMS_NB).ipynb: $(filter-out %/$(CLAIMS_NB).ipynb %/20_align_a_live_performance.ipynb,$(SMOKE_NBS))

# one figure or table alone, e.g. `make figures/fig5_similarity.pdf`: runs its notebook
# (and what that notebook needs)
define FIGURE_RULE
figures/$(1)%: build/notebooks/$(2).ipynb
	@test -f $$@ || { echo "$(2) did not write $$@"; exit 1; }
endef
$(eval $(call FIGURE_RULE,data_,01_data_and_motions))
$(eval $(call FIGURE_RULE,fig1_,02_fig1_oedtw))
$(eval $(call FIGURE_RULE,fig2_,03_fig2_fig4_windows))
$(eval $(call FIGURE_RULE,fig4_,03_fig2_fig4_windows))
$(eval $(call FIGURE_RULE,fig3_,04_fig3_forecast))
$(eval $(call FIGURE_RULE,experiment_,05_run_experiments))
$(eval $(call FIGURE_RULE,fig5_,06_fig5_fig6_scores))
$(eval $(call FIGURE_RULE,fig6_,06_fig5_fig6_scores))
$(eval $(call FIGURE_RULE,table1_,07_table1_60hz))
$(eval $(call FIGURE_RULE,fig7_,08_fig7_fig10_heatmaps))
$(eval $(call FIGURE_RULE,fig10_,08_fig7_fig10_heatmaps))
$(eval $(call FIGURE_RULE,table2_,09_table2_timing))
$(eval $(call FIGURE_RULE,fig8_,10_fig8_walk_pair))
$(eval $(call FIGURE_RULE,fig9_,11_fig9_typev))
$(eval $(call FIGURE_RULE,claims,12_claims))
$(eval $(call FIGURE_RULE,opw_fig4,13_opw_fig4))
$(eval $(call FIGURE_RULE,opw_curve,13_opw_fig4))
$(eval $(call FIGURE_RULE,opw_fig5,14_opw_fig5_fig6))
$(eval $(call FIGURE_RULE,opw_fig6,14_opw_fig5_fig6))
$(eval $(call FIGURE_RULE,readings_,15_readings_of_algorithm_3))
$(eval $(call FIGURE_RULE,silent_choices,15_readings_of_algorithm_3))
$(eval $(call FIGURE_RULE,selection_,15_readings_of_algorithm_3))
$(eval $(call FIGURE_RULE,live_,20_align_a_live_performance))

clean:
	rm -rf build .pytest_cache

distclean: clean
	rm -rf $(VENV) data_cache results
