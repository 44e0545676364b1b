"""A cache of structures built from a mesh given as arrays.

The engine contract passes meshes as ``(vertices, faces)`` arrays, one query
at a time; an engine that builds something per mesh (refsim's welded
:class:`~refsim.models.mesh.Mesh` and its hierarchy, FCL's BVH model) keeps
it here so that a query repeated on the same mesh pays for it once.

The key is the arrays' identity when both are read-only (as
:class:`refsim.Mesh` hands them out: they cannot change under the cache), and
a digest of their bytes otherwise (an array the caller may still write to).
Entries keep their arrays alive, so an identity is never reused while cached;
the least recently used entry goes first beyond ``size``.

Cost: O(1) per lookup for read-only arrays; O(n) (a BLAKE2 digest of the
bytes) for writeable ones.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Callable

import numpy as np

#: Meshes kept per cache: the studies and the conformance cases cycle through
#: a few dozen at most.
CACHE_SIZE = 64


class MeshCache:
    """``get(vertices, faces)`` returns ``build(vertices, faces)``, built once."""

    def __init__(self, build: Callable[[np.ndarray, np.ndarray], object],
                 size: int = CACHE_SIZE):
        self._build = build
        self._size = size
        self._entries: OrderedDict = OrderedDict()

    def __len__(self) -> int:
        """How many meshes are cached."""
        return len(self._entries)

    def get(self, vertices, faces):
        vertices, faces = np.asarray(vertices), np.asarray(faces)
        key = _key(vertices, faces)
        entry = self._entries.get(key)
        if entry is None:
            entry = (vertices, faces, self._build(vertices, faces))
            self._entries[key] = entry
            if len(self._entries) > self._size:
                self._entries.popitem(last=False)
        else:
            self._entries.move_to_end(key)
        return entry[2]


def _key(vertices: np.ndarray, faces: np.ndarray):
    if not (vertices.flags.writeable or faces.flags.writeable):
        return ("id", id(vertices), id(faces))
    digest = hashlib.blake2b(digest_size=16)
    for array in (vertices, faces):
        digest.update(str((array.dtype.str, array.shape)).encode())
        digest.update(np.ascontiguousarray(array).tobytes())
    return ("bytes", digest.hexdigest())
