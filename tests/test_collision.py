"""Interpenetration measured on meshes (geometry/collision.py) and used by the filter: hand-built meshes and the
real 3D-FRONT furniture sample."""
import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from pipeline import config
from pipeline.filtering import category_room_counts, filter_rooms
from pipeline.geometry import collision, meshes
from pipeline.geometry.raycast import intersector_class
from pipeline.stage import Files

from conftest import Room, l_sofa_mesh, shared_data, table_mesh

EMBREE = intersector_class("embree")
_C = config.validate({"filter": {"min_category_rooms": 1}})
PEN = collision.Measure(**_C["filter"]["penetration"])


def placed(mesh, xy, yaw_deg=0.0, z=0.0):
    return meshes.transform(mesh[0], (*xy, z), math.radians(yaw_deg)), mesh[1]


@pytest.mark.parametrize("overlap", [0.02, 0.05, 0.2, 0.6])
def test_box_meshes_penetrate_by_their_overlap_within_a_pitch(overlap):
    a = placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (0.0, 0.0))
    b = placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (1.0 - overlap, 0.3))
    pitch = max(min(1.0 / PEN.resolution, overlap / 6), PEN.min_pitch)
    assert collision.mesh_penetration(a, b, EMBREE, PEN) == pytest.approx(overlap, abs=pitch)


def test_a_turned_corner_pushed_in_reads_most_of_its_depth():
    """A box turned 45 deg pushes a corner 0.1 m into another: the region inside both is a wedge, whose thickness
    (its inscribed diameter) is 2 / (1 + sqrt 2) = 0.83 of the depth."""
    a = placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (0.0, 0.0))
    b = placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (0.5 + math.sqrt(0.5) - 0.1, 0.0), yaw_deg=45.0)
    assert collision.mesh_penetration(a, b, EMBREE, PEN) == pytest.approx(0.083, abs=0.017)


def test_apart_and_touching_meshes_do_not_penetrate():
    a = placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (0.0, 0.0))
    assert collision.mesh_penetration(a, placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (1.01, 0.0)), EMBREE, PEN) == 0.0
    assert collision.mesh_penetration(a, placed(meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5)), (1.0, 0.0)), EMBREE, PEN) < 0.01


def _filter(room: Room, measure: str):
    rooms = pd.DataFrame([dict(vars(room.row()), shard=0)])
    objs = room.objects_df()
    cfg = {**_C["filter"], "floor_contact": _C["floor_contact"], "intersector": EMBREE,
           "penetration": {**_C["filter"]["penetration"], "measure": measure}}
    rep = filter_rooms(rooms, room.walls(), objs, cfg, category_room_counts(rooms, objs), room.models)
    return rep.iloc[0]


def _living():
    r = Room([[0, 0], [6, 0], [6, 6], [0, 6]], room_type="living")
    for k in range(3):
        r.add(f"chair{k}", "armchair", (0.7, 0.7, 0.8), (0.6 + 1.0 * k, 5.3))
    return r


def test_coffee_table_inside_an_l_sofas_box_is_no_interpenetration():
    r = _living()
    r.add("sofa", "sofa", (2.4, 2.4, 0.8), (3.0, 3.0), mesh=l_sofa_mesh())
    r.add("table", "coffee_table", (0.7, 0.7, 0.45), (2.55, 3.35), mesh=table_mesh(0.7, 0.7, 0.45))  # in the L's crook
    assert _filter(r, "mesh").status == "kept"
    boxes = _filter(r, "box")
    assert boxes.rule == "interpenetration" and "(boxes)" in boxes.detail  # what the boxes alone would say


def test_chair_tucked_under_a_table_is_kept_and_a_chair_through_a_cabinet_is_not():
    r = _living()
    r.add("table", "dining_table", (1.4, 0.8, 0.75), (3.0, 3.0), mesh=table_mesh(1.4, 0.8, 0.75))
    r.add("chair", "chair", (0.45, 0.5, 0.7), (3.0, 2.75))  # box chair, seat and back below the 0.72 m top
    assert _filter(r, "mesh").status == "kept"
    r.add("cabinet", "cabinet", (0.8, 0.6, 1.0), (1.0, 1.0))
    r.add("stool", "stool", (0.45, 0.45, 0.5), (1.2, 1.1))  # 0.425 m into the cabinet's closed body
    row = _filter(r, "mesh")
    assert row.rule == "interpenetration" and "(meshes)" in row.detail and "cabinet" in row.detail


@pytest.mark.realdata
def test_real_furniture_meshes_overlap_far_less_than_their_boxes(tmp_path):
    """The 3D-FRONT sample with real 3D-FUTURE meshes: every pair whose boxes overlap by more than the filter's
    0.15 m is measured on the meshes; chairs tucked under tables overlap 0.4 m as boxes and about 3 cm as meshes."""
    from pipeline import tables
    from pipeline.geometry import boxes
    from pipeline.geometry.collision import world_mesh as _world

    from test_sources import run_ingest

    sample = shared_data("3d-front-meshes")
    t = run_ingest("front3d", {"houses": str(sample / "houses"), "future": str(sample / "3d-future"),
                               "cache_dir": str(tmp_path / "cache")}, tmp_path)
    tables.write(tmp_path / "models.parquet", "models", tables.pa.Table.from_pandas(t["models"], preserve_index=False))
    mesh_of, box_models = tables.read_meshes(tmp_path / "models.parquet", t["objects"].model_id.dropna())
    box_only, mesh_depths = [], []
    for _, g in t["objects"].groupby("room_id"):
        depth = boxes.penetration_depths(g[["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]].to_numpy())
        poses, mids = g[["px", "py", "pz", "yaw", "sx", "sy", "sz"]].to_numpy(), g.model_id.tolist()
        for i, j in zip(*np.nonzero(np.triu(depth > 0.15, 1))):
            if mids[i] in box_models or mids[j] in box_models:
                continue
            d = collision.mesh_penetration(_world(mesh_of[mids[i]], poses[i]), _world(mesh_of[mids[j]], poses[j]),
                                           EMBREE, PEN)
            mesh_depths.append(d)
            box_only.append(d <= 0.15)
    assert len(mesh_depths) >= 8
    assert sum(box_only) >= 6  # overlaps that exist only between the boxes no longer reject their rooms
    assert np.median(mesh_depths) < 0.05
    # the same rooms extracted: the sample's furniture all stands on the floor (some meshes float mm above it),
    # so no support edge may join two pieces of it (a sofa 1.2 mm up once became its coffee table's child)
    from pipeline.stages import extract_graphs, symmetry

    cfg = config.validate({"source": "front3d", "shards": 1})
    ing = tmp_path / "ingest"
    symmetry.run(cfg, Files(models=[ing / "models-0.parquet"]), Files(table=tmp_path / "sym.parquet", agreement=tmp_path / "sym.json"))
    extract_graphs.run(cfg, Files(rooms=ing / "rooms-0.parquet", architecture=ing / "architecture-0.parquet",
                                  objects=ing / "objects-0.parquet", models=ing / "models-0.parquet", symmetry=tmp_path / "sym.parquet"),
                       Files(nodes=tmp_path / "n.parquet", edges=tmp_path / "e.parquet", summary=tmp_path / "s.json"), shard=0)
    nodes = pd.read_parquet(tmp_path / "n.parquet")
    edges = pd.read_parquet(tmp_path / "e.parquet")
    assert len(nodes[nodes.kind == "object"]) >= 100
    assert (nodes[nodes.kind == "object"].tier == 1).all() and not (edges.edge_type == "support").any()


def test_a_pair_the_coarse_per_attempt_grid_clears_is_measured_again_the_evaluations_way():
    """Two box meshes 1.5 cm into each other: a 4 cm screening grid has no point inside both and clears them; the
    instantiation's check then measures again on the evaluation's grid, so it and the evaluation both call it a
    collision (the bathroom toilet and vanity the coarse grid once passed at 0.98 cm: 1.75 cm by the evaluation)."""
    from pipeline.evaluation import physical
    from pipeline.placement.checks import Checker, checks_config, collision as check_collision

    cfg = config.validate({})
    r = Room([[0, 0], [4, 0], [4, 4], [0, 4]], room_type="bathroom")
    r.add("a", "cabinet", (1.0, 1.0, 1.0), (1.5, 2.0))
    r.add("b", "cabinet", (1.0, 1.0, 1.0), (2.485, 2.3))
    room, ext = r.room_input(), {"floor_contact": cfg["floor_contact"], **cfg["extract"]}
    screen = {**cfg["instantiate"]["checks"]["penetration"], "resolution": 4, "min_pitch": 0.04, "max_cells": 1000,
              "surface_spacing": None}  # a grid alone, which misses the 1.5 cm slab
    checks = {**checks_config(cfg), "penetration": screen}
    assert checks_config(cfg)["confirm"] == cfg["evaluate"]["collision"]["penetration"]
    assert check_collision(room, 1, set(), Checker(r.models, set(), {}, ext, EMBREE, {**checks, "confirm": None})) is None
    hit = check_collision(room, 1, set(), Checker(r.models, set(), {}, ext, EMBREE, checks))
    assert hit is not None and hit[0] == 0 and hit[1] == pytest.approx(0.015, abs=0.0065)  # one pitch: 6 mm here
    ev = collision.CollisionTest.of(cfg["evaluate"]["collision"]["penetration"], cfg["evaluate"]["collision"]["max_penetration"], EMBREE)
    assert physical.colliding(room, [None, None], [r.models[m] for m in room.model_ids], ev).all()


# ------------------------------------------------------------------------ thin parts (issue 27): bookshelves
def bookshelf(shelves=5, width=0.8, depth=0.35, height=1.8, panel=0.02):
    """Two side panels, a bottom, a top and ``shelves`` shelves between them, 2 cm box panels concatenated (model
    frame: bottom centre at the origin)."""
    side = [meshes.box((panel, depth, height), (s * (width - panel) / 2, 0, height / 2)) for s in (-1, 1)]
    step = (height - panel) / (shelves + 1)
    flat = [meshes.box((width - 2 * panel, depth, panel), (0, 0, panel / 2 + k * step)) for k in range(shelves + 2)]
    return meshes.combine(side + flat)


def shifted(mesh, offset):
    return mesh[0] + np.asarray(offset, float), mesh[1]


SPACING = (1.8 - 0.02) / 6  # between the 5-shelf bookcase's panels
LIMIT = _C["evaluate"]["collision"]["max_penetration"]  # 1 cm: what the evaluation and the placement checks allow
SETTINGS = {"evaluate": collision.Measure(**_C["evaluate"]["collision"]["penetration"]),
            "instantiate": collision.Measure(**_C["instantiate"]["checks"]["penetration"]), "filter": PEN}


def _grid_only(pen):
    """The measure before issue 27: the grid over the boxes' overlap alone."""
    return replace(pen, surface_spacing=None)


@pytest.mark.parametrize("setting", ["evaluate", "instantiate"])
@pytest.mark.parametrize("shelves, offset", [
    (5, (0.4, 0.0, SPACING / 2)),  # half a spacing up, half a width across: side panels cut the other's shelves
    (5, (0.3, 0.05, SPACING / 2)),
    (5, (0.5, 0.1, SPACING / 3)),
    (4, (0.4, 0.0, 0.0)),  # both on the floor, 4 and 5 shelves: bottoms and tops coincide in part, sides cut shelves
    (4, (0.5, 0.05, 0.0)),
])
def test_bookshelves_whose_panels_interleave_penetrate_by_a_panel_the_grid_alone_missed(setting, shelves, offset):
    """The issue's case: the boxes overlap 0.3-0.5 x 0.3 x 1.7 m, so the grid's pitch is 5-6 cm and none of its points
    falls inside both 2 cm panels (it read 0: no collision); the surface screen finds where the surfaces cross and
    measures the panel there, about its 2 cm thickness."""
    pen = SETTINGS[setting]
    a, b = bookshelf(), shifted(bookshelf(shelves), offset)
    lo, hi = collision.box_overlap(a[0].min(0), a[0].max(0), b[0].min(0), b[0].max(0))
    assert collision.grid(lo, hi, pen.resolution, pen.min_pitch, pen.max_cells)[1] > 0.04
    assert collision.mesh_penetration(a, b, EMBREE, _grid_only(pen)) < LIMIT
    assert collision.mesh_penetration(a, b, EMBREE, pen) == pytest.approx(0.02, abs=pen.min_pitch)


def test_bookshelves_apart_or_one_inside_the_others_compartment_do_not_penetrate():
    """Side by side 1 cm apart, flush against each other, and a small shelf (0.3 x 0.25 x 0.2 m) standing in the
    big one's bottom compartment, 1 cm above its bottom panel and 10 cm below the first shelf: its box lies wholly
    inside the big one's, its mesh touches nothing."""
    a = bookshelf()
    small = shifted(bookshelf(shelves=0, width=0.3, depth=0.25, height=0.2), (0.0, 0.0, 0.03))
    for pen in SETTINGS.values():
        assert collision.mesh_penetration(a, shifted(a, (0.81, 0.0, 0.0)), EMBREE, pen) == 0.0
        assert collision.mesh_penetration(a, shifted(a, (0.8, 0.0, 0.0)), EMBREE, pen) < LIMIT
        assert collision.mesh_penetration(a, small, EMBREE, pen) == 0.0


def test_interleaved_bookshelves_collide_for_the_placement_checks_the_filter_and_the_evaluation():
    """One measure serves all three (geometry.collision.penetrating_pairs): two bookshelves standing on the floor,
    4 and 5 shelves, 0.4 m apart, collide for the placement checks and the evaluation and, at a 1 cm limit, for the
    filter; with the grid alone (surface_spacing null everywhere) none of the three saw it."""
    from pipeline.evaluation import physical
    from pipeline.placement.checks import Checker, checks_config, collision as check_collision

    def room():
        r = _living()
        r.add("shelf_a", "bookcase", (0.8, 0.35, 1.8), (3.0, 3.0), mesh=bookshelf())
        return r.add("shelf_b", "bookcase", (0.8, 0.35, 1.8), (3.4, 3.0), mesh=bookshelf(4))

    def verdicts(cfg):
        r = room()
        room_in, ext = r.room_input(), {"floor_contact": cfg["floor_contact"], **cfg["extract"]}
        placed = check_collision(room_in, 4, set(), Checker(r.models, set(), {}, ext, EMBREE, checks_config(cfg)))
        ev = collision.CollisionTest.of(cfg["evaluate"]["collision"]["penetration"], LIMIT, EMBREE)
        evaluated = physical.colliding(room_in, [None] * 5, [r.models[m] for m in room_in.model_ids], ev)
        rooms = pd.DataFrame([dict(vars(r.row()), shard=0)])
        flt = {**cfg["filter"], "floor_contact": cfg["floor_contact"], "intersector": EMBREE, "max_penetration": LIMIT}
        kept = filter_rooms(rooms, r.walls(), r.objects_df(), flt, category_room_counts(rooms, r.objects_df()), r.models)
        return placed, evaluated[3:].tolist(), kept.iloc[0]

    placed, evaluated, kept = verdicts(_C)
    assert placed is not None and placed[0] == 3 and placed[1] == pytest.approx(0.02, abs=0.005)
    assert evaluated == [True, True]
    assert kept.rule == "interpenetration" and "(meshes)" in kept.detail and "shelf_a and shelf_b" in kept.detail
    off = {"surface_spacing": None}
    grid_only = config.validate({"filter": {"min_category_rooms": 1, "penetration": off},
                                 "instantiate": {"checks": {"penetration": off}},
                                 "evaluate": {"collision": {"penetration": off}}})
    placed, evaluated, kept = verdicts(grid_only)
    assert placed is None and evaluated == [False, False] and kept.status == "kept"


@pytest.mark.parametrize("setting", ["evaluate", "instantiate"])
def test_a_measure_that_stops_past_the_limit_gives_every_pair_the_full_measures_verdict(setting, monkeypatch):
    """``enough``: the search and the evaluation ask only whether a pair penetrates deeper than the limit, so the
    surface screen is skipped where the coarse grid already finds more. Over hand-built pairs from apart to deep
    (boxes, bookshelves whose panels interleave, a table and an L-shaped sofa), the verdict at the limit is the
    full measure's and the depth returned is never above it; the screen runs on fewer pairs."""
    pen = SETTINGS[setting]
    cube = meshes.box((1.0, 1.0, 1.0), (0, 0, 0.5))
    pairs = [(placed(cube, (0, 0)), placed(cube, (1.0 - d, 0.2))) for d in (-0.01, 0.0, 0.005, 0.02, 0.05, 0.3)]
    pairs += [(bookshelf(), shifted(bookshelf(s), o)) for s, o in [(5, (0.4, 0.0, SPACING / 2)), (4, (0.5, 0.05, 0.0)),
                                                                   (5, (0.81, 0.0, 0.0)), (5, (0.2, 0.1, 0.0))]]
    pairs += [(placed(table_mesh(1.2, 0.6, 0.45), (0, 0)), placed(l_sofa_mesh(), (x, 0.3), 90.0))
              for x in (0.3, 0.9, 1.6)]
    screens = []  # the real screen, counted
    monkeypatch.setattr(collision, "surface_depth", lambda *a, _f=collision.surface_depth: screens.append(1) or _f(*a))
    full = [collision.mesh_penetration(a, b, EMBREE, pen) for a, b in pairs]
    screened = len(screens)
    quick = [collision.mesh_penetration(a, b, EMBREE, pen, enough=LIMIT) for a, b in pairs]
    assert [q > LIMIT for q in quick] == [f > LIMIT for f in full]
    assert all(q <= f + 1e-12 for q, f in zip(quick, full))
    assert sum(f > LIMIT for f in full) >= 5 and sum(f <= LIMIT for f in full) >= 3
    assert len(screens) - screened < screened  # the quick measure skips the screen on pairs already past it
