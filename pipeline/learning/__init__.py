"""What every learner shares: typed checkpoints and the choice of device (PyTorch). The learners themselves live in
their methods' packages (``pipeline.methods.<method>``) and the evaluation's classifier in ``pipeline.evaluation.sca``."""
