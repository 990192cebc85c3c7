"""What a learner's training hands its rule: the typed checkpoint, the history, a summary and the loss curves."""
from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from .. import tables
from . import checkpoint


@dataclass
class Fitted:
    checkpoint: checkpoint.Checkpoint
    history: pd.DataFrame
    summary: dict
    curve: object  # matplotlib figure


def write_fitted(out, fitted: Fitted) -> dict:
    """The training outputs of a rule (``out``: model, history, curve, summary); returns the summary."""
    checkpoint.save(out.model, fitted.checkpoint)
    tables.write_csv(out.history, fitted.history)
    tables.write_figure(out.curve, fitted.curve)
    tables.write_json(out.summary, fitted.summary)
    return fitted.summary


def epoch_figure(history: pd.DataFrame, lines: list[tuple], title: str, ylabel: str | None = None):
    """Curves over the epochs of a history: ``lines`` of (column name or a Series, label, line style)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    if len(history):
        for values, label, style in lines:
            ax.plot(history["epoch"], history[values] if isinstance(values, str) else values, label=label,
                    linestyle=style)
    ax.set(xlabel="epoch", title=title, **({"ylabel": ylabel} if ylabel else {}))
    ax.legend()
    fig.tight_layout()
    return fig
