"""The run's random streams: named streams are the NumPy streams their callers drew before the names, and scene
seeds the CRC32 of their names, so that outputs stay as they were."""
import zlib

import numpy as np

from pipeline.seeding import STREAMS, rng_for, seed_of


def test_named_streams_are_the_numbered_ones():
    assert rng_for(3, "bootstrap").random(4).tolist() == np.random.default_rng([3, 8080]).random(4).tolist()
    want = np.random.default_rng([3, 2, 17, 7919]).random(4)
    assert rng_for(np.int64(3), 2, 17, "procedural-room").random(4).tolist() == want.tolist()
    epoch = rng_for(5, 12).integers(100, size=9)
    assert epoch.tolist() == np.random.default_rng([5, 12]).integers(100, size=9).tolist()
    assert all(isinstance(v, int) and v >= 0 for v in STREAMS.values())


def test_scene_seeds_are_the_crc32_of_their_names():
    assert seed_of(0, "infinigen", "gen_bedroom_00003") == zlib.crc32(b"0/infinigen/gen_bedroom_00003")
    assert seed_of(7, "grains") == zlib.crc32(b"7/grains") and seed_of(7, "grains") != seed_of(8, "grains")
