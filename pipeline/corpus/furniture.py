"""Furniture catalogue of the procedural corpus: parametric triangle meshes per category.

Every model is built in model space with its origin at the bottom centre of its bounding box, Z up,
front = +Y. Each category names a template (how the parts are laid out), a size range (width along x,
depth along y, height) and the functional symmetry its geometry has by construction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import meshes as M
from ..seeding import rng_for


# --------------------------------------------------------------------------------------------- templates
def _legs(w, d, h, r, inset):
    xs, ys = w / 2 - inset, d / 2 - inset
    return [M.cylinder(r, h, (sx * xs, sy * ys, h / 2), 8) for sx in (-1, 1) for sy in (-1, 1)]


def table(w, d, h, rng, round_top=False):
    t = 0.03 + 0.02 * rng.random()
    if round_top:
        r = w / 2
        return [M.cylinder(r, t, (0, 0, h - t / 2), 16), M.cylinder(0.05, h - t, (0, 0, (h - t) / 2), 12),
                M.cylinder(r * 0.5, 0.02, (0, 0, 0.01), 16)]
    return [M.box((w, d, t), (0, 0, h - t / 2)), *_legs(w, d, h - t, 0.025, 0.06)]


def cabinet(w, d, h, rng, handles=2):
    kick = 0.08
    parts = [M.box((w, d - 0.02, kick), (0, -0.01, kick / 2)), M.box((w, d - 0.02, h - kick), (0, -0.01, kick + (h - kick) / 2)),
             M.box((w - 0.02, 0.02, h - kick - 0.02), (0, d / 2 - 0.01, kick + (h - kick) / 2))]
    for k in range(handles):
        x = (k + 0.5) / handles * w - w / 2 if handles > 1 else 0.0
        parts.append(M.box((0.02, 0.02, min(0.2, h * 0.3)), (x * 0.6, d / 2 + 0.01, kick + (h - kick) * 0.7)))
    return parts


@dataclass(frozen=True)
class SeatStyle:
    """A seat's build: a back, arms, the seat's height (m; None: the whole height, a stool-like top) and a soft
    (upholstered block) or hard (slab on legs) seat."""
    back: bool = True
    arms: bool = False
    seat_h: float | None = 0.45
    soft: bool = False


def seat(w, d, h, rng, style: SeatStyle = SeatStyle()):
    back, arms, soft = style.back, style.arms, style.soft
    seat_h = h if style.seat_h is None else style.seat_h
    parts = []
    if soft:
        parts.append(M.box((w, d, seat_h), (0, 0, seat_h / 2)))
    else:
        parts += [M.box((w, d, 0.05), (0, 0, seat_h - 0.025)), *_legs(w, d, seat_h - 0.05, 0.02, 0.04)]
    if back:
        bt = 0.08 if soft else 0.04
        parts.append(M.box((w, bt, h - seat_h), (0, -d / 2 + bt / 2, seat_h + (h - seat_h) / 2)))
    if arms:
        ah = seat_h + 0.2
        for sx in (-1, 1):
            parts.append(M.box((0.12, d, ah), (sx * (w / 2 - 0.06), 0, ah / 2)))
    return parts


def stool(w, d, h, rng):
    return [M.cylinder(w / 2, 0.04, (0, 0, h - 0.02)), M.cylinder(0.03, h - 0.04, (0, 0, (h - 0.04) / 2), 8),
            M.cylinder(w / 2 * 0.8, 0.02, (0, 0, 0.01))]


def bed(w, d, h, rng):
    frame_h, mat = 0.3, 0.2
    return [M.box((w, d, frame_h), (0, 0, frame_h / 2)),
            M.box((w - 0.06, d - 0.1, mat), (0, 0.02, frame_h + mat / 2)),
            M.box((w, 0.08, h), (0, -d / 2 + 0.04, h / 2)),
            M.box((w * 0.35, 0.35, 0.1), (-w * 0.22, -d / 2 + 0.3, frame_h + mat + 0.05)),
            M.box((w * 0.35, 0.35, 0.1), (w * 0.22, -d / 2 + 0.3, frame_h + mat + 0.05))]


def screen(w, d, h, rng, stand=True):
    panel_t = 0.04
    foot = 0.06 if stand else 0.0
    parts = [M.box((w, panel_t, h - foot), (0, d / 2 - panel_t / 2, foot + (h - foot) / 2)),
             M.box((w * 0.5, d - panel_t, (h - foot) * 0.5), (0, -panel_t / 2, foot + (h - foot) * 0.45))]
    if stand:
        parts.append(M.box((w * 0.3, d, foot), (0, 0, foot / 2)))
    return parts


def lamp(w, d, h, rng):
    r = w / 2
    return [M.cylinder(r * 0.5, 0.03, (0, 0, 0.015)), M.cylinder(0.012, h * 0.7, (0, 0, 0.03 + h * 0.35), 8),
            M.cone(r, h * 0.3, (0, 0, h * 0.7))]


def plant(w, d, h, rng):
    pot_h = h * 0.35
    return [M.cylinder(w * 0.3, pot_h, (0, 0, pot_h / 2)), M.sphere(w / 2, (0, 0, h - w / 2), 1)]


def vessel(w, d, h, rng):
    return [M.cylinder(w / 2, h, (0, 0, h / 2)), M.cylinder(w / 2 * 0.8, 0.01, (0, 0, h + 0.005))]


def appliance(w, d, h, rng):
    return [M.box((w, d - 0.03, h), (0, -0.015, h / 2)), M.box((w * 0.9, 0.03, h * 0.85), (0, d / 2 - 0.015, h * 0.5)),
            M.box((0.03, 0.03, h * 0.3), (w * 0.35, d / 2 + 0.015, h * 0.6))]


def stove(w, d, h, rng):
    parts = appliance(w, d, h, rng)
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(M.cylinder(w * 0.12, 0.015, (sx * w * 0.22, sy * d * 0.2, h + 0.0075), 12))
    return parts


def shelf(w, d, h, rng, boards=4):
    t = 0.02
    parts = [M.box((t, d, h), (-w / 2 + t / 2, 0, h / 2)), M.box((t, d, h), (w / 2 - t / 2, 0, h / 2)),
             M.box((w, t, h), (0, -d / 2 + t / 2, h / 2))]
    for k in range(boards):
        z = t / 2 + k * (h - t) / (boards - 1)
        parts.append(M.box((w - 2 * t, d - t, t), (0, t / 2, z)))
    return parts


def desk(w, d, h, rng):
    t = 0.03
    return [M.box((w, d, t), (0, 0, h - t / 2)), M.box((0.03, d, h - t), (-w / 2 + 0.015, 0, (h - t) / 2)),
            M.box((0.4, d, h - t), (w / 2 - 0.2, 0, (h - t) / 2)), M.box((0.02, 0.02, 0.1), (w / 2 - 0.2, d / 2 + 0.01, h * 0.7))]


def toilet(w, d, h, rng):
    return [M.cylinder(w / 2, 0.4, (0, d * 0.15, 0.2)), M.box((w, d * 0.3, h), (0, -d / 2 + d * 0.15, h / 2))]


def bathtub(w, d, h, rng):
    return [M.box((w, d, h), (0, 0, h / 2)), M.cylinder(0.03, 0.2, (0, -d / 2 + 0.08, h + 0.1), 8)]


def rack(w, d, h, rng):
    return [M.cylinder(w * 0.35, 0.03, (0, 0, 0.015), 12), M.cylinder(0.02, h, (0, 0, h / 2), 8),
            M.cylinder(w / 2, 0.03, (0, 0, h - 0.1), 12)]


def block(w, d, h, rng):
    return [M.box((w, d, h), (0, 0, h / 2))]


def keyboard(w, d, h, rng):
    return [M.box((w, d, h * 0.5), (0, 0, h * 0.25)), M.box((w, d * 0.3, h * 0.5), (0, -d * 0.35, h * 0.75))]


def laptop(w, d, h, rng):
    return [M.box((w, d, 0.02), (0, 0, 0.01)), M.box((w, 0.01, h - 0.02), (0, -d / 2 + 0.005, 0.02 + (h - 0.02) / 2))]


def bowl(w, d, h, rng):
    return [M.cylinder(w / 2 * 0.6, h * 0.4, (0, 0, h * 0.2)), M.cone(w / 2, h * 0.6, (0, 0, h * 0.4))]


TEMPLATES = {
    "table": table, "round_table": lambda w, d, h, rng: table(w, w, h, rng, round_top=True),
    "cabinet": cabinet, "cabinet1": lambda w, d, h, rng: cabinet(w, d, h, rng, handles=1),
    "chair": seat, "armchair": lambda w, d, h, rng: seat(w, d, h, rng, SeatStyle(arms=True, seat_h=0.42, soft=True)),
    "sofa": lambda w, d, h, rng: seat(w, d, h, rng, SeatStyle(arms=True, seat_h=0.42, soft=True)),
    "ottoman": lambda w, d, h, rng: seat(w, d, h, rng, SeatStyle(back=False, seat_h=None, soft=True)),
    "bench": lambda w, d, h, rng: seat(w, d, h, rng, SeatStyle(back=False, seat_h=None)),
    "stool": stool, "bed": bed, "screen": screen, "monitor": screen,
    "lamp": lamp, "plant": plant, "vessel": vessel, "appliance": appliance, "stove": stove,
    "shelf": shelf, "desk": desk, "toilet": toilet, "bathtub": bathtub, "rack": rack, "block": block,
    "keyboard": keyboard, "laptop": laptop, "bowl": bowl,
}


@dataclass(frozen=True)
class Category:
    name: str
    template: str
    size: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]  # (w, d, h) ranges, m
    symmetry: str  # by construction
    square: bool = False  # w == d


def _c(name, template, w, d, h, symmetry, square=False):
    return Category(name, template, (w, d, h), symmetry, square)


CATEGORIES: dict[str, Category] = {c.name: c for c in [
    # beds and sleeping
    _c("bed", "bed", (1.4, 1.8), (1.95, 2.15), (0.9, 1.2), "left-right"),
    _c("nightstand", "cabinet1", (0.42, 0.55), (0.38, 0.45), (0.5, 0.62), "left-right"),
    _c("wardrobe", "cabinet", (0.9, 1.0), (0.55, 0.62), (1.9, 2.2), "left-right"),
    _c("dresser", "cabinet", (1.0, 1.4), (0.45, 0.55), (0.8, 1.0), "left-right"),
    _c("toy_box", "block", (0.6, 0.8), (0.4, 0.5), (0.4, 0.5), "rotational-2"),
    # seating
    _c("chair", "chair", (0.42, 0.5), (0.45, 0.52), (0.85, 1.0), "left-right"),
    _c("dining_chair", "chair", (0.42, 0.48), (0.46, 0.52), (0.88, 1.0), "left-right"),
    _c("office_chair", "chair", (0.55, 0.65), (0.55, 0.65), (0.95, 1.15), "left-right"),
    _c("armchair", "armchair", (0.75, 0.95), (0.75, 0.9), (0.8, 0.95), "left-right"),
    _c("sofa", "sofa", (1.8, 2.4), (0.85, 0.98), (0.8, 0.95), "left-right"),
    _c("ottoman", "ottoman", (0.5, 0.6), (0.5, 0.6), (0.4, 0.45), "rotational-4", square=True),
    _c("stool", "stool", (0.35, 0.42), (0.35, 0.42), (0.45, 0.7), "radial", square=True),
    _c("bench", "bench", (1.0, 1.4), (0.35, 0.42), (0.42, 0.48), "rotational-2"),
    # tables and desks
    _c("dining_table", "table", (1.4, 1.9), (0.85, 1.0), (0.72, 0.78), "rotational-2"),
    _c("round_table", "round_table", (0.9, 1.2), (0.9, 1.2), (0.72, 0.76), "radial", square=True),
    _c("coffee_table", "table", (0.9, 1.3), (0.5, 0.7), (0.38, 0.46), "rotational-2"),
    _c("side_table", "table", (0.4, 0.55), (0.4, 0.55), (0.5, 0.6), "rotational-4", square=True),
    _c("desk", "desk", (1.1, 1.6), (0.6, 0.75), (0.72, 0.77), "none"),
    _c("meeting_table", "table", (1.8, 2.4), (0.9, 1.1), (0.72, 0.76), "rotational-2"),
    _c("kitchen_island", "cabinet", (1.2, 1.8), (0.8, 0.95), (0.88, 0.92), "left-right"),
    # storage
    _c("bookshelf", "shelf", (0.8, 0.9), (0.3, 0.38), (1.7, 2.0), "left-right"),
    _c("shelf", "shelf", (0.6, 0.9), (0.3, 0.4), (0.9, 1.2), "left-right"),
    _c("filing_cabinet", "cabinet1", (0.45, 0.5), (0.55, 0.62), (0.7, 1.1), "left-right"),
    _c("cabinet", "cabinet", (0.7, 1.0), (0.4, 0.5), (0.8, 1.0), "left-right"),
    _c("sideboard", "cabinet", (1.4, 1.8), (0.42, 0.5), (0.75, 0.9), "left-right"),
    _c("tv_stand", "cabinet", (1.2, 1.8), (0.4, 0.48), (0.45, 0.6), "left-right"),
    _c("kitchen_cabinet", "cabinet1", (0.58, 0.62), (0.58, 0.62), (0.86, 0.9), "left-right"),
    _c("sink_cabinet", "cabinet", (0.58, 0.62), (0.58, 0.62), (0.86, 0.9), "left-right"),
    _c("pantry", "cabinet", (0.58, 0.62), (0.58, 0.62), (2.0, 2.2), "left-right"),
    _c("vanity", "cabinet", (0.6, 1.0), (0.45, 0.55), (0.82, 0.88), "left-right"),
    # appliances and electronics
    _c("refrigerator", "appliance", (0.7, 0.9), (0.65, 0.75), (1.7, 1.95), "left-right"),
    _c("stove", "stove", (0.58, 0.62), (0.58, 0.62), (0.86, 0.9), "left-right"),
    _c("dishwasher", "appliance", (0.58, 0.62), (0.58, 0.62), (0.86, 0.9), "left-right"),
    _c("washing_machine", "appliance", (0.58, 0.62), (0.55, 0.62), (0.84, 0.88), "left-right"),
    _c("dryer", "appliance", (0.58, 0.62), (0.55, 0.62), (0.84, 0.88), "left-right"),
    _c("microwave", "appliance", (0.45, 0.55), (0.32, 0.4), (0.27, 0.32), "left-right"),
    _c("toaster", "appliance", (0.25, 0.3), (0.16, 0.2), (0.18, 0.22), "left-right"),
    _c("coffee_maker", "appliance", (0.2, 0.28), (0.25, 0.32), (0.3, 0.38), "left-right"),
    _c("kettle", "vessel", (0.16, 0.2), (0.16, 0.2), (0.22, 0.28), "radial", square=True),
    _c("tv", "screen", (0.9, 1.4), (0.2, 0.28), (0.55, 0.85), "left-right"),
    _c("monitor", "monitor", (0.5, 0.7), (0.18, 0.24), (0.35, 0.5), "left-right"),
    _c("laptop", "laptop", (0.32, 0.38), (0.22, 0.26), (0.2, 0.24), "left-right"),
    _c("keyboard", "keyboard", (0.42, 0.46), (0.13, 0.16), (0.02, 0.03), "left-right"),
    _c("printer", "appliance", (0.4, 0.5), (0.35, 0.45), (0.25, 0.35), "left-right"),
    _c("speaker", "block", (0.2, 0.28), (0.2, 0.28), (0.9, 1.1), "rotational-4", square=True),
    _c("water_cooler", "appliance", (0.3, 0.35), (0.3, 0.35), (1.0, 1.2), "left-right"),
    # lighting, plants, small things
    _c("floor_lamp", "lamp", (0.35, 0.5), (0.35, 0.5), (1.5, 1.8), "radial", square=True),
    _c("table_lamp", "lamp", (0.22, 0.32), (0.22, 0.32), (0.35, 0.55), "radial", square=True),
    _c("plant", "plant", (0.35, 0.55), (0.35, 0.55), (0.7, 1.4), "radial", square=True),
    _c("small_plant", "plant", (0.15, 0.22), (0.15, 0.22), (0.2, 0.35), "radial", square=True),
    _c("vase", "vessel", (0.12, 0.2), (0.12, 0.2), (0.25, 0.45), "radial", square=True),
    _c("trash_can", "vessel", (0.25, 0.35), (0.25, 0.35), (0.35, 0.5), "radial", square=True),
    _c("laundry_basket", "vessel", (0.4, 0.5), (0.4, 0.5), (0.5, 0.6), "radial", square=True),
    _c("coat_rack", "rack", (0.4, 0.5), (0.4, 0.5), (1.6, 1.8), "radial", square=True),
    _c("towel_rack", "rack", (0.4, 0.5), (0.4, 0.5), (0.9, 1.1), "radial", square=True),
    _c("cup", "vessel", (0.07, 0.09), (0.07, 0.09), (0.09, 0.11), "radial", square=True),
    _c("soap", "vessel", (0.07, 0.09), (0.07, 0.09), (0.15, 0.2), "radial", square=True),
    _c("fruit_bowl", "bowl", (0.25, 0.32), (0.25, 0.32), (0.1, 0.14), "radial", square=True),
    _c("books", "block", (0.2, 0.3), (0.15, 0.22), (0.05, 0.2), "rotational-2"),
    _c("clock", "vessel", (0.1, 0.14), (0.1, 0.14), (0.12, 0.16), "radial", square=True),
    _c("radiator", "block", (0.8, 1.2), (0.1, 0.12), (0.5, 0.6), "rotational-2"),
    # bathroom fixtures
    _c("toilet", "toilet", (0.38, 0.42), (0.65, 0.72), (0.75, 0.85), "left-right"),
    _c("bathtub", "bathtub", (0.7, 0.8), (1.6, 1.75), (0.55, 0.6), "left-right"),
    _c("shower", "block", (0.85, 0.95), (0.85, 0.95), (2.0, 2.1), "rotational-4", square=True),
    _c("hamper", "block", (0.4, 0.5), (0.35, 0.4), (0.55, 0.65), "rotational-2"),
    _c("toilet_brush", "vessel", (0.1, 0.13), (0.1, 0.13), (0.35, 0.42), "radial", square=True),
    _c("bath_scale", "block", (0.3, 0.34), (0.3, 0.34), (0.03, 0.05), "rotational-4", square=True),
    _c("candle", "vessel", (0.06, 0.09), (0.06, 0.09), (0.1, 0.2), "radial", square=True),
    _c("mirror", "screen", (0.5, 0.7), (0.3, 0.4), (1.5, 1.8), "left-right"),
]}

# Rare categories: each used by a handful of "rare category" defect rooms only.
RARE = ["aquarium", "harp", "rowing_machine", "telescope", "easel", "globe", "grandfather_clock", "pinball",
        "kayak", "loom", "anvil", "totem", "drum_kit", "mannequin", "jukebox", "orrery", "sextant", "spinning_wheel",
        "suit_of_armour", "tuba", "birdcage", "barrel", "cello", "hourglass", "gong", "sculpture", "bonsai_rack",
        "dartboard", "treadmill", "sewing_machine", "piano", "arcade_cabinet", "hammock", "canoe", "xylophone"]


def build_model(category: str, variant: int, seed: int) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float]]:
    """Mesh of one model variant of a category (model space, bottom-centre origin) and its (w, d, h)."""
    rng = rng_for(seed, variant, sum(map(ord, category)))
    cat = CATEGORIES.get(category) or Category(category, "block", ((0.5, 0.9), (0.4, 0.8), (0.6, 1.6)), "rotational-2")
    w, d, h = (lo + (hi - lo) * rng.random() for lo, hi in cat.size)
    if cat.square:
        d = w
    parts = TEMPLATES[cat.template](w, d, h, rng)
    v, f = M.to_origin_bottom_centre(M.combine(parts))
    ext = v.max(axis=0) - v.min(axis=0)
    return v, f, (float(ext[0]), float(ext[1]), float(ext[2]))


def model_id(category: str, variant: int) -> str:
    return f"{category}__{variant:02d}"
