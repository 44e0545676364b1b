"""What a task may return and take: plain records, as JSON text.

A task's result travels from a worker to the parent as JSON text, is stored
as JSON, and is handed back decoded from that text, on every backend and
when resumed from a store. So a result is the same object, bit for bit,
however it was obtained: the in-process backend does not skip the round
trip (a tuple would otherwise come back as a tuple in-process and as a list
from a store).

Allowed in a result and in a task's arguments:

- ``None``, ``bool``, ``int``, ``float`` (NaN and infinities included:
  Python's JSON writes them as ``NaN`` and ``Infinity``), ``str``;
- lists and tuples of these (both come back as lists);
- dicts with ``str`` keys (JSON turns other keys into strings: ``{1: x}``
  comes back as ``{"1": x}``);
- numpy scalars and arrays, converted with ``.item()`` and ``.tolist()``
  (an array comes back as nested lists of Python numbers).

A float survives exactly: JSON writes ``repr(x)``, the shortest text that
reads back as the same double. Anything else (an object, a set, bytes) is
refused with a ``TypeError`` that names its type.

Cost: O(size of the record).
"""

from __future__ import annotations

import hashlib
import json

ALLOWED = ("None, bool, int, float, str, lists and tuples, dicts with str keys, "
           "numpy scalars and arrays")


def _plain(value):
    """``json.dumps``'s hook for the numpy types; refuses everything else."""
    module = type(value).__module__
    if module == "numpy" and hasattr(value, "tolist"):
        return value.tolist()           # an array as nested lists; a scalar as a number
    raise TypeError(f"a {type(value).__name__} is not a plain record (allowed: {ALLOWED})")


def encode(value) -> str:
    """``value`` as compact JSON text; ``TypeError`` for what is not allowed.

    ``check_circular`` stays on: a list that contains itself is a
    ``ValueError``, not an endless loop.
    """
    return json.dumps(value, default=_plain, separators=(",", ":"))


def decode(text: str):
    """The object that :func:`encode`'s text stands for."""
    return json.loads(text)


def canonical(value) -> str:
    """JSON text with sorted keys: equal records give equal text, whatever
    the order their dicts were built in (the basis of a task's fingerprint)."""
    return json.dumps(value, default=_plain, separators=(",", ":"), sort_keys=True)


def digest(text: str) -> str:
    """SHA-256 of ``text`` (UTF-8) as 64 hex digits."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
