"""PlanIT pipeline: relation-graph extraction, refinement and scene generation over canonical Parquet tables."""

__version__ = "0.1.0"
