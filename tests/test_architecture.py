"""The layout the design fixes: rule name = CLI subcommand = stage module, stages declared once, thin stages,
torch only in the learners' packages, layers kept (import-linter)."""
import ast
import importlib
import re
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

PKG = ROOT / "pipeline"
BIN = Path(sys.executable).parent
RULE = re.compile(r"^(?:rule|checkpoint) (\w+):", re.M)


def rule_blocks() -> dict[str, str]:
    """Rule name -> its text, over every rule file."""
    out = {}
    for f in sorted((ROOT / "rules").glob("*.smk")):
        parts = re.split(r"(?m)^(?=rule |checkpoint )", f.read_text())
        out.update({m.group(1): p for p in parts if (m := RULE.match(p))})
    return out


def test_every_rule_is_a_stage_of_the_same_name_and_every_stage_has_a_rule():
    from pipeline.stages import STAGES

    blocks = rule_blocks()
    assert set(blocks) == set(STAGES), set(blocks) ^ set(STAGES)
    for name, text in blocks.items():
        assert f'io=stage_io("{name}")' in text and "        STAGE\n" in text, name  # planit <name> ...
        assert hasattr(importlib.import_module(f"pipeline.stages.{name}"), "run"), name


def test_every_stage_is_a_subcommand_of_its_name():
    from pipeline.stages import STAGES

    out = subprocess.run([str(BIN / "planit"), "--help"], capture_output=True, text=True, timeout=120,
                         env={"COLUMNS": "200", "PATH": str(BIN)})
    listed = set(re.findall(r"^│ (\w+)\s", out.stdout, re.M))
    assert set(STAGES) <= listed, set(STAGES) - listed


def test_a_rule_whose_files_differ_from_its_stage_declaration_is_refused(tmp_path):
    """stage_io checks a rule's named files against the declaration when Snakemake builds the jobs."""
    extra = tmp_path / "Snakefile"
    extra.write_text(f'include: "{ROOT}/rules/common.smk"\n\n'
                     'rule symmetry:\n    input:\n        modelz=["m.parquet"]\n    output:\n        table="t.parquet",\n'
                     '        agreement="a.json"\n    params:\n        config=keys(),\n        io=stage_io("symmetry")\n'
                     '    log:\n        "l.log"\n    shell:\n        STAGE\n')
    (tmp_path / "m.parquet").write_text("")
    out = subprocess.run([str(BIN / "snakemake"), "t.parquet", "-s", str(extra), "-d", str(tmp_path), "-n", "--configfile",
                          str(ROOT / "config/config.yaml")], capture_output=True, text=True, timeout=300)
    assert out.returncode != 0 and "the rule symmetry names inputs ['modelz']" in out.stdout + out.stderr


def test_a_rule_with_a_folder_valued_output_is_refused(tmp_path):
    """No rule reads or writes a folder: the workflow refuses one, named, when it is parsed."""
    extra = tmp_path / "Snakefile"
    extra.write_text('rule shots:\n    output:\n        shots=directory("shots")\n    shell:\n        "mkdir {output}"\n\n'
                     f'include: "{ROOT}/Snakefile"\n')
    out = subprocess.run([str(BIN / "snakemake"), "shots", "-s", str(extra), "-d", str(tmp_path), "-n", "--configfile",
                          str(ROOT / "config/config.yaml")], capture_output=True, text=True, timeout=300)
    assert out.returncode != 0 and "the rule shots reads or writes folders ['shots']; " in out.stdout + out.stderr


def _imports(path: Path) -> set[str]:
    """Every module a file imports, at any depth (function-level imports included), as absolute names."""
    tree = ast.parse(path.read_text())
    pkg = ".".join(path.relative_to(ROOT).with_suffix("").parts)
    pkg = pkg if path.name == "__init__.py" else pkg.rsplit(".", 1)[0]
    pkg = pkg.removesuffix(".__init__")
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = pkg.split(".")[:len(pkg.split(".")) - node.level + 1] if node.level else []
            mod = ".".join([*base, node.module] if node.module else base)
            out.add(mod)
            out |= {f"{mod}.{a.name}" for a in node.names}
    return out


TORCH_HOMES = ("pipeline.methods.planit", "pipeline.methods.strings", "pipeline.methods.grains", "pipeline.learning",
               "pipeline.evaluation.sca")


def test_torch_is_imported_only_in_the_learners_packages():
    offenders = []
    for f in sorted(PKG.rglob("*.py")):
        name = ".".join(f.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
        if any(name == h or name.startswith(h + ".") for h in TORCH_HOMES):
            continue
        if any(m == "torch" or m.startswith("torch.") for m in _imports(f)):
            offenders.append(name)
    assert not offenders, offenders


def _lint(root: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "lint-imports"), "--config", str(root / ".importlinter")], cwd=root,
                          capture_output=True, text=True, timeout=300, env={"PATH": str(BIN), "PYTHONPATH": str(root)})


def test_the_layers_hold_and_a_breach_is_caught(tmp_path):
    out = _lint(ROOT)
    assert out.returncode == 0 and "4 kept, 0 broken" in out.stdout, out.stdout[-2000:]
    import shutil

    shutil.copytree(ROOT / "pipeline", tmp_path / "pipeline", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / ".importlinter", tmp_path)
    with open(tmp_path / "pipeline" / "geometry" / "__init__.py", "a") as f:  # geometry reaching up into a stage
        f.write("\nfrom ..stages import extract_graphs  # noqa\n")
    with open(tmp_path / "pipeline" / "stages" / "symmetry.py", "a") as f:  # a stage importing a stage
        f.write("\nfrom . import ingest  # noqa\n")
    out = _lint(tmp_path)
    assert out.returncode != 0 and "pipeline.geometry is not allowed to import pipeline.stages" in out.stdout
    assert "pipeline.stages.symmetry is not allowed to import pipeline.stages.ingest" in out.stdout


MAX_LINES, MAX_PARAMETERS = 45, 7
CLI_COMMANDS = {("pipeline/cli.py", "view")}  # a typer command's options are its command line, one parameter each


def long_or_wide(source: str, path: str) -> list[str]:
    """The functions of ``source`` over MAX_LINES lines or MAX_PARAMETERS parameters (``self``/``cls`` aside)."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and (path, node.name) not in CLI_COMMANDS:
            a = node.args
            names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs)] + [x.arg for x in (a.vararg, a.kwarg) if x]
            params = len([n for n in names if n not in ("self", "cls")])
            lines = node.end_lineno - node.lineno + 1
            if lines > MAX_LINES or params > MAX_PARAMETERS:
                out.append(f"{path}:{node.lineno} {node.name}: {lines} lines, {params} parameters")
    return out


def test_no_function_runs_over_45_lines_or_takes_over_7_parameters():
    found = [f for p in sorted((ROOT / "pipeline").rglob("*.py"))
             for f in long_or_wide(p.read_text(), str(p.relative_to(ROOT)))]
    assert found == [], "\n".join(found)
    wide = "def f(a, b, c, d, e, f, g, h):\n    return a\n"
    long = "def g(self):\n" + "    x = 1\n" * 45
    assert long_or_wide(wide, "x.py") == ["x.py:1 f: 2 lines, 8 parameters"]
    assert long_or_wide(long, "x.py") == ["x.py:1 g: 46 lines, 0 parameters"]
