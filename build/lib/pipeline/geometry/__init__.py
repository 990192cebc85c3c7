"""Pure geometry over NumPy arrays (no file IO): polygons, oriented boxes, meshes, rays, symmetry."""
