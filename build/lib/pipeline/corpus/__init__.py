"""Scene sources: the built-in procedural corpus and readers of real datasets, all ending in canonical tables."""
