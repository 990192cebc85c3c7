"""Run every benchmark in order and print their JSON: `make bench` (figures go to docs/benchmarks.md by hand)."""
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
for script in ("corpus.py", "extraction.py", "refine.py", "front3d.py"):
    print(f"== {script}", flush=True)
    subprocess.run([sys.executable, str(HERE / script)], check=True)
