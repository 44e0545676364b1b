"""The fixed cost of three small compiled queries, two checkouts alternating.

    python docs/decisions/query_dispatch_overhead.py BEFORE_CHECKOUT AFTER_CHECKOUT [ROUNDS]

Each round runs this script's measurement once in a fresh process on each
checkout (its ``refsim`` first on ``sys.path``; each checkout keeps its own
numba cache, warmed by one untimed process first), before then after. A
process times three queries on the bundled meshes, compiled kernel:

- ``bodies_collide`` of two unit cubes 10 m apart (the boolean query's
  fixed cost: one node pair);
- ``bodies_collide`` of two overlapping tori (torus.ac, shifted by
  (0.3, 0.2, 0.1));
- ``intersecting_pairs`` of the two far cubes (the all-pairs query asks
  the boolean one first).

Each figure is the least of 7 repeats of 2000 calls, taken three times; a
process reports the least of the three. The table gives each checkout's
median over the rounds, their ratio and the median of the rounds'
after/before ratios, in microseconds.
"""

from __future__ import annotations

import statistics
import subprocess
import sys

QUERIES = ("collide far", "collide near", "pairs far")


def measure(checkout: str) -> dict[str, float]:
    """This process's figures (microseconds) with ``checkout``'s refsim."""
    sys.path.insert(0, checkout)
    import timeit

    import numpy as np

    import refsim
    from refsim.collision.bodies import bodies_collide, intersecting_pairs

    torus, cube = refsim.load_model("torus.ac"), refsim.load_model("cube.ac")
    here = (np.eye(3), np.zeros(3))
    far = (np.eye(3), np.array([10.0, 0.0, 0.0]))
    near = (np.eye(3), np.array([0.3, 0.2, 0.1]))
    cases = {"collide far": (bodies_collide, (cube, here, cube, far)),
             "collide near": (bodies_collide, (torus, here, torus, near)),
             "pairs far": (intersecting_pairs, (cube, here, cube, far))}
    out = {}
    for name, (query, args) in cases.items():
        def call(query=query, args=args):
            return query(*args, kernel="compiled")

        call()
        out[name] = min(min(timeit.repeat(call, number=2000, repeat=7)) / 2000 * 1e6
                        for _ in range(3))
    return out


def run(checkout: str) -> dict[str, float]:
    done = subprocess.run([sys.executable, __file__, "--measure", checkout],
                          capture_output=True, text=True, check=True)
    return {name: float(value) for name, value in
            (line.rsplit(" ", 1) for line in done.stdout.strip().splitlines())}


def main(before: str, after: str, rounds: int) -> None:
    run(before), run(after)                        # warm each checkout's numba cache
    figures: dict[str, list[dict[str, float]]] = {"before": [], "after": []}
    for _ in range(rounds):
        figures["before"].append(run(before))
        figures["after"].append(run(after))
    print("| query | before (us) | after (us) | ratio of medians | median of ratios |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name in QUERIES:
        b = [f[name] for f in figures["before"]]
        a = [f[name] for f in figures["after"]]
        ratios = [x / y for x, y in zip(a, b, strict=True)]
        print(f"| {name} | {statistics.median(b):.3f} | {statistics.median(a):.3f} | "
              f"{statistics.median(a) / statistics.median(b):.3f} | "
              f"{statistics.median(ratios):.3f} |")


if __name__ == "__main__":
    if sys.argv[1] == "--measure":
        for name, value in measure(sys.argv[2]).items():
            print(f"{name} {value!r}")
    else:
        main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 8)
