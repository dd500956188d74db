# rockfrag - make targets. Every target bootstraps its own virtual environment (.venv) on first
# use and re-installs it when pyproject.toml changes, so a fresh clone needs nothing else.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
ROCKFRAG := $(BIN)/rockfrag
UV     := $(BIN)/uv
REPORTS := reports
# pytest-xdist workers of the test targets (auto: one per core); `make test WORKERS=0` runs in one process.
WORKERS ?= auto
PYTEST := $(BIN)/python -m pytest -n $(WORKERS) --dist loadgroup
# Consumer environments (tests/consumers/README.md): .venv-NAME from tests/consumers/NAME.txt.
CONSUMERS := $(patsubst tests/consumers/%.txt,%,$(filter-out %.no-deps.txt,$(wildcard tests/consumers/*.txt)))
CONSUMER_STAMPS := $(CONSUMERS:%=.venv-%/.installed)

.DEFAULT_GOAL := help
.PHONY: help install consumers warm warm-imports lint test test-fast docs records cube fragility bench clean

help:  ## list the targets
	@echo "rockfrag make targets:"
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/^([a-z-]+):.*## /  make \1\t/' | expand -t 20

# Bytecode is written on first import (--no-compile: pip would compile every installed module on one core,
# about half the install time). PYTHONDONTWRITEBYTECODE would make every test process compile its imports again
# (minutes of CPU in make test), so the targets here do not pass it on.
unexport PYTHONDONTWRITEBYTECODE

# uv (from PyPI) installs into the venv in seconds where pip takes about a minute; it resolves the same
# versions from the same index and, like --no-compile, leaves bytecode to the first import.
# The venv is made without pip (installing pip into it took 7 s of a fresh clone's set-up); the system's pip
# (22.3 or later: --python) puts uv into it. Without such a pip, the venv gets its own pip, which installs uv.
$(STAMP): pyproject.toml
	$(PYTHON) -m venv --without-pip $(VENV)
	$(PYTHON) -m pip --python $(BIN)/python install --quiet --no-compile 'uv>=0.5' \
	  || { $(PYTHON) -m venv $(VENV) && $(BIN)/python -m pip install --quiet --no-compile 'uv>=0.5'; }
	$(UV) pip install --quiet --python $(BIN)/python -e '.[test,docs]'
	touch $(STAMP)

install: $(STAMP)  ## create .venv and install rockfrag with its test and documentation tools

# A consumer environment never stops make: a failed build leaves no stamp, and the test that needs it fails
# under `make test` (ROCKFRAG_CONSUMERS=required) with the log's name, after every other test has run.
# Its scripts run once with --help, which imports the consumer: that writes the bytecode of what the round trip
# imports (4-8 s of CPU per environment, here on the core the kernel compile leaves idle, not in the tests).
.SECONDEXPANSION:
.venv-%/.installed: tests/consumers/%.txt $$(wildcard tests/consumers/$$*.no-deps.txt) $(STAMP)
	@rm -rf .venv-$* && echo "building the $* consumer environment .venv-$* (log: .venv-$*.log)"
	@if { $(UV) venv --quiet --python $(BIN)/python .venv-$* \
	      && if [ -f tests/consumers/$*.no-deps.txt ]; then \
	           $(UV) pip install --python .venv-$*/bin/python --no-deps -r tests/consumers/$*.no-deps.txt; fi \
	      && $(UV) pip install --python .venv-$*/bin/python -r tests/consumers/$*.txt \
	      && for script in tests/consumers/$*_*.py; do NUMBA_DISABLE_JIT=1 .venv-$*/bin/python $$script --help; done; \
	    } > .venv-$*.log 2>&1; \
	then touch $@; else echo "the $* consumer environment failed to build: see .venv-$*.log" >&2; exit 1; fi

consumers: $(CONSUMER_STAMPS)  ## build the consumer environments (.venv-pelicun, .venv-openquake) of the round-trip tests

# Compiles the numba kernels into their on-disk cache once, so that the test workers load them instead of
# each compiling them (about 25 s of CPU in a fresh clone, a second when cached).
warm: $(STAMP)
	$(BIN)/python -m tests.warm_kernels

# Writes the bytecode of the package, the tests (assert-rewritten, as pytest collects them) and the libraries they
# import once (14-18 s of CPU in a fresh clone), beside the kernel compile, instead of in pytest and each of its
# workers side by side.
warm-imports: $(STAMP)
	$(BIN)/python -m tests.warm_imports

# The main environment, the kernel cache, the bytecode and the consumer environments are built side by side
# (-j2); only a failed main environment stops here (make -q: is the stamp up to date).
test:  ## run every test (physics verification and consumer round trips included) on all cores
	@$(MAKE) --no-print-directory -j2 -k warm warm-imports consumers || $(MAKE) --no-print-directory -q $(STAMP)
	$(BIN)/ruff check .
	ROCKFRAG_CONSUMERS=required $(PYTEST)

test-fast: warm  ## the tests without the `slow` ones, for while you work (consumer round trips if built)
	$(BIN)/ruff check .
	$(PYTEST) -m "not slow"

# The site is built afresh each time (what an earlier build generated is removed; -E: autodoc pages would not notice a
# changed docstring otherwise), warnings are errors, and every tutorial executes (docs/conf.py). `make test` builds it too: tests/test_docs.py runs this target
# on one pytest worker beside the other tests.
DOCS_HTML := docs/_build/html
docs: $(STAMP)  ## build the documentation site into docs/_build/html (tutorials executed, warnings are errors)
	rm -rf docs/_build docs/_generated docs/tutorials docs/reference/api docs/sg_execution_times.rst
	$(BIN)/python -m sphinx -E -W --keep-going -q -b html -d docs/_build/doctrees docs $(DOCS_HTML)
	@echo "the site: $(DOCS_HTML)/index.html"

lint: $(STAMP)  ## the style gate alone: ruff (pyflakes, pycodestyle at 120 characters, import order, numpy docstrings)
	$(BIN)/ruff check .

records: $(STAMP)  ## intensity-measure table and per-record plots of all shipped records
	$(ROCKFRAG) records --set all --plot --output $(REPORTS)

fragility: $(STAMP)  ## run the whole pipeline (records -> cube -> IDA -> fragility -> report)
	$(ROCKFRAG) fragility --output $(REPORTS)

cube: $(STAMP)  ## run the default study into reports/cube.nc (resumes after an interruption)
	$(ROCKFRAG) run --output $(REPORTS)

bench: $(STAMP)  ## solver and study benchmarks (prints figures; not part of the tests)
	$(BIN)/python benchmarks/run.py

clean:  ## remove generated reports, caches and the virtual environments
	rm -rf $(REPORTS) $(VENV) .venv-* .pytest_cache .hypothesis build *.egg-info
	rm -rf docs/_build docs/_generated docs/tutorials docs/reference/api docs/sg_execution_times.rst
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
