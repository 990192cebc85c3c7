"""The annealing engine two methods share (Infinigen Indoors' constraint solver, Qi et al.'s S-AOG sampler): a room's
architecture plus objects with poses inside their degrees of freedom (``state``), moves (``moves``), energy terms
over oriented boxes (``terms``, ``operators``), temperature schedules (``schedule``) and the Metropolis-Hastings loop
with staged solving (``anneal``). Geometry comes from ``pipeline.geometry`` and ``pipeline.placement.checks``: the
same predicates extraction, PlanIT's search and the evaluation use. No torch."""
