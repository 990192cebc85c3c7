"""Instantiation (PlanIT section 6): relation graphs -> rooms with models in place. NumPy and Embree only; the
networks that propose locations and orientations live in :mod:`pipeline.methods.planit.nets` and are passed in."""
