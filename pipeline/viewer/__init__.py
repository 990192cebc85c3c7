"""The room inspector (``planit view``, and the report's 3D gallery): rooms and their relation graphs drawn in 3D by
three.js in one self-contained HTML page. ``payload.py`` turns a room and its graphs into the page's JSON,
``sources.py`` finds rooms in a run's results, ``page.py`` writes the page, ``serve.py`` serves it; ``app.js`` is
the page's script."""
