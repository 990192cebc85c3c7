"""Relation graphs as strings (Kalojanov et al. 2019): SMILES-like serialisation and the grammar learned from the
training graphs (issue 31). The sequence VAE and the paper's own instantiation come next."""
