"""The sweep's entry: the speed of each backend of :mod:`refsim.sweep`.

Offered by ``refsim study sweep-speed``; the report does not run it.
"""

from __future__ import annotations

from refsim.report.run import Run


def sweep_speed(run: Run):
    from refsim.studies import sweep

    if run.quick:
        return sweep.measure_sweep_speed(tasks=4, duration=1.0, trivial_tasks=20, repeats=1)
    return sweep.measure_sweep_speed()
