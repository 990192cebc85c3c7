# Two entry points for a fresh machine (see README):
#   make pipeline   set up .venv, run the whole pipeline on the built-in procedural corpus, write its report
#   make test       set up .venv and run the test suite (what .ci/run calls)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
CORES ?= 2

.PHONY: setup browser pipeline test test-slurm bench clean

VIEWER := pipeline/viewer

setup: $(VENV)/.installed $(VIEWER)/node_modules/.installed

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet -e '.[test,slurm]'
	touch $@

# three.js for the room viewer (planit view, the report's 3D gallery), pinned in its package-lock.json; each page
# inlines it, so nothing is fetched when a page opens
$(VIEWER)/node_modules/.installed: $(VIEWER)/package-lock.json
	@command -v npm >/dev/null || { echo "npm (Node.js) is needed for the room viewer: install it (Debian: apt-get install npm)"; exit 1; }
	npm ci --prefix $(VIEWER) --no-audit --no-fund --loglevel=error
	touch $@

pipeline: setup
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/snakemake --cores $(CORES)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/snakemake --report results/report.html

# The report's browser test needs Debian's chromium and chromium-driver: installed here when missing and this is a
# Debian machine run as root; elsewhere that one test skips and says why.
browser:
	@if command -v chromium >/dev/null && command -v chromedriver >/dev/null; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing chromium and chromium-driver (Debian) for the report's browser test"; \
	  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null; } \
	    || echo "installing chromium failed: the report's browser test will skip"; \
	else echo "chromium not installed and not installable here: the report's browser test will skip"; fi

test: setup browser
	$(BIN)/lint-imports
	$(BIN)/ruff check pipeline tests bench
	$(BIN)/mypy
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pytest -q -ra -n 2 --dist loadgroup

test-slurm: setup
	timeout -s INT 900 bash tests/slurm/run.sh

bench: setup
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python bench/run_all.py

clean:
	rm -rf results logs benchmarks .snakemake
