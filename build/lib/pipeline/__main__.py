"""``python -m pipeline``: the ``planit`` command line."""
from .cli import app

app(prog_name="planit")
