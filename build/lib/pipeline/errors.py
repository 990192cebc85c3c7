"""Domain errors: what the CLI turns into a one-line message (exit code 2). Anything else is a bug and keeps
its traceback."""
from __future__ import annotations


class PlanitError(Exception):
    """Base of every error caused by the user's input, config or environment, not by the code."""


class InputError(PlanitError):
    """A source file or folder is missing or unusable; the message names it (and the field, where one is at fault)."""
