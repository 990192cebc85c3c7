"""What the Snakefile needs from the package at parse time: how jobs find ``planit``."""
from __future__ import annotations

import os
import sys
from pathlib import Path


def prepare_jobs(workflow_dir: str) -> None:
    """Set the environment every job inherits.

    - ``PATH`` starts with the folder of the Python running Snakemake, so jobs call the ``planit`` installed
      beside it whether or not a venv is activated (with ``--sdm conda`` the rule's environment comes first);
    - ``PLANIT_STRICT_KEYS=1``: each stage sees only the config keys its rule passes (``pipeline.cli``);
    - ``PLANIT_SOURCE``: this package's folder, which the conda environment's post-deploy script installs.
    """
    os.environ["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"
    os.environ["PLANIT_STRICT_KEYS"] = "1"
    os.environ["PLANIT_SOURCE"] = str(Path(workflow_dir).resolve())
