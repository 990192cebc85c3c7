"""One export: read a set of rooms, write them in a format into a folder (``planit export``) or one archive (the
``export_rooms`` stage), with a summary (``export.json``: rooms, objects, files, what had no counterpart, the rooms skipped and why)."""
from __future__ import annotations

import importlib
import tempfile
from pathlib import Path

from .. import tables
from ..errors import InputError
from .rooms import load_set, table_paths

FORMATS = ("usd", "procthor", "front3d")


def writer(fmt: str):
    """The ``write(room set, folder, options) -> summary`` function of a format (its module imported on demand)."""
    if fmt not in FORMATS:
        raise InputError(f"export format '{fmt}': unknown (known: {', '.join(FORMATS)})")
    return importlib.import_module(f"{__package__}.{fmt}").write


def export_folder(fmt: str, folder: Path, out: Path | None, options: dict) -> tuple[Path, dict]:
    """Every room of a generated set's or a corpus's ``folder`` in ``fmt`` under ``out`` (default
    ``<folder>/export/<fmt>``); ``options``: the ``export`` config section plus ``ithor``. Returns the folder and the
    summary."""
    write = writer(fmt)
    rooms = load_set(table_paths(folder), str(folder))
    out = Path(out) if out is not None else Path(folder) / "export" / fmt
    out.mkdir(parents=True, exist_ok=True)
    summary = write(rooms, out, options) | {"skipped": rooms.skipped}
    tables.write_json(out / "export.json", summary)
    return out, summary


def export_archive(fmt: str, paths: dict[str, list[Path]], archive: Path, options: dict) -> dict:
    """The same files as :func:`export_folder` as the entries of one zip archive (``paths``: the four tables)."""
    write = writer(fmt)
    rooms = load_set(paths, str(Path(paths["rooms"][0]).parent))
    with tempfile.TemporaryDirectory() as tmp:
        summary = write(rooms, Path(tmp), options) | {"skipped": rooms.skipped}
        with tables.write_archive(archive) as zf:
            zf.add_json("export.json", summary)
            for f in sorted(p for p in Path(tmp).rglob("*") if p.is_file()):
                zf.add(f.relative_to(tmp).as_posix(), f.read_bytes())
    return summary
