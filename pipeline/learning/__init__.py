"""What every learner shares: typed checkpoints, the choice of device and the Gaussian code's KL (PyTorch). The
learners themselves live in their methods' packages (``pipeline.methods.<method>``) and the evaluation's classifier
in ``pipeline.evaluation.sca``."""
