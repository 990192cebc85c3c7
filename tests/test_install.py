"""The package installed as a user installs it: a wheel without the source tree, the conda post-deploy script."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from conftest import ROOT

pytestmark = pytest.mark.slow
BIN = Path(sys.executable).parent


def _env_without_venv() -> dict:
    path = os.pathsep.join(p for p in os.environ["PATH"].split(os.pathsep) if Path(p) != BIN)
    return {k: v for k, v in os.environ.items() if k != "VIRTUAL_ENV"} | {"PATH": path}


def copy_tracked(dest: Path) -> Path:
    """The repository's tracked files (as in a fresh clone) copied to ``dest``."""
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    for rel in filter(None, files.split("\0")):
        src = ROOT / rel
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        if src.is_symlink():
            os.symlink(os.readlink(src), dest / rel)
        elif src.exists():
            shutil.copy2(src, dest / rel)
    return dest


def test_wheel_installs_and_runs_without_the_source_tree(tmp_path):
    wheels = tmp_path / "wheels"
    source = copy_tracked(tmp_path / "source")  # the build writes build/ beside the sources: not in the checkout
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(wheels),
                    str(source)], check=True, capture_output=True, timeout=300)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    site = next(venv.glob("lib/python*/site-packages"))
    wheel = next(wheels.glob("planit_pipeline-*.whl"))
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                   check=True, capture_output=True, timeout=300)
    # dependencies from the test venv, after the installed package (not the editable checkout: .pth files there are
    # not processed when the folder is added this way)
    deps = next(BIN.parent.glob("lib/python*/site-packages"))
    (site / "zz_deps.pth").write_text(f"{deps}\n")
    work = tmp_path / "run"
    work.mkdir()
    py = venv / "bin" / "python"
    where = subprocess.run([str(py), "-c", "import pipeline; print(pipeline.__file__)"], cwd=work, capture_output=True,
                           text=True, check=True).stdout.strip()
    assert where.startswith(str(site)), where
    outs = [a for n in ("rooms", "architecture", "objects", "models", "ground-truth", "ingest-report", "drops")
            for a in (f"--out-{n}", str(work / f"{n}.parquet"))]
    cfg = '{"shards": 1, "procedural": {"rooms": {"bedroom": 2, "living": 1, "office": 0, "bathroom": 1, "kitchen": 0}}}'
    out = subprocess.run([str(py), "-m", "pipeline", "ingest", "--shard", "0", "--config-json", cfg, *outs], cwd=work,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert pq.read_table(work / "rooms.parquet").num_rows == 4
    bad = subprocess.run([str(py), "-m", "pipeline", "ingest", "--shard", "0", "--config-json", '{"shards": 0}', *outs],
                         cwd=work, capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "invalid config at key 'shards'" in bad.stderr  # the schema came with the wheel


def test_conda_post_deploy_script_installs_the_package(tmp_path):
    # `--sdm conda` cannot run here (no conda, conda-forge unreachable); what the environment adds to its
    # dependencies, the post-deploy script, runs here in a fresh venv with the variable the workflow sets
    source = copy_tracked(tmp_path / "source")
    venv = tmp_path / "env"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    env = {**_env_without_venv(), "PATH": f"{venv / 'bin'}{os.pathsep}{_env_without_venv()['PATH']}",
           "PLANIT_SOURCE": str(source)}
    scripts = [(ROOT / f).read_text() for f in ("environment.post-deploy.sh", "environment-gpu.post-deploy.sh")]
    assert scripts[0] == scripts[1]  # the GPU environment installs the package the same way
    out = subprocess.run(["bash", str(ROOT / "environment.post-deploy.sh")], env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    show = subprocess.run([str(venv / "bin/python"), "-m", "pip", "show", "-f", "planit-pipeline"], capture_output=True,
                          text=True, check=True, timeout=120).stdout
    assert "pipeline/schema.yaml" in show and "Version: 0.1.0" in show
