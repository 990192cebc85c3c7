"""Logging and progress for long loops: a rich bar on a terminal, periodic log lines in rule logs."""
from __future__ import annotations

import logging
import sys
import time
from typing import Iterable, Iterator, TypeVar

T = TypeVar("T")
log = logging.getLogger("planit")


def setup(verbose: bool = False) -> None:
    logging.basicConfig(level=logging.DEBUG if verbose else logging.INFO, stream=sys.stderr,
                        format="%(asctime)s %(levelname)s %(name)s: %(message)s", force=True)


def progress(items: Iterable[T], total: int | None = None, desc: str = "") -> Iterator[T]:
    """Iterate with progress: a rich bar when stderr is a terminal, else a log line every ~10%."""
    total = total if total is not None else (len(items) if hasattr(items, "__len__") else None)
    if sys.stderr.isatty():
        from rich.progress import track

        yield from track(items, total=total, description=desc, transient=True)
        return
    step = max(1, (total or 10) // 10)
    start = time.perf_counter()
    for k, item in enumerate(items, 1):
        yield item
        if total and (k % step == 0 or k == total):
            log.info("%s: %d/%d (%.1f s)", desc, k, total, time.perf_counter() - start)
