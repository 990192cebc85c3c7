"""The annealers' energy traces as a figure: per method, the first scene's weighted energy and hard violations over
its steps, stage by stage (what the report shows per room type)."""
from __future__ import annotations

import json

import pandas as pd


def first_trace(scenes: pd.DataFrame) -> tuple[str, pd.DataFrame] | None:
    """The first scene with a trace and its rows (stage, step, temperature, violations, energy, objects)."""
    rows = scenes[scenes["energy_trace"].notna()] if "energy_trace" in scenes.columns else scenes.iloc[:0]
    if rows.empty:
        return None
    trace = pd.DataFrame(json.loads(rows["energy_trace"].iloc[0]))
    return str(rows["scene_id"].iloc[0]), trace


def trace_figure(traces: dict[str, tuple[str, pd.DataFrame]], room_type: str):
    """One row of panels per method: energy (left axis) and violations (right axis) against the step counted over
    the stages."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(max(len(traces), 1), 1, figsize=(8, 2.8 * max(len(traces), 1)), squeeze=False)
    for ax, (method, (scene, t)) in zip(axes[:, 0], traces.items()):
        x = range(len(t))
        ax.plot(x, t["energy"], c="tab:blue", lw=1)
        ax.set_ylabel("energy", color="tab:blue")
        ax2 = ax.twinx()
        ax2.step(x, t["violations"], c="tab:red", lw=1, where="post")
        ax2.set_ylabel("hard violations", color="tab:red")
        for stage, g in t.groupby("stage", sort=False):
            ax.axvline(g.index[0], c="grey", ls=":", lw=0.8)
            ax.text(g.index[0], ax.get_ylim()[1], f" {stage}", va="top", fontsize=8, color="grey")
        ax.set_title(f"{method}: {scene} ({room_type})", fontsize=9)
        ax.set_xlabel("trace row (every 10 proposed moves)")
    if not traces:
        axes[0, 0].text(0.5, 0.5, "no annealing method ran", ha="center")
    fig.tight_layout()
    return fig
