"""The device a learner runs on."""
from __future__ import annotations

import torch


def pick_device(setting: str) -> str:
    """'auto': CUDA when PyTorch sees a GPU, else the CPU."""
    if setting == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    return setting
