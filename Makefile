# Two entry points for a fresh machine (see README):
#   make pipeline   set up .venv and run the whole pipeline on the built-in procedural corpus
#   make test       set up .venv and run the test suite (what .ci/run calls)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
CORES ?= 2

.PHONY: setup pipeline test test-slurm bench clean

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet -e '.[test,slurm]'
	touch $@

pipeline: setup
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/snakemake --cores $(CORES)

test: setup
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pytest -q -ra -n 2 --dist loadgroup

test-slurm: setup
	timeout -s INT 900 bash tests/slurm/run.sh

bench: setup
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python bench/run_all.py

clean:
	rm -rf results logs benchmarks .snakemake
