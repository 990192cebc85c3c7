"""The README's commands, verbatim, as a newcomer runs them (no activated venv), on the tiny config."""
import re
import shlex
import subprocess
from pathlib import Path

import pytest

from conftest import ROOT
from test_install import BIN, _env_without_venv, copy_tracked

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("readme")]
CLUSTER_ONLY = ("--workflow-profile profiles/slurm",)  # tests/slurm/run.sh runs that one on a real Slurm


def readme_commands() -> list[str]:
    """`make pipeline` and every `.venv/bin/...` line of the README's bash blocks, in order, comments stripped
    (`make test` is this suite)."""
    text = (ROOT / "README.md").read_text()
    lines = [line for block in re.findall(r"```bash\n(.*?)```", text, re.S) for line in block.splitlines()]
    return [line.split(" #")[0].strip() for line in lines if line.startswith((".venv/bin/", "make pipeline"))]


# The methods the commands read (export, view, specs and completion read PlanIT's rooms): every method runs through
# the same rules in the tiny workflow of tests/test_e2e.py and on AI2-THOR rooms in tests/test_ithor_run.py, so here
# they would only run a second time (they were two thirds of this test's time).
METHODS = "generation: {methods: [planit, planit_prior]}\n"


@pytest.fixture(scope="session")  # once per worker: xdist interleaves modules, which would rebuild a module fixture
def clone(tmp_path_factory) -> Path:
    """A fresh copy of the repository, its venv linked, config/config.yaml made tiny (with :data:`METHODS`)."""
    dest = copy_tracked(tmp_path_factory.mktemp("clone"))
    (dest / ".venv").symlink_to(BIN.parent)
    (dest / "config" / "config.yaml").write_text((ROOT / "config" / "tiny.yaml").read_text() + METHODS)
    return dest


def test_readme_commands_work_as_written(clone):
    commands = readme_commands()
    assert len(commands) >= 8
    ran = 0
    for cmd in commands:
        if any(c in cmd for c in CLUSTER_ONLY):
            continue
        out = subprocess.run(shlex.split(cmd), cwd=clone, capture_output=True, text=True, env=_env_without_venv(),
                             timeout=1200)  # the AI2-THOR run: four room types, on 2 cores
        assert out.returncode == 0, f"{cmd}\n{out.stdout[-2000:]}\n{out.stderr[-2000:]}"
        ran += 1
        if cmd == "make pipeline":  # it ends with the report
            assert (clone / "results/report.html").stat().st_size > 100_000, out.stdout[-2000:]
        if " -d " in cmd:  # a run in a work folder of its own: it produced the graphs there
            work = clone / cmd.split(" -d ")[1].split()[0]
            assert (work / "results/graphs/ingested/edges.parquet").exists(), cmd
    assert ran == len(commands) - 1


