"""The learning stages: the graph generative model (PyTorch lives here and only here).

Only the stages that train or sample import this subpackage; ingest, geometry, extraction and refinement never do
(a test checks). ``graph_data`` and ``graph_checks`` are plain NumPy / networkx, the rest needs torch.
"""
