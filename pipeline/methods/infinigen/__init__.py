"""Infinigen-Indoors-style generation (Raistrick et al. 2024): a readable constraint program per room type
(``program.py``: the YAML format, parser and writer) derived from the training split's relation-graph statistics
(``derive.py``) and solved by simulated annealing (``pipeline.methods.solver``). A user can edit a derived program and
pass it back (``planit generate --method infinigen --program FILE``)."""
from __future__ import annotations

from .program import DEFAULT_WEIGHTS, STAGES, TERMS, ObjectRule, Program, dump_program, load_program, parse_program

__all__ = ["DEFAULT_WEIGHTS", "STAGES", "TERMS", "ObjectRule", "Program", "dump_program", "load_program",
           "parse_program"]
