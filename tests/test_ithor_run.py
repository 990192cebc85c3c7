"""Every generation method through the whole workflow on real AI2-THOR rooms (the procthor wheel's, which `make setup`
installs), on the tiny presets and one room type. The README test runs the AI2-THOR command as written with the
methods its other commands read (tests/test_readme.py); the tiny workflow of tests/test_e2e.py runs every method on the
procedural corpus; this test runs every method on real rooms."""
import json

import pandas as pd
import pytest

from pipeline import config as config_mod

from test_e2e import ROOT, snakemake

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("ithor_run")]
ROOM_TYPE = "bathroom"  # the smallest AI2-THOR rooms: every method's training and generation in seconds


def test_every_method_places_and_is_scored_on_real_ai2thor_rooms(tmp_path):
    methods = config_mod.load(ROOT / "config" / "tiny.yaml")["generation"]["methods"]  # every method, by default
    one_type = tmp_path / "one_type.yaml"
    one_type.write_text(f"graph_model: {{room_types: [{ROOM_TYPE}]}}\n")
    work = tmp_path / "run"
    snakemake(work, f"results/eval/{ROOM_TYPE}/metrics.json", extra_config=[ROOT / "config" / "ithor.yaml", one_type])
    res = work / "results"
    for method in methods:
        scenes = pd.read_parquet(res / "generated" / ROOM_TYPE / method / "scenes.parquet")
        objects = pd.read_parquet(res / "generated" / ROOM_TYPE / method / "objects.parquet")
        assert len(scenes) and scenes.status.isin(["placed", "partial"]).any(), method
        assert set(objects.room_id) <= set(scenes.scene_id) and len(objects), method
    metrics = json.loads((res / "eval" / ROOM_TYPE / "metrics.json").read_text())
    assert set(metrics["sets"]) == {*methods, "real_heldout"}
    for name, row in metrics["sets"].items():  # every set scored by the same code, to finite figures
        assert row["scenes"] >= 1 and 0 <= row["category_kl"] < float("inf"), name
        assert 0 <= row["object_collision_rate"] <= 1 and 0 <= row["functional_all"] <= 1, name
