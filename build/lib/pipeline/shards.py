"""Which shard a room (or a source file) belongs to: one stable rule for every stage."""
from __future__ import annotations

import zlib


def shard_of(key: str, shards: int) -> int:
    """Stable shard index of a room id or source file name (crc32): independent of corpus order and size."""
    return zlib.crc32(key.encode()) % shards
