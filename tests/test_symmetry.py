import numpy as np
import pytest

from pipeline.corpus import furniture
from pipeline.geometry import meshes, symmetry


@pytest.mark.parametrize("category, expected", [
    ("bed", "left-right"), ("round_table", "radial"), ("side_table", "rotational-4"), ("plant", "radial"),
    ("dining_table", "rotational-2"), ("nightstand", "left-right"), ("sofa", "left-right"),
])
def test_detects_catalogue_models(category, expected):
    v, f, _ = furniture.build_model(category, 0, 0)
    assert symmetry.detect(v, f) == expected


def test_agreement_with_construction_over_the_catalogue():
    results = []
    for name, cat in furniture.CATEGORIES.items():
        v, f, _ = furniture.build_model(name, 0, 0)
        results.append(symmetry.detect(v, f) == cat.symmetry)
    assert np.mean(results) >= 0.9


def test_asymmetric_and_corner_shapes():
    l_shape = meshes.combine([meshes.box((1.0, 0.3, 0.7), (0, -0.35, 0.35)), meshes.box((0.3, 1.0, 0.7), (-0.35, 0.0, 0.35))])
    assert symmetry.detect(*l_shape) == "corner-left"  # mirror image across y = -x
    lopsided = meshes.combine([meshes.box((1.0, 0.5, 0.7), (0, 0, 0.35)), meshes.box((0.2, 0.2, 0.3), (0.3, 0.3, 0.85))])
    assert symmetry.detect(*lopsided) == "none"
