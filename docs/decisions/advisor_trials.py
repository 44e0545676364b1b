"""The measurements behind the advisor's metrics (docs/decisions/advisor-metrics.md).

Run from the repository root: ``python docs/decisions/advisor_trials.py``.
Each trial prints its numbers; nothing is timed, so they are the same on
every machine (to rounding).

1. Event times: approach speed or response speed. A cube dropped onto the
   floor (the advisor tests' DROP scene), midpoint at 2 ms against rk4 at
   0.25 ms, both recorded at every step: the largest distance at the 10 ms
   sample times, at every common step time, and the bounce's time
   difference times the approach speed and times the response speed.
2. A jump of position. The advisor tests' CHAOS scene (two cubes, corrected
   rotation and impulses), rk4 at 62.5 us and 125 us: the largest distance
   at every common step up to 0.14 s and where it happens.
3. Orientation. spinning-cube.toml for 1 s (free fall, spinning): midpoint
   at 1 ms against rk4 at 0.125 ms, the distance of the reported positions
   and the distance of the bodies' points (orientation included).
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

import refsim
from refsim.advisor.records import Fidelity
from refsim.advisor.runs import with_fidelity

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "advisor"))
from test_advisor import CHAOS, DROP  # noqa: E402  (the tests' scenes, one definition)


def _run(scene, solver: str, step: float, duration: float):
    fidelity = Fidelity(solver, step, "exact", "linear")
    return refsim.simulate(with_fidelity(scene, fidelity, duration), every=1)


def _common(a, b, step_a: float, step_b: float):
    """Frame indices of ``a`` and ``b`` at the times both have a frame."""
    k = round(step_b / step_a)
    n = min((len(a.t) - 1) // k, len(b.t) - 1) + 1
    return np.arange(n) * k, np.arange(n)


def _scene(text: str):
    path = Path(tempfile.mkdtemp()) / "scene.toml"
    path.write_text(text)
    return refsim.load_scene(path)


def event_speeds() -> None:
    scene = _scene(DROP)
    h_ref, h = 0.00025, 0.002
    ref, run = _run(scene, "rk4", h_ref, 0.8), _run(scene, "midpoint", h, 0.8)
    i, j = _common(ref, run, h_ref, h)
    d = np.linalg.norm(ref.position[i] - run.position[j], axis=2).max(axis=1)
    samples = (j % round(0.01 / h)) == 0
    (e_ref, *_), (e_run, *_) = ref.events, run.events
    dt = abs(e_run.time - e_ref.time)
    v_before = ref.velocity[e_ref.step - 1, 0]
    v_after = ref.velocity[e_ref.step, 0]
    approach = float(np.linalg.norm(v_before))
    response = float(np.linalg.norm(v_after - v_before))
    print("1. event times (DROP, midpoint 2 ms against rk4 0.25 ms)")
    print(f"   bounce at {e_ref.time:.6g} s and {e_run.time:.6g} s: dt = {dt * 1e3:.3g} ms")
    print(f"   distance at the samples {d[samples].max() * 1e3:.3g} mm, at every common step "
          f"{d.max() * 1e3:.3g} mm (at t = {ref.t[i][np.argmax(d)]:.6g} s)")
    print(f"   dt x approach speed ({approach:.3g} m/s) = {dt * approach * 1e3:.3g} mm; "
          f"dt x response speed ({response:.3g} m/s) = {dt * response * 1e3:.3g} mm")


def position_jump() -> None:
    scene = _scene(CHAOS)
    h_ref, h = 6.25e-5, 1.25e-4
    ref, run = _run(scene, "rk4", h_ref, 0.6), _run(scene, "rk4", h, 0.6)
    i, j = _common(ref, run, h_ref, h)
    keep = ref.t[i] <= 0.14 + 1e-12
    d = np.linalg.norm(ref.position[i[keep]] - run.position[j[keep]], axis=2).max(axis=1)
    k = int(np.argmax(d))
    print("2. a jump of position (CHAOS, rk4 62.5 us against 125 us, up to 0.14 s)")
    print(f"   largest distance at every common step {d[k] * 1e3:.3g} mm at t = "
          f"{ref.t[i[keep]][k]:.6g} s; one step before {d[k - 1] * 1e3:.3g} mm, one after "
          f"{d[k + 1] * 1e3:.3g} mm")
    onsets = [(e.time, e.kind) for e in ref.events if abs(e.time - ref.t[i[keep]][k]) < 1e-3]
    print(f"   events within 1 ms of it in the finer run: {onsets}")


def orientation() -> None:
    scene = refsim.load_scene("spinning-cube.toml")
    h_ref, h = 0.000125, 0.001
    ref, run = _run(scene, "rk4", h_ref, 1.0), _run(scene, "midpoint", h, 1.0)
    i, j = _common(ref, run, h_ref, h)
    r = float(np.linalg.norm(scene.mesh(scene.bodies[0]).vertices, axis=1).max())
    dx = np.linalg.norm(ref.position[i] - run.position[j], axis=2).max()
    dR = ref.orientation[i] - run.orientation[j]
    chord = np.sqrt((dR * dR).sum(axis=(2, 3)) / 2.0).max()
    print("3. orientation (spinning-cube.toml, 1 s, midpoint 1 ms against rk4 0.125 ms)")
    print(f"   reported positions {dx:.3g} m apart; orientations {2 * math.asin(chord / 2):.3g} "
          f"rad apart, {chord * r * 1e3:.3g} mm at the cube's radius {r:.3g} m")


if __name__ == "__main__":
    event_speeds()
    position_jump()
    orientation()
