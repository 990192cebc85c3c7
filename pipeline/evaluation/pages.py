"""The evaluation's pages for the report, from ``metrics.json``'s content: every method beside the real rooms with
95% intervals (a difference from the first method or from the real rooms whose interval excludes zero marked), the
functional checks, the classifier's power check and the goals on one page; the power check as a plot."""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import pandas as pd

from ..html import Table, page
from .functional import check_name
from .sets import REAL

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FIGURES = {"scenes": "rooms scored (placed)", "attempted": "rooms the method attempted",
           "category_kl": "category KL to the real rooms (ATISS)", "count_distance": "object-count TV distance",
           "object_collision_rate": "share of objects colliding (mesh penetration)",
           "scene_collision_rate": "share of rooms with a collision", "out_of_bounds_rate": "share of objects out of bounds",
           "walkable_share": "door-connected share of the free floor", "reachable_scenes": "share of rooms whose every "
           "floor object can be reached", "functional_all": "share of rooms passing every functional check",
           "contents_excess": "share of rooms with a category more often than any training room",
           "contents_missing": "share of rooms missing a category the training rooms hold",
           "consistency": "planned edges found again", "nn_similarity": "similarity to the nearest training room",
           "cooccurrence_similarity": "GRAINS's co-occurrence similarity to the training rooms",
           "seconds_per_scene": "median seconds per scored room (one core)"}


def _with_interval(value: Any, span: Sequence[float] | None) -> str | int | None:
    if value is None or value != value:
        return None
    if isinstance(value, int):
        return value
    low, high = span if span else (None, None)
    return f"{value:.4g}" if low is None or low != low else f"{value:.4g} [{low:.4g}, {high:.4g}]"


def _marks(metrics: dict[str, Any], name: str, figure: str) -> str:
    """``P`` where the set differs from the first method, ``R`` where from the real rooms (interval excludes 0)."""
    first = list(metrics["sets"])[0]
    return "".join(letter for ref, letter in ((first, "P"), (REAL, "R"))
                   if metrics["differences"][f"vs_{ref}"].get(name, {}).get(figure, {}).get("excludes_zero"))


def figure_table(metrics: dict[str, Any], figures: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Sets as rows, ``figures`` as columns (``value [low, high]``), and the marks."""
    names = list(metrics["sets"])
    frame = pd.DataFrame([{f: _with_interval(metrics["sets"][n].get(f), metrics["sets"][n]["intervals"].get(f))
                           for f in figures} for n in names], index=pd.Index(names, name="set"))
    marks = pd.DataFrame([{f: _marks(metrics, n, f) for f in figures} for n in names], index=frame.index)
    return frame, marks


def sca_table(metrics: dict[str, Any]) -> pd.DataFrame:
    """The classifier's accuracy per method and per power set, with its interval and whether it is read."""
    passed = metrics["power"]["passed"]
    rows = [{"set": n, "kind": "method", "sca": _with_interval(s["sca"]["accuracy"], [s["sca"]["low"], s["sca"]["high"]]),
             "read": "yes" if passed else "inconclusive (power check failed)"}
            for n, s in metrics["sets"].items() if s.get("sca")]
    required = set(metrics["power"]["required"])
    rows += [{"set": n, "kind": "power: required" if n in required else "power", "read": "",
              "sca": _with_interval(s["accuracy"], [s["low"], s["high"]])} for n, s in metrics["power"]["scores"].items()]
    return pd.DataFrame(rows).set_index("set")


def check_rows(metrics: dict[str, Any]) -> pd.DataFrame:
    """What each functional check asks, as learned from the training rooms."""
    rows = []
    for c in metrics["functional"]["checks"]:
        what = ("back to a wall" if c["kind"] == "wall" else
                f"{c['region']} of a {c['anchor']}" + (f", within {c['gap']:g} m" if c.get("gap") else "")
                + ("" if c["facing"] == "any" else f", {c['facing']} it"))
        rows.append({"check": check_name(c), "every": c["target"], "stands": what,
                     "training rooms": c["train_rooms"], "training share": c["train_share"]})
    return pd.DataFrame(rows, columns=["check", "every", "stands", "training rooms", "training share"]).set_index("check")


# What each method is good at and where it fails, read from its figures against the real rooms': (figure, phrase,
# good(value, real, floor), bad(value, real, floor)); a figure neither good nor bad is left out of the sentence.
VERDICTS = (
    ("category_kl", lambda v, r, f: f"category mix {v / f:.1f}x the sampling floor",
     lambda v, r, f: v <= 1.5 * f, lambda v, r, f: v > 3 * f),
    ("object_collision_rate", lambda v, r, f: f"{v:.0%} of objects colliding (real {r:.0%})",
     lambda v, r, f: v <= r + 0.02, lambda v, r, f: v > r + 0.05),
    ("out_of_bounds_rate", lambda v, r, f: f"{v:.0%} of objects out of bounds",
     lambda v, r, f: v <= r + 0.01, lambda v, r, f: v > r + 0.05),
    ("functional_all", lambda v, r, f: f"{v:.2f} of rooms passing every functional check (real {r:.2f})",
     lambda v, r, f: v >= r - 0.10, lambda v, r, f: v < r - 0.15),
    ("sca", lambda v, r, f: f"real-vs-synthetic classifier at {v:.0f}%",
     lambda v, r, f: v <= 60, lambda v, r, f: v >= 70),
)


def method_sentences(metrics: dict[str, Any]) -> pd.DataFrame:
    """One sentence per method from its measured figures: what lies near the real rooms (good at) and what lies far
    from them (fails at), by :data:`VERDICTS`' thresholds; the classifier only where its power check passed."""
    real = metrics["sets"][REAL]
    floor = metrics.get("floors", {}).get("category_kl", {}).get("mean") or float("nan")
    rows = []
    for name, got in metrics["sets"].items():
        if name == REAL:
            continue
        good, bad = [], []
        for figure, phrase, is_good, is_bad in VERDICTS:
            value = (got.get("sca") or {}).get("accuracy") if figure == "sca" else got.get(figure)
            ref = real.get(figure) if figure != "sca" else 50.0
            if value is None or value != value or ref is None or (figure == "sca" and not metrics["power"]["passed"]):
                continue
            if figure == "category_kl" and floor != floor:
                continue
            if is_good(value, ref, floor):
                good.append(phrase(value, ref, floor))
            elif is_bad(value, ref, floor):
                bad.append(phrase(value, ref, floor))
        text = (f"good at: {'; '.join(good)}" if good else "nothing near the real rooms") + \
            (f". Fails at: {'; '.join(bad)}." if bad else ".")
        rows.append({"set": name, "in one sentence": text})
    return pd.DataFrame(rows, columns=["set", "in one sentence"]).set_index("set")


def evaluation_page(metrics: dict[str, Any]) -> str:
    """The room type's evaluation page (HTML)."""
    first, real = list(metrics["sets"])[0], REAL
    figures, fmarks = figure_table(metrics, list(FIGURES))
    checks, cmarks = figure_table(metrics, metrics["checks"])
    goals = pd.DataFrame({"goal": list(metrics["goals"]), "met": [str(v) for v in metrics["goals"].values()]})
    mark_note = (f"value [95% bootstrap interval]; P: differs from {first}, R: differs from {real} (the interval "
                 "of the difference excludes 0)")
    return page(f"Evaluation: {metrics['room_type']}", [
        Table("Every method beside the real rooms", figures, mark_note, fmarks, FIGURES),
        Table("Every method in one sentence (from the figures above)", method_sentences(metrics),
              "good at: within reach of the real rooms (category KL <= 1.5x its floor, collisions and out of bounds "
              "within 2 and 1 points of real, functional_all within 10 points, SCA <= 60%); fails at: category KL > 3x "
              "its floor, 5 points or more beyond real, functional_all more than 15 points under it, SCA >= 70%"),
        Table("Functional checks (share of rooms holding both categories that pass)", checks,
              mark_note, cmarks),
        Table("What the functional checks ask (learned from the training rooms)", check_rows(metrics)),
        Table("Real-vs-synthetic classifier and its power check", sca_table(metrics),
              f"balanced accuracy % [95% interval], 50 is ideal; the power check "
              f"{'passed' if metrics['power']['passed'] else 'FAILED: every SCA is inconclusive'} (required "
              f"perturbations >= {metrics['power']['min_accuracy']:g}%, real vs real within "
              f"{metrics['power']['null_tolerance']:g} points of 50)"),
        Table("Goals", goals)])


def power_figure(metrics: dict[str, Any]) -> Figure:
    """The classifier's accuracy on each known-bad set and the real-vs-real control, with intervals (a figure)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    num = lambda v: float("nan") if v is None else float(v)  # None: too few rooms to score
    scores = metrics["power"]["scores"]
    names = list(scores)
    acc = [num(scores[n]["accuracy"]) for n in names]
    err = [[a - num(scores[n]["low"]) for n, a in zip(names, acc)], [num(scores[n]["high"]) - a for n, a in zip(names, acc)]]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    colours = ["tab:red" if n in metrics["power"]["required"] else "tab:grey" if n == "real_vs_real" else "tab:blue"
               for n in names]
    ax.bar(names, acc, yerr=err, color=colours, capsize=3)
    ax.axhline(metrics["power"]["min_accuracy"], ls="--", c="tab:red", lw=1, label="required accuracy")
    ax.axhline(50, ls=":", c="k", lw=1, label="chance")
    ax.set_ylim(45, 101)
    ax.set_ylabel("classifier accuracy (%)")
    ax.set_title(f"{metrics['room_type']}: power check {'passed' if metrics['power']['passed'] else 'FAILED'}")
    ax.legend(loc="lower right", fontsize=8)
    plt.setp(ax.get_xticklabels(), rotation=20, ha="right")
    fig.tight_layout()
    return fig
