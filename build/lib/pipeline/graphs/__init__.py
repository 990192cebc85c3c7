"""Graph refinement (paper §4.3, appendix A): superstructures, pruning, connectivity. Pure functions per room."""
