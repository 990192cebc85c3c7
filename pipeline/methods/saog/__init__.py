"""Qi et al.'s human-centric synthesis (S-AOG): a grammar learned from the training rooms, sampled by MCMC over poses. No torch."""
