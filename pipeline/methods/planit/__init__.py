"""PlanIT (Wang et al. 2019): the graph model (graph_model/), the placement networks (nets/) and the search that places
graphs with them (layout.py, over pipeline.placement)."""
