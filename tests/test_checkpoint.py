"""Typed checkpoints: kind, config hash, state and record; refused with one line naming the file when they are of
another kind or other settings, or not checkpoints at all; loaded without running pickled code."""
import subprocess
import sys
from pathlib import Path

import pytest
import torch

from pipeline.errors import InputError
from pipeline.learning import checkpoint

BIN = Path(sys.executable).parent


def _saved(tmp_path, kind="placement_nets", chash="abc") -> Path:
    path = tmp_path / "model.pt"
    checkpoint.save(path, checkpoint.Checkpoint(kind, chash, {"nets": [{"w": torch.ones(2, 3)}]},
                                                {"categories": ["bed"], "heldout_ids": ["r1"], "best": float("inf")}))
    return path


def test_a_checkpoint_round_trips_its_kind_hash_state_and_record(tmp_path):
    got = checkpoint.load(_saved(tmp_path), "placement_nets", "abc")
    assert (got.kind, got.config_hash, got.record["categories"]) == ("placement_nets", "abc", ["bed"])
    assert torch.equal(got.state["nets"][0]["w"], torch.ones(2, 3)) and got.record["best"] == float("inf")


def test_another_kind_other_settings_or_a_foreign_file_is_refused_naming_the_file(tmp_path):
    path = _saved(tmp_path)
    with pytest.raises(InputError, match=f"^{path}: a 'placement_nets' checkpoint, not a 'graph_model' one$"):
        checkpoint.load(path, "graph_model")
    with pytest.raises(InputError, match=f"^{path}: trained with other settings"):
        checkpoint.load(path, "placement_nets", "other")
    assert checkpoint.resume(path, "placement_nets", "other") is None  # training starts afresh
    junk = tmp_path / "junk.pt"
    junk.write_bytes(b"not a checkpoint")
    with pytest.raises(InputError, match=f"^{junk}: not a readable planit checkpoint"):
        checkpoint.load(junk, "graph_model")
    untyped = tmp_path / "old.pt"
    torch.save({"state_dict": {"w": torch.zeros(1)}}, untyped)  # an untyped dict of the old format
    with pytest.raises(InputError, match=f"^{untyped}: not a planit checkpoint"):
        checkpoint.load(untyped, "graph_model")


def test_loading_runs_no_pickled_code(tmp_path):
    class Evil:
        def __reduce__(self):
            return (print, ("pwned",))

    path = tmp_path / "evil.pt"
    torch.save({"format": 1, "kind": "graph_model", "config_hash": "x", "state": {}, "record": Evil()}, path)
    with pytest.raises(InputError, match="not a readable planit checkpoint"):
        checkpoint.load(path, "graph_model")


def test_a_stage_given_the_wrong_checkpoint_fails_in_one_line(tmp_path):
    path = _saved(tmp_path)  # placement networks where the graph model's metrics expect a graph model
    args = [a for n in ("nodes", "edges", "gen-nodes", "gen-edges", "sample-summary") for a in (f"--{n}", str(tmp_path / n))]
    out = subprocess.run([str(BIN / "planit"), "graph_model_metrics", "--model", str(path), *args, "--out-metrics",
                          str(tmp_path / "m.json"), "--room-type", "bedroom"], capture_output=True, text=True, timeout=300)
    errors = [line for line in out.stderr.splitlines() if line.startswith("error:")]
    assert out.returncode == 2 and "Traceback" not in out.stderr, out.stderr[-2000:]
    assert errors == [f"error: {path}: a 'placement_nets' checkpoint, not a 'graph_model' one"]
