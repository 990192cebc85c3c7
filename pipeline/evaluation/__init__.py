"""Evaluation of generated rooms against held-out real ones (no torch here: the real-vs-synthetic classifier lives
in :mod:`pipeline.evaluation.sca`). Each metric is a pure function over canonical rooms, applied the same way to generated
rooms, real rooms and baselines."""
