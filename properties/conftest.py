"""Hypothesis profiles.

``ci`` (the default) is derandomized and bounded, so ``make test`` gives the
same examples on every run and stays within its time budget. ``dev`` explores
more and at random: ``HYPOTHESIS_PROFILE=dev pytest properties``. ``fuzz`` is
the API fuzzer's (``python -m tests.fuzz.campaign``, which seeds each run
itself): no shrinking, since every probe is recorded and is its own
reproducer; no deadline, since each probe runs in a worker process with its
own timeout; no database and no health checks (a probe's cost is the
library's, not the strategy's).
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, Phase, settings

settings.register_profile(
    "ci",
    derandomize=True,
    max_examples=100,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", max_examples=1000, deadline=None)
settings.register_profile(
    "fuzz",
    derandomize=False,
    database=None,
    max_examples=50,
    deadline=None,
    phases=[Phase.explicit, Phase.generate],
    suppress_health_check=list(HealthCheck),
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
