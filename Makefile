# rockfrag - make targets. Every target bootstraps its own virtual environment (.venv) on first
# use and re-installs it when pyproject.toml changes, so a fresh clone needs nothing else.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
ROCKFRAG := $(BIN)/rockfrag
REPORTS := reports

.DEFAULT_GOAL := help
.PHONY: help install test records cube fragility bench clean

help:  ## list the targets
	@echo "rockfrag make targets:"
	@grep -E '^[a-z]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/^([a-z]+):.*## /  make \1\t/' | expand -t 20

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

install: $(STAMP)  ## create .venv and install rockfrag with its test tools

test: $(STAMP)  ## run the test suite (physics verification included)
	$(BIN)/python -m pytest

records: $(STAMP)  ## intensity-measure table and per-record plots of all shipped records
	$(ROCKFRAG) records --set all --plot --output $(REPORTS)

fragility: $(STAMP)  ## run the whole pipeline (records -> cube -> IDA -> fragility -> report)
	$(ROCKFRAG) fragility --output $(REPORTS)

cube: $(STAMP)  ## run the default study into reports/cube.nc (resumes after an interruption)
	$(ROCKFRAG) run --output $(REPORTS)

bench: $(STAMP)  ## solver and study benchmarks (prints figures; not part of the tests)
	$(BIN)/python benchmarks/run.py

clean:  ## remove generated reports, caches and the virtual environment
	rm -rf $(REPORTS) $(VENV) .pytest_cache .hypothesis build *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
