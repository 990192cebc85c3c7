import json
import re
import tomllib

import pytest
import yaml

from pipeline import config

from conftest import ROOT


def test_defaults_fill_every_section():
    cfg = config.validate({})
    assert cfg["source"] == "procedural" and cfg["shards"] == 4
    assert cfg["filter"]["max_penetration"] == 0.15
    assert cfg["extract"]["distance"]["adjacent_abs"] == 0.0508
    assert cfg["extract"]["support"]["max_distance"] == 0.10


def test_repo_config_is_valid_and_has_2000_rooms():
    cfg = config.load(ROOT / "config" / "config.yaml")
    assert sum(cfg["procedural"]["rooms"].values()) >= 2000


def test_bad_value_names_the_key(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("filter:\n  max_height: -1\n")
    with pytest.raises(config.ConfigError, match=r"bad.yaml: invalid config at key 'filter.max_height'"):
        config.load(bad)


def test_unknown_key_is_rejected(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("extract:\n  suport: {grid: 3}\n")
    with pytest.raises(config.ConfigError, match=r"key 'extract'.*suport"):
        config.load(bad)


def test_unreadable_and_malformed_files(tmp_path):
    with pytest.raises(config.ConfigError, match="cannot read config"):
        config.load(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("shards: [1,\n")
    with pytest.raises(config.ConfigError, match="broken.yaml: not valid YAML"):
        config.load(broken)
    with pytest.raises(config.ConfigError, match="--config-json: not valid JSON"):
        config.load(None, "{nope")


def test_json_overrides_merge_deeply():
    cfg = config.load(ROOT / "config" / "config.yaml", json.dumps({"filter": {"max_height": 3.5}}))
    assert cfg["filter"]["max_height"] == 3.5
    assert cfg["filter"]["max_extent"] == 6.0


def _norm(name: str) -> str:
    return {"python-duckdb": "duckdb", "pytorch": "torch"}.get(name, name).lower().replace("_", "-")


def _conda_pins(path) -> dict:
    env = yaml.safe_load(path.read_text())
    conda = {}
    deps = []
    for dep in env["dependencies"]:
        deps += dep["pip"] if isinstance(dep, dict) else [dep]
    for dep in deps:
        m = re.match(r"([A-Za-z0-9_.-]+)\s*(=|>=)\s*(\S+)", dep.replace("==", "="))
        if m and m.group(1) != "python":
            conda[_norm(m.group(1))] = ("==" if m.group(2) == "=" else ">=", m.group(3))
    return conda


def test_gpu_environment_has_the_same_pins_as_the_cpu_one():
    cpu, gpu = _conda_pins(ROOT / "environment.yml"), _conda_pins(ROOT / "environment-gpu.yml")
    test_only = {"pytest", "pytest-xdist", "hypothesis", "import-linter", "ruff", "mypy", "snakemake-executor-plugin-slurm"}
    assert {k: v for k, v in cpu.items() if k not in test_only} == gpu
    assert "pytorch-cuda" in (ROOT / "environment-gpu.yml").read_text()


def test_schema_is_package_data_in_json_schema_2020_12():
    schema = config.load_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema" and "$defs" in schema
    assert (ROOT / "config" / "schema.yaml").resolve() == (ROOT / "pipeline" / "schema.yaml").resolve()


def test_config_errors_are_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("refine:\n  thresholds: {adjacent: 2, proximal: nope}\n")
    with pytest.raises(config.ConfigError) as err:
        config.load(bad)
    assert "\n" not in str(err.value) and "refine.thresholds.adjacent" in str(err.value)


def test_pick_holds_exactly_the_dotted_keys():
    cfg = config.validate({})
    picked = config.pick(cfg, ["seed", "extract.support", "refine.thresholds.proximal"])
    assert picked == {"seed": 0, "extract": {"support": cfg["extract"]["support"]}, "refine": {"thresholds": {"proximal": 0.08}}}
    assert config.restrict(cfg, picked) == picked
    with pytest.raises(config.ConfigError, match="no config key 'extract.nope'"):
        config.pick(cfg, ["extract.nope"])


def test_environment_yml_matches_pyproject():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    pins = {}
    for spec in project["dependencies"] + sum(project["optional-dependencies"].values(), []):
        name, op, version = re.match(r"([A-Za-z0-9_.-]+)\s*(==|>=)\s*([^;\s]+)", spec).groups()
        pins[_norm(name)] = (op, version)
    env = yaml.safe_load((ROOT / "environment.yml").read_text())
    conda = {}
    deps = []
    for dep in env["dependencies"]:
        deps += dep["pip"] if isinstance(dep, dict) else [dep]
    for dep in deps:
        dep = dep.replace("==", "=")
        m = re.match(r"([A-Za-z0-9_.-]+)\s*(=|>=)\s*(\S+)", dep)
        if m and m.group(1) != "python":
            conda[_norm(m.group(1))] = ("==" if m.group(2) == "=" else ">=", m.group(3))
    assert conda == pins


@pytest.mark.parametrize("name", ["tiny", "front3d", "ithor", "paper"])
def test_every_shipped_config_validates_over_the_defaults(name):
    cfg = config.load(ROOT / "config" / f"{name}.yaml")
    assert cfg["seed"] is not None and cfg["evaluate"]["sca"]["steps"] >= 1
    if name == "paper":
        assert cfg["graph_model"]["preset"] == cfg["placement"]["preset"] == "paper"
        assert cfg["placement"]["presets"]["paper"]["size"] == 256


def test_default_run_places_30_rooms_per_type_and_caps_the_baselines_at_30():
    from pipeline.methods.planit.layout import scene_count

    ic = config.load(ROOT / "config" / "config.yaml")["instantiate"]
    counts = {name: scene_count(ic, v) for name, v in ic["variants"].items()}
    assert counts["planit"] == counts["strings"] == 30  # what make pipeline places (issues 30, 31)
    assert counts["random_sampled"] == counts["unconditional_sampled"] == 30
    big = config.load(ROOT / "bench" / "configs" / "eval500.yaml")["instantiate"]
    assert {scene_count(big, v) for n, v in big["variants"].items() if v["graphs"] == "sampled"} == {500}
    assert counts["heldout"] == ic["table3_scenes"] == 20
    tiny = config.load(ROOT / "config" / "tiny.yaml")["instantiate"]
    assert {scene_count(tiny, v) for v in tiny["variants"].values()} == {2}  # the cap never raises a count


def test_grains_selection_by_samples_needs_its_period_and_sample_count(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("grains:\n  presets:\n    default: {feature: 8, hidden: 8, root_feature: 8, root_hidden: 8, batch_size: 4,"
                   " lr: 0.001, max_epochs: 5, patience: 5, kl_weight: 0.1, select: samples}\n")
    with pytest.raises(config.ConfigError, match=r"bad.yaml: invalid config at key 'grains.presets.default'.*select_every"):
        config.load(bad)
    bad.write_text(bad.read_text().replace("select: samples}", "select: samples, select_every: 2, select_samples: 4}"))
    assert config.load(bad)["grains"]["presets"]["default"]["select_every"] == 2
