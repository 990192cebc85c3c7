"""The Infinigen-style room programs: the YAML format (parse, validate with line-numbered errors, dump and read back)
and their derivation from hand-built final relation-graph tables of a training split."""
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pandas as pd
import pytest

from pipeline.errors import InputError
from pipeline.methods.infinigen.derive import derive_program, program_header, training_rooms
from pipeline.methods.infinigen.program import (
    DEFAULT_WEIGHTS,
    STAGES,
    TERMS,
    ObjectRule,
    Program,
    dump_program,
    load_program,
    parse_program,
)

EXAMPLE = """\
# a bedroom, as shipped
room_type: bedroom
objects:
  bed: {count: [1, 1], stage: large, against_wall: true}
  nightstand: {count: [0, 2], stage: medium, against_wall: true, next_to: bed}
  table_lamp: {count: [0, 2], stage: small, on: nightstand}
  desk: {count: [0, 1], stage: medium, against_wall: true}
  chair: {count: [0, 1], stage: medium, facing: desk}
weights: {against_wall: 2.0, next_to: 2.0, facing: 1.0, accessibility: 1.0, alignment: 0.5, symmetry: 1.0, \
free_floor: 1.0}
"""

CFG = {"count_percentiles": [5, 95], "min_room_share": 0.1, "against_wall_share": 0.5, "support_share": 0.5,
       "next_to_share": 0.3, "facing_share": 0.3, "stage_areas": [0.25, 1.0], "recipes": False}


def _zero_lines(program: Program) -> Program:
    """The program with every rule's line set to 0."""
    return dataclasses.replace(program, objects={c: dataclasses.replace(r, line=0) for c, r in program.objects.items()})


def _with(line: int, text: str, base: str = EXAMPLE) -> str:
    """``base`` with its 1-based ``line`` replaced by ``text``."""
    lines = base.splitlines()
    lines[line - 1] = text
    return "\n".join(lines) + "\n"


def _error(text: str, source: str = "bedroom.yaml") -> str:
    """The message of the InputError parsing ``text`` raises."""
    with pytest.raises(InputError) as info:
        parse_program(text, source)
    return str(info.value)


# ---------------------------------------------------------------- the format

def test_example_parses_with_its_fields():
    p = parse_program(EXAMPLE, "bedroom.yaml")
    assert p.room_type == "bedroom" and p.source == "bedroom.yaml"
    assert list(p.objects) == ["bed", "nightstand", "table_lamp", "desk", "chair"]
    assert p.objects["bed"] == ObjectRule("bed", (1, 1), "large", against_wall=True)
    assert p.objects["nightstand"].next_to == "bed" and p.objects["nightstand"].count == (0, 2)
    lamp = p.objects["table_lamp"]
    assert (lamp.on, lamp.stage, lamp.against_wall, lamp.line) == ("nightstand", "small", False, 6)
    assert p.objects["chair"].facing == "desk" and p.objects["chair"].next_to is None
    assert p.weights == DEFAULT_WEIGHTS and set(p.weights) == set(TERMS)


def test_missing_weights_take_the_defaults():
    p = parse_program(_with(9, "weights: {alignment: 3}"))
    assert p.weights == {**DEFAULT_WEIGHTS, "alignment": 3.0} and isinstance(p.weights["alignment"], float)
    no_weights = "\n".join(EXAMPLE.splitlines()[:8]) + "\n"
    assert parse_program(no_weights).weights == DEFAULT_WEIGHTS


def test_round_trip_of_a_hand_built_program():
    objects = [ObjectRule("sofa", (1, 2), "large", against_wall=True),
               ObjectRule("coffee_table", (0, 1), "medium", facing="sofa"),
               ObjectRule("side_table", (0, 2), "medium", next_to="sofa"),
               ObjectRule("yes", (0, 1), "small", on="side_table", against_wall=True),  # a YAML 1.1 boolean word
               ObjectRule("null", (0, 3), "small", on="coffee_table", next_to="yes")]
    weights = {**DEFAULT_WEIGHTS, "facing": 1e-05, "free_floor": 0.0, "symmetry": 12.5}
    p = Program("living room", {r.category: r for r in objects}, weights, source="hand")
    text = dump_program(p, ["hand-built", "two\nlines"])
    assert text.splitlines()[:3] == ["# hand-built", "# two", "# lines"]
    assert "  side_table: {count: [0, 2], stage: medium, next_to: sofa}" in text.splitlines()
    back = parse_program(text)
    assert _zero_lines(back) == p and list(back.objects) == list(p.objects)
    assert back.objects["null"].line == text.splitlines().index(next(l for l in text.splitlines()
                                                                     if l.startswith('  "null"'))) + 1


def test_dump_leaves_out_default_fields():
    text = dump_program(parse_program(EXAMPLE), [])
    assert "  bed: {count: [1, 1], stage: large, against_wall: true}" in text.splitlines()
    assert "  table_lamp: {count: [0, 2], stage: small, on: nightstand}" in text.splitlines()
    assert "null" not in text and "false" not in text


def test_load_program_names_the_file(tmp_path):
    path = tmp_path / "bed.yaml"
    path.write_text(_with(5, "  nightstand: {count: [0, 2], stage: huge}"))
    with pytest.raises(InputError, match=re.escape(f"{path}:5: objects.nightstand.stage: 'huge' is not one of")):
        load_program(path)
    with pytest.raises(InputError, match="missing.yaml"):
        load_program(tmp_path / "missing.yaml")
    path.write_text(EXAMPLE)
    assert load_program(path).source == str(path)


# ---------------------------------------------------------------- validation: source, line and field in each message

@pytest.mark.parametrize("text, line, field", [
    (_with(5, "  nightstand: {count: [0, 2], stage: medium, colour: red}"), 5, "objects.nightstand.colour"),
    (_with(5, "  nightstand: {count: [2, 1], stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {count: [1], stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {count: [-1, 2], stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {count: [0, two], stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {count: [0, true], stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {stage: medium}"), 5, "objects.nightstand.count"),
    (_with(5, "  nightstand: {count: [0, 2], stage: tiny}"), 5, "objects.nightstand.stage"),
    (_with(5, "  nightstand: {count: [0, 2], stage: medium, against_wall: 1}"), 5, "objects.nightstand.against_wall"),
    (_with(6, "  table_lamp: {count: [0, 2], stage: small, on: shelf}"), 6, "objects.table_lamp.on"),
    (_with(6, "  table_lamp: {count: [0, 2], stage: small, on: table_lamp}"), 6, "objects.table_lamp.on"),
    (_with(5, "  nightstand: {count: [0, 2], stage: medium, next_to: wardrobe}"), 5, "objects.nightstand.next_to"),
    (_with(8, "  chair: {count: [0, 1], stage: medium, facing: 3}"), 8, "objects.chair.facing"),
    (_with(6, "  table_lamp: {count: [0, 2], stage: large, on: nightstand}"), 6, "objects.table_lamp.on"),
    (_with(9, "weights: {against_wall: 2.0, frobnicate: 1.0}"), 9, "weights.frobnicate"),
    (_with(9, "weights: {against_wall: -2.0}"), 9, "weights.against_wall"),
    (_with(9, "weights: {against_wall: lots}"), 9, "weights.against_wall"),
    (_with(9, "weights: {against_wall: .nan}"), 9, "weights.against_wall"),
    (_with(9, "weights: [1, 2]"), 9, "weights"),
    (_with(9, "colour: red"), 9, "colour"),
    (_with(5, "  bed: {count: [0, 2], stage: medium}"), 5, "objects.bed"),
    (_with(2, "room_type: [bedroom]"), 2, "room_type"),
    (_with(2, "# no room type"), 1, "room_type"),
    ("room_type: bedroom\n", 1, "objects"),
    ("room_type: bedroom\nobjects: {}\n", 2, "objects"),
    ("- room_type\n- objects\n", 1, "program"),
    ("", 1, "program"),
    (_with(5, "  nightstand: {count: [0, 2], stage: medium"), 6, "yaml"),
    (_with(7, "  desk: {count: [0, 1]: stage: medium}"), 7, "yaml"),
])
def test_each_error_names_source_line_and_field(text, line, field):
    message = _error(text)
    assert message.startswith(f"bedroom.yaml:{line}: {field}: "), message


def test_on_cycle_is_an_error():
    three = _with(4, "  bed: {count: [1, 1], stage: large, on: table_lamp}")
    three = _with(5, "  nightstand: {count: [0, 2], stage: medium, on: bed}", three)
    message = _error(three)
    assert message.startswith("bedroom.yaml:4: objects.bed.on: support cycle: bed on table_lamp on nightstand on bed")
    block = """\
room_type: shelfroom
objects:
  a:
    count: [0, 1]
    stage: small
    on: b
  b: {count: [0, 1], stage: small, on: a}
"""
    message = _error(block, "shelves.yaml")
    assert message.startswith("shelves.yaml:6: objects.a.on: support cycle: a on b on a"), message


def test_on_with_against_wall_is_allowed():
    text = _with(6, "  table_lamp: {count: [0, 2], stage: small, on: nightstand, against_wall: true}")
    rule = parse_program(text).objects["table_lamp"]
    assert rule.on == "nightstand" and rule.against_wall


def test_the_on_key_is_not_a_boolean():
    # YAML 1.1 reads a bare `on` as true; the program format keeps it a key (and `yes` a category name)
    text = _with(8, "  'yes': {count: [0, 1], stage: small, on: desk}")
    assert parse_program(text).objects["yes"].on == "desk"


# ---------------------------------------------------------------- derivation from hand-built final graphs

NIGHTSTANDS = [0, 1, 2, 2, 2, 1, 2, 2, 0, 2]  # per training room: percentiles 5 / 95 -> 0 / 2


def _node(room: str, node: str, kind: str, category: str, hx: float, hy: float, parent: str | None = None,
          role: str = "none", group: str | None = None, room_type: str = "bedroom") -> dict:
    """One final_nodes row (box at the origin; only the footprint matters here)."""
    return {"room_id": room, "node_id": node, "kind": kind, "category": category, "parent_id": parent,
            "tier": 0 if kind != "object" else (2 if parent else 1), "cx": 0.0, "cy": 0.0, "cz": 0.0, "hx": hx,
            "hy": hy, "hz": 0.4, "yaw": 0.0, "role": role, "group_id": group, "room_type": room_type}


def _edge(room: str, source: str, target: str, edge_type: str, direction: str | None = None,
          distance: str | None = None, status: str = "kept", room_type: str = "bedroom") -> dict:
    """One final_edges row."""
    return {"room_id": room, "source": source, "target": target, "edge_type": edge_type, "direction": direction,
            "distance": distance, "status": status, "room_type": room_type}


def _bedroom(i: int) -> tuple[list[dict], list[dict]]:
    """Training bedroom ``i``: bed against wall_0, NIGHTSTANDS[i] nightstands beside it (hub and spokes in even
    rooms, adjacent left/right edges in odd ones) with a lamp on each, and a desk with a chair before it in rooms
    0-4; room 0 also has a guitar."""
    r = f"bed_{i:02d}"
    nodes = [_node(r, f"wall_{k}", "wall", "wall", 1.5, 0.05) for k in range(4)]
    hub = i % 2 == 0 and NIGHTSTANDS[i] > 0
    nodes.append(_node(r, "bed", "object", "bed", 1.0, 1.1, role="hub" if hub else "none",
                       group="hub_0" if hub else None))
    edges = [_edge(r, "wall_0", "bed", "spatial", "front", "adjacent"),
             _edge(r, "wall_1", "bed", "spatial", "front", "distant")]
    for k in range(NIGHTSTANDS[i]):
        ns, lamp = f"ns_{k}", f"lamp_{k}"
        nodes.append(_node(r, ns, "object", "nightstand", 0.3, 0.25, role="spoke" if hub else "none",
                           group="hub_0" if hub else None))
        nodes.append(_node(r, lamp, "object", "table_lamp", 0.15, 0.15, parent=ns))
        edges += [_edge(r, "wall_0", ns, "spatial", "front", "adjacent"), _edge(r, ns, lamp, "support")]
        if not hub:
            edges.append(_edge(r, "bed", ns, "spatial", "left" if k == 0 else "right", "adjacent"))
    if i < 5:
        nodes += [_node(r, "desk", "object", "desk", 0.6, 0.35), _node(r, "chair", "object", "chair", 0.3, 0.3)]
        edges += [_edge(r, "desk", "chair", "spatial", "front", "adjacent"),
                  _edge(r, "wall_2", "desk", "spatial", "front", "proximal"),  # near a wall, not against it
                  _edge(r, "bed", "chair", "spatial", "left", "adjacent", status="pruned")]  # pruned: ignored
    if i == 0:
        nodes.append(_node(r, "guitar", "object", "guitar", 0.1, 0.3))  # small
    return nodes, edges


def _heldout(i: int) -> tuple[list[dict], list[dict]]:
    """A held-out bedroom unlike the training ones: three beds, six nightstands and pianos, nothing against a wall."""
    r = f"held_{i}"
    nodes = [_node(r, "wall_0", "wall", "wall", 1.5, 0.05)]
    nodes += [_node(r, f"bed_{k}", "object", "bed", 0.1, 0.1) for k in range(3)]
    nodes += [_node(r, f"ns_{k}", "object", "nightstand", 2.0, 2.0) for k in range(6)]
    nodes += [_node(r, f"piano_{k}", "object", "piano", 1.0, 1.0) for k in range(4)]
    edges = [_edge(r, "piano_0", f"ns_{k}", "spatial", "front", "adjacent") for k in range(6)]
    return nodes, edges


def _tables() -> tuple[pd.DataFrame, pd.DataFrame, dict[str, str]]:
    """10 training bedrooms (8 fit, 2 validation), 2 held-out ones, and a training kitchen."""
    nodes, edges, split = [], [], {}
    for i in range(10):
        n, e = _bedroom(i)
        nodes, edges = nodes + n, edges + e
        split[f"bed_{i:02d}"] = "validation" if i in (3, 8) else "fit"
    for i in range(2):
        n, e = _heldout(i)
        nodes, edges = nodes + n, edges + e
        split[f"held_{i}"] = "heldout"
    nodes.append(_node("kit_0", "fridge", "object", "fridge", 0.4, 0.4, room_type="kitchen"))
    split["kit_0"] = "fit"
    node_df = pd.DataFrame(nodes).astype({"kind": "category", "category": "category", "room_type": "category",
                                          "role": "category"})
    return node_df, pd.DataFrame(edges).astype({"edge_type": "category", "status": "category"}), split


def test_derivation_reads_the_training_rooms():
    nodes, edges, split = _tables()
    p, why = derive_program(nodes, edges, split, "bedroom", CFG)
    assert training_rooms(nodes, split, "bedroom") == [f"bed_{i:02d}" for i in range(10)]
    assert p.source == "derived:bedroom" and p.weights == DEFAULT_WEIGHTS
    assert list(p.objects) == ["bed", "chair", "desk", "nightstand", "guitar", "table_lamp"]
    assert p.objects["bed"] == ObjectRule("bed", (1, 1), "large", against_wall=True)
    assert p.objects["nightstand"] == ObjectRule("nightstand", (0, 2), "medium", against_wall=True, next_to="bed")
    assert p.objects["table_lamp"] == ObjectRule("table_lamp", (0, 2), "small", on="nightstand")
    assert p.objects["chair"] == ObjectRule("chair", (0, 1), "medium", facing="desk")  # the pruned edge is ignored
    assert p.objects["desk"] == ObjectRule("desk", (0, 1), "medium")  # proximal to a wall is not against it
    assert "piano" not in p.objects and "piano" not in why and "fridge" not in why
    assert why["nightstand"]["next_to"] == {"category": "bed", "share": 1.0, "kept": True}
    assert why["desk"]["rooms_share"] == 0.5 and why["bed"]["wall_share"] == 1.0


def test_rare_categories_are_left_out():
    nodes, edges, split = _tables()
    p, why = derive_program(nodes, edges, split, "bedroom", {**CFG, "min_room_share": 0.2})
    assert "guitar" not in p.objects and why["guitar"]["in_program"] is False and why["guitar"]["rooms_share"] == 0.1
    assert "desk" in p.objects


def test_thresholds_come_from_the_config():
    nodes, edges, split = _tables()
    p, _ = derive_program(nodes, edges, split, "bedroom", {**CFG, "count_percentiles": [50, 100],
                                                            "support_share": 1.01, "stage_areas": [0.01, 0.02]})
    assert p.objects["nightstand"].count == (2, 2)
    assert p.objects["table_lamp"].on is None and p.objects["table_lamp"].stage == "large"
    assert all(r.stage == "large" for r in p.objects.values())


def test_a_derived_program_reads_back():
    nodes, edges, split = _tables()
    p, _ = derive_program(nodes, edges, split, "bedroom", CFG)
    header = program_header("bedroom", 10, CFG)
    assert 3 <= len(header) <= 4 and "10 training rooms" in header[0] and "--program FILE" in header[-1]
    text = dump_program(p, header)
    assert _zero_lines(parse_program(text)) == p and text.startswith("# ")


def test_derivation_without_training_rooms_or_settings_fails():
    nodes, edges, split = _tables()
    with pytest.raises(InputError, match="'office': no training"):
        derive_program(nodes, edges, split, "office", CFG)
    with pytest.raises(InputError, match="infinigen.derive: missing setting.*facing_share"):
        derive_program(nodes, edges, split, "bedroom", {k: v for k, v in CFG.items() if k != "facing_share"})
    assert STAGES == ("large", "medium", "small")


def test_recipes_are_the_training_rooms_contents_drawn_as_wholes():
    """With recipes, a scene's counts are one training room's: every lamp with its nightstand, the desk with its
    chair; the recipes read back from the file, and each names its rooms."""
    nodes, edges, split = _tables()
    p, _ = derive_program(nodes, edges, split, "bedroom", {**CFG, "recipes": True})
    assert sum(r.rooms for r in p.recipes) == 10 and p.recipes[0].rooms >= p.recipes[-1].rooms
    for r in p.recipes:
        assert r.counts["bed"] == 1 and r.counts.get("table_lamp", 0) == r.counts.get("nightstand", 0)
        assert r.counts.get("desk", 0) == r.counts.get("chair", 0)
    want = sorted((n, 1 if i < 5 else 0) for i, n in enumerate(NIGHTSTANDS))
    got = sorted((r.counts.get("nightstand", 0), r.counts.get("desk", 0)) for r in p.recipes for _ in range(r.rooms))
    assert got == want
    text = dump_program(p, [])
    assert "recipes:" in text and _zero_lines(parse_program(text)) == p
    rng = np.random.default_rng(0)
    for _ in range(50):
        counts = p.counts(rng)
        assert counts["nightstand"] == counts["table_lamp"] and counts["nightstand"][0] == counts["nightstand"][1]
    seen = {p.counts(rng)["nightstand"][0] for _ in range(200)}
    assert seen == set(NIGHTSTANDS) and p.objects["nightstand"].count == (0, 2)  # the whole range: no recipe cut
    edited = dataclasses.replace(p, objects={**p.objects, "nightstand": dataclasses.replace(
        p.objects["nightstand"], count=(1, 1)), "desk": dataclasses.replace(p.objects["desk"], count=(0, 0))})
    for _ in range(50):  # a user's narrower range holds every recipe's count within it
        counts = edited.counts(rng)
        assert counts["nightstand"] == (1, 1) and counts["desk"] == (0, 0)


def test_a_program_without_recipes_draws_each_count_in_its_range_and_a_bad_recipe_names_its_line():
    p = parse_program(EXAMPLE)
    assert p.recipes == [] and p.counts(np.random.default_rng(0)) == {c: r.count for c, r in p.objects.items()}
    first = next(iter(p.objects))
    bad = EXAMPLE + f"recipes:\n  - {{rooms: 2, counts: {{{first}: 1}}}}\n  - {{rooms: 1, counts: {{piano: 1}}}}\n"
    lines = bad.splitlines()
    msg = _error(bad)
    assert f"bedroom.yaml:{len(lines)}: recipes[1].counts.piano" in msg and "not an object of this program" in msg
    assert _error(EXAMPLE + "recipes:\n  - {rooms: 0, counts: {}}\n").startswith(f"bedroom.yaml:{len(lines) - 1}")
