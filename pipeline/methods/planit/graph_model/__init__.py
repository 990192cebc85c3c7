"""PlanIT's relation-graph generative model (paper section 5): data, GNN, teacher forcing, training, sampling."""
