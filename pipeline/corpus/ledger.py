"""What an ingest job did: the report's counts and one row per dropped house, room, object or model."""
from __future__ import annotations

from collections import Counter

WHERE = frozenset({"file", "house", "room", "item", "field"})  # what names a dropped item


class Ledger(Counter):
    """Counts keyed ``(level, status, reason)`` (the ingest report) plus ``drops``: one row per item dropped or
    skipped, naming the source file, the house, room and item ids and the JSON path of the field at fault."""

    def __init__(self, source: str) -> None:
        super().__init__()
        self.source = source
        self.drops: list[dict] = []
        self.houses: list[tuple[str, str]] = []  # (house uid, file) of every house read

    def drop(self, level: str, reason: str, status: str = "dropped", **where) -> None:
        """Count and record one dropped ``level`` (house | room | object | model | mesh); ``where`` names it by any of
        ``file``, ``house``, ``room``, ``item`` and ``field``."""
        unknown = set(where) - WHERE
        if unknown:
            raise TypeError(f"drop(): unknown keys {sorted(unknown)} (known: {sorted(WHERE)})")
        file = where.get("file")
        self[(level, status, reason)] += 1
        self.drops.append({"source": self.source, "file": None if file is None else str(file),
                           "house_id": where.get("house"), "room_id": where.get("room"), "item_id": where.get("item"),
                           "level": level, "status": status, "field": where.get("field"), "reason": reason})
