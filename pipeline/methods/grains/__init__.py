"""GRAINS (Li et al. 2019): recursive hierarchies of rooms and a recursive VAE over them."""
