"""Seeds and random streams. Every random draw starts from the run's seed (config ``seed``) and says what it is for:
:func:`rng_for` gives the NumPy stream of a named purpose (:data:`STREAMS`) and any numbers (an epoch, an index);
:func:`seed_of` gives a stable 32-bit seed of names (a method, a scene), for NumPy or torch alike."""
from __future__ import annotations

import zlib

import numpy as np

# Each named stream's spawn key: rng_for(seed, name, *numbers) is NumPy's default_rng([seed, key, *numbers]). The
# numbers predate the names and are kept so that every stream stays as it was; names that share a number share the
# stream for one seed.
STREAMS: dict[str, int] = {
    "strings-vocab": 0,  # the string VAE's token vocabulary
    "tagger-vocab": 1,  # the edge tagger's token vocabulary
    "tagger-votes": 7,  # the random strings a room's edge tags are voted over
    "plan-pruning": 31,  # placement plans: the seeded half of the pruned edges
    "train-similarity": 31,  # the training rooms sampled for their nearest-neighbour similarity
    "heldout-order": 77,  # the graph model's fixed decision order of each held-out graph
    "graph-floor": 99,  # the training graphs of the graph metrics' sampling floor
    "sampling-floor": 1414,  # the disjoint real sets of the distribution distances' floors
    "perturb": 2718,  # the power check's known-bad rooms
    "heldout": 4242,  # the held-out split of a room type's rooms
    "power-control": 4242,  # the power check's real-vs-real control split
    "validation": 4343,  # the validation split of the training rooms
    "sca-halves": 5150,  # the SCA classifier's two folds
    "sca-bootstrap": 5151,  # the SCA interval's bootstrap
    "procedural-room": 7919,  # one procedural room (after its type and index)
    "bootstrap": 8080,  # the set figures' bootstrap intervals
}


def rng_for(seed: int, *keys: str | int) -> np.random.Generator:
    """The random stream of ``seed`` for ``keys``: names of :data:`STREAMS` and numbers, in order (NumPy's
    ``default_rng([seed, *keys])``, each name standing for its number)."""
    return np.random.default_rng([int(seed), *(STREAMS[k] if isinstance(k, str) else int(k) for k in keys)])


def seed_of(*parts: object) -> int:
    """A stable 32-bit seed of the run's seed and names: the CRC32 of their text joined by ``/``."""
    return zlib.crc32("/".join(map(str, parts)).encode())
