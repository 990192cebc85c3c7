"""Where each learner stops improving (issue 41): every ``history.csv`` a run's training rules wrote, its held-out
figure against training seconds. Per learner and room type: the seconds trained, the best held-out figure and when
it came, the seconds at which 95% and 99% of the whole improvement was reached, and the gain of the last fifth of
the training time as a share of the whole improvement (still improving when that is over ``--still``).

    cd RUN && .venv/bin/python bench/learning_curves.py [--still 0.05] [--workdir bench/out]

Writes ``learning_curves.json`` and ``learning_curves.png`` (one panel per learner, one curve per room type) to
``--workdir``. Nothing is trained: it reads what the run's training wrote.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from common import arguments, report  # noqa: E402

# held-out figure of each learner's history, and whether higher is better
FIGURES = (("heldout_pose_loglik", True), ("validation_nll", False), ("validation_elbo", False),
           ("validation_loss", False), ("validation_accuracy", True))


def figure_of(history: pd.DataFrame) -> tuple[str, bool] | None:
    """The history's held-out column and whether higher is better (None: no held-out figure)."""
    return next(((c, up) for c, up in FIGURES if c in history), None)


def elapsed(history: pd.DataFrame) -> np.ndarray:
    """``(n,)`` seconds of training at each row. A column that grows is cumulative (where it falls back, training
    resumed after an interrupt and counts on from there); otherwise it holds each row's own seconds (per epoch)."""
    s = history["seconds"].to_numpy(float)
    d = np.diff(s, prepend=0.0)
    if (d > 0).mean() >= 0.8 and s.max() > 3 * s[0]:
        return np.cumsum(np.where(d > 0, d, s))
    return np.cumsum(s)


def curve_summary(seconds: np.ndarray, score: np.ndarray, still: float) -> dict:
    """Best, when reached, and the seconds to 95% / 99% of the improvement over the first row (``score``: higher is
    better)."""
    gain = score.max() - score[0]
    reach = lambda share: float(seconds[np.argmax(score >= score[0] + share * gain)]) if gain > 0 else float(seconds[0])
    tail = seconds >= 0.8 * seconds[-1]
    late = (score[tail].max() - score[~tail].max()) / gain if gain > 0 and (~tail).any() else 0.0
    return {"seconds": round(float(seconds[-1]), 1), "best_at_s": round(float(seconds[np.argmax(score)]), 1),
            "to_95_s": round(reach(0.95), 1), "to_99_s": round(reach(0.99), 1),
            "last_fifth_gain": round(float(late), 3), "still_improving": bool(late > still)}


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--still", type=float, default=0.05)
    ap.add_argument("--results", type=Path, default=Path("results"))
    args = ap.parse_args()
    found = sorted(args.results.glob("*/*/*/history.csv"))
    learners: dict[str, dict] = {}
    for path in found:
        history = pd.read_csv(path)
        fig = figure_of(history)
        if fig is None or "seconds" not in history or len(history) < 2:
            continue
        stage, room_type, name = path.parts[-4:-1]
        seconds, raw = elapsed(history), history[fig[0]].to_numpy(float)
        score = raw if fig[1] else -raw
        row = {"figure": fig[0], "best": round(float(raw[np.argmax(score)]), 4),
               **curve_summary(seconds, score, args.still)}
        learners.setdefault(f"{stage}/{name}", {})[room_type] = {**row, "curve": [seconds.round(1).tolist(), raw.round(4).tolist()]}
    if not learners:
        raise SystemExit(f"no history.csv with a held-out figure under {args.results.resolve()}")
    panels, axes = len(learners), None
    fig, axes = plt.subplots(1, panels, figsize=(4.5 * panels, 3.4), squeeze=False)
    for ax, (learner, types) in zip(axes[0], sorted(learners.items())):
        for room_type, row in sorted(types.items()):
            ax.plot(*row.pop("curve"), label=room_type)
            ax.axvline(row["to_95_s"], lw=0.5, ls=":", color=ax.lines[-1].get_color())
        ax.set(title=learner, xlabel="training seconds", ylabel=next(iter(types.values()))["figure"])
        ax.legend(fontsize=7)
    args.workdir.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(args.workdir / "learning_curves.png", dpi=110)
    report({"results": str(args.results.resolve()), "learners": learners}, args.workdir, "learning_curves")


if __name__ == "__main__":
    main()
