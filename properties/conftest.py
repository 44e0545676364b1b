"""Hypothesis profiles.

``ci`` (the default) is derandomized and bounded, so ``make test`` gives the
same examples on every run and stays within its time budget. ``dev`` explores
more and at random: ``HYPOTHESIS_PROFILE=dev pytest properties``.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    derandomize=True,
    max_examples=100,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", max_examples=1000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
