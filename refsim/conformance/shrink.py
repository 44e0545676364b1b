"""A minimal failing input, found and shrunk by Hypothesis.

When a check finds failing cases in its seeded set, it asks Hypothesis for a
failing case of the same families (:mod:`refsim.conformance.draw`):
``hypothesis.find`` generates cases until the engine fails one, then shrinks
it (simpler parameters: integers towards 0, floats towards simple values,
the first family) while it still fails. The result goes first in the
check's ``examples``, marked ``"shrunk": true``.

The search is seeded (``random.Random(seed)``) and uses no example database,
so the same engine, seed and refsim version give the same minimal example.
If the search finds nothing within its budget (a failure too rare for
:data:`SEARCH_EXAMPLES` draws), the check keeps only its seeded examples.

Cost: up to ``SEARCH_EXAMPLES`` cases generated plus the shrinking steps
(typically a few hundred more), each an engine call and a ground truth.
"""

from __future__ import annotations

import random

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
    not fail" (an engine error is not the failure being minimized)."""
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
        return find(strategy, condition, settings=config, random=random.Random(seed))
    except (NoSuchExample, Unsatisfiable):
        return None
