"""The one place refsim decides whether a readable loop gets compiled.

numba is an optional extra (``refsim[fast]``). A kernel written as plain loops
over arrays is compiled with ``numba.njit(cache=True)`` when numba imports;
otherwise the caller runs the same loops, or a numpy version of them,
uncompiled. ``cache=True`` keeps the machine code on disk, so a machine pays
the compile once (the functions must be defined at module level for the
cache to hit).
"""

from __future__ import annotations


def compiled_or_none(function):
    """``numba.njit(cache=True)(function)``, or None without a usable numba."""
    try:
        import numba
    except Exception:  # not installed, or built against another numpy
        return None
    return numba.njit(cache=True)(function)
