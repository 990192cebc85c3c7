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
