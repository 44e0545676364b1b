"""The compiled loop's first call, cold and cached (docs/decisions/compiled-loop.md).

    python docs/decisions/loop_compile_cost.py

Two fresh processes share an empty ``NUMBA_CACHE_DIR``. Each makes a
``Simulation`` of ten cubes (rotation "seed", the compiled kernel) and
times its first ``advance(1)`` (wall and CPU time), then 1000 more steps. The first process
compiles the loop and writes it to the cache; the second loads it.
Printed: both first calls and the mean step afterwards (seconds), and
numba's cache counters of the loop's kernel in each process
(``Dispatcher.stats``): the second process must show a hit and no miss.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

PROBE = r"""
import json, time
from refsim.dynamics.simulation import Simulation
from refsim.studies.bounce_scenes import cubes_scene
sim = Simulation(cubes_scene(10, "seed"), kernel="compiled")
t0, c0 = time.perf_counter(), time.process_time()
sim.advance(1)
t1, c1 = time.perf_counter(), time.process_time()
sim.advance(1000)
t2 = time.perf_counter()
from refsim.dynamics._numba_kernels import advance
stats = advance.stats
print(json.dumps({"first": t1 - t0, "first_cpu": c1 - c0, "steady": (t2 - t1) / 1000,
                  "hits": sum(stats.cache_hits.values()),
                  "misses": sum(stats.cache_misses.values())}))
"""


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for name in ("cold", "cached"):
            out = subprocess.run([sys.executable, "-c", PROBE], env=env,
                                 capture_output=True, text=True, check=True)
            run = json.loads(out.stdout.strip().splitlines()[-1])
            print(f"{name}: first call {run['first']:.3f} s ({run['first_cpu']:.3f} s CPU), "
                  f"step afterwards "
                  f"{run['steady'] * 1e6:.2f} us, cache hits {run['hits']}, "
                  f"misses {run['misses']}")


if __name__ == "__main__":
    main()
