#!/usr/bin/env bash
# Snakemake runs this inside the new conda environment (--sdm conda): install this package into it, without
# dependencies (environment.yml lists them). rules/common.smk sets PLANIT_SOURCE to the workflow's folder.
set -euo pipefail
python -m pip install --quiet --no-deps "${PLANIT_SOURCE:?PLANIT_SOURCE is set by rules/common.smk}"
