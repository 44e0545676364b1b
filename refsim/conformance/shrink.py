"""A minimal failing input, found and shrunk by Hypothesis.

When a check finds failing cases in its seeded set, it asks Hypothesis for a
failing case of the same families (:mod:`refsim.conformance.draw`):
``hypothesis.find`` generates cases until the engine fails one, then shrinks
it (simpler parameters: integers towards 0, floats towards simple values,
the first family) while it still fails. The result goes first in the
check's ``examples``, marked ``"shrunk": true``.

The search is seeded (``random.Random(seed)``) and uses no example database,
so the same engine, seed and refsim version give the same minimal example,
in any process. DEVIATION from plain ``hypothesis.find``: Hypothesis (6.13x
on) also draws, now and then, constants it collects from the "local"
modules the process has imported (for an editable install, refsim's own
modules), and caches them; the same search in a fresh worker process then
met other constants than in the report's main process, and found another
minimal example. :func:`_without_local_constants` gives the search an
empty set of local constants (Hypothesis's internal hook, checked to exist:
without it the search runs as it is).
If the search finds nothing within its budget (a failure too rare for
:data:`SEARCH_EXAMPLES` draws), the check keeps only its seeded examples.

Cost: up to ``SEARCH_EXAMPLES`` cases generated plus the shrinking steps
(typically a few hundred more), each an engine call and a ground truth.
"""

from __future__ import annotations

import random
from contextlib import contextmanager

#: Cases Hypothesis generates while looking for a failure. Failures in the
#: seeded sets of the broken engines in tests/conformance appear once in 5 to
#: 50 cases; 300 finds them with room to spare and keeps a search near a
#: second for a millisecond-per-case ground truth.
SEARCH_EXAMPLES = 300

#: Calls of the engine during shrinking at most (Hypothesis stops earlier
#: once no simplification still fails): bounds the search's cost on a slow
#: engine. Past it every further candidate counts as passing, so Hypothesis
#: returns the simplest failure found so far.
SHRINK_STEPS = 2000


def minimal_failure(strategy, fails, seed: int):
    """The minimal value of ``strategy`` for which ``fails(value)`` is true,
    or None when none is found. Exceptions inside ``fails`` count as "does
    not fail" (a caller that minimizes a crash catches the engine's
    exception in ``fails`` itself, as
    :class:`refsim.conformance.checks_geometry.CaseCheck` does)."""
    from hypothesis import HealthCheck, Phase, find, settings
    from hypothesis.errors import NoSuchExample, Unsatisfiable

    calls = 0

    def condition(value) -> bool:
        nonlocal calls
        calls += 1
        if calls > SEARCH_EXAMPLES + SHRINK_STEPS:
            return False
        try:
            return bool(fails(value))
        except Exception:  # noqa: BLE001 - see the docstring
            return False

    config = settings(max_examples=SEARCH_EXAMPLES, database=None, deadline=None,
                      phases=(Phase.generate, Phase.shrink),
                      suppress_health_check=list(HealthCheck))
    try:
        with _without_local_constants():
            return find(strategy, condition, settings=config, random=random.Random(seed))
    except (NoSuchExample, Unsatisfiable):
        return None


@contextmanager
def _without_local_constants():
    """Hypothesis's draws without the constants of the modules this process
    has imported (module docstring), restored afterwards. Not thread-safe:
    a search runs in one thread of its process at a time."""
    try:
        from hypothesis.internal.conjecture import providers
        from hypothesis.internal.constants_ast import Constants

        original, cache = providers._get_local_constants, providers.CONSTANTS_CACHE
    except (ImportError, AttributeError):            # another Hypothesis: nothing to pin
        yield
        return
    empty = Constants()
    providers._get_local_constants = lambda: empty
    providers.CONSTANTS_CACHE = type(cache)(1024)
    try:
        yield
    finally:
        providers._get_local_constants, providers.CONSTANTS_CACHE = original, cache
