"""Generated rooms (or any corpus's rooms) in the formats other tools load: USD stages, ProcTHOR-style house JSON
and 3D-FRONT-style scene JSON with 3D-FUTURE-style models (``docs/formats.md``). ``planit export FORMAT FOLDER``
writes a folder; the ``export_rooms`` stage the same files as one archive."""
from .run import FORMATS, export_archive, export_folder

__all__ = ["FORMATS", "export_archive", "export_folder"]
