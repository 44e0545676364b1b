"""CPU seconds of one engine's column of the conformance matrix (the
shared matrix's 20 cases, seed 0), each engine run alone in this process.

    python docs/decisions/engine_column_cpu.py [ENGINE ...]

Default: pybullet, drake and drake-hydroelastic. Used in
docs/decisions/test-suite-time.md, alternating the code before and after a
change (git stash) to compare an adapter's cost."""

from __future__ import annotations

import os
import sys
import time

os.environ["REFSIM_CACHE_DIR"] = ""     # the case sets built, not read from a cache


def main(names: list[str]) -> None:
    from refsim.conformance.matrix import run_matrix
    from refsim.conformance.shipped import SHIPPED_ENGINES

    for name in names:
        start = time.process_time()
        run_matrix({name: SHIPPED_ENGINES[name]}, cases=20, seed=0)
        print(f"{name}: {time.process_time() - start:.2f} CPU s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:] or ["pybullet", "drake", "drake-hydroelastic"])
