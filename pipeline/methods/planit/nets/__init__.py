"""PlanIT's placement networks (paper section 6): the location CFCN (or unconditional FCN) and the orientation network."""
