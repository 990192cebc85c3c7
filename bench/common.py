"""What every benchmark script shares: the repository root, its command line, the one-shard default
config, and how a result is reported (printed and written as JSON under the work folder)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from pipeline import config as config_mod

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "bench" / "out"


def arguments(doc: str, workdir: Path = OUT) -> argparse.ArgumentParser:
    """A parser whose help is the script's docstring, with ``--workdir``."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workdir", type=Path, default=workdir)
    return ap


def default_config() -> dict:
    """config/config.yaml with a single shard (benchmarks time one process)."""
    return config_mod.load(ROOT / "config" / "config.yaml", json.dumps({"shards": 1}))


def report(result: dict, workdir: Path, name: str) -> None:
    """Print ``result`` and write it to ``workdir/name.json``."""
    workdir.mkdir(parents=True, exist_ok=True)
    text = json.dumps(result, indent=2)
    (workdir / f"{name}.json").write_text(text)
    print(text)
