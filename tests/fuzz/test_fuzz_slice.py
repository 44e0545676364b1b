"""A fixed slice of the fuzz campaign, run by ``make test``.

Each case is one command line (a mutant model or scene, a special file, an
``-o`` target, a signal, hostile arguments: see :mod:`tests.fuzz.cases`) or
one call of the public API (:mod:`tests.fuzz.api_worker`), with the outcome
the laws require: refused with exactly one line naming the file and the
line or key, or accepted with a sound result; never a traceback, a signal,
a hang, a stray file or a replaced one (:mod:`tests.fuzz.judge`).

The random cases are built from the seed ``"slice"`` and their index, so the
slice is the same on every run. A case that fails because of a bug in refsim
is marked ``pytest.mark.xfail(strict=True, reason=<root cause>)`` until the
fix, which turns it into an XPASS failure and so removes the mark; every bug
the campaign has found so far is fixed, and its case guards the fix.

Every failure message ends with the case's reproducer:
``python -m tests.fuzz.campaign --replay ID`` (a command line) or
``python -m tests.fuzz.api_worker --probe EXPR`` (an API call).
"""

from __future__ import annotations

import pytest

from tests.fuzz.api_worker import KNOWN_PROBES, Probe, judge_probe, shared_runner
from tests.fuzz.cases import case_from_id, with_cpu_limit
from tests.fuzz.execute import execute
from tests.fuzz.judge import judge
from tests.fuzz.runner import ForkServer

#: Seconds of CPU time a slice case may use before it counts as over its CPU
#: limit: the slice's cases use well under a second each, and a slow loop
#: coming back (a long polygon) must not cost the suite more than this. A
#: limit in CPU time, not wall time, so that a loaded machine cannot fail a
#: case; a case that waits (a FIFO) is stopped by the wall-clock backstop,
#: tests.fuzz.runner.WALL_FACTOR times its CPU limit, as a hang.
SLICE_CPU_LIMIT = 3.0

#: Smaller limits for cases that once hung: opening a FIFO blocks at once,
#: so any correct refusal takes milliseconds (and the backstop comes sooner);
#: a 20 000-corner polygon is a fraction of a second for an ear clipper that
#: prunes its tests.
CASE_CPU_LIMIT = {"special:scene-fifo": 1.0, "special:model-polygon-20000-star": 2.0}

#: The same for an API probe (each probe uses milliseconds; a worker
#: restart after a crash is not counted here).
SLICE_PROBE_CPU_LIMIT = 3.0

REFUSED, ACCEPTED = "refused", "accepted"

#: (case id, the outcome the laws require).
CASES = [
    # mutants that refsim handles as it should (regression guards)
    pytest.param("model:truncate:slice:1", REFUSED),
    pytest.param("model:binary_junk:slice:0", REFUSED),
    pytest.param("model:hostile_number:slice:1", REFUSED),
    pytest.param("model:huge_count:slice:0", REFUSED),
    pytest.param("model:hostile_rot:slice:0", REFUSED),
    pytest.param("model:deep_nesting:slice:1", ACCEPTED),
    pytest.param("model:collapse:slice:0", ACCEPTED),
    pytest.param("scene:truncate:slice:0", REFUSED),
    pytest.param("scene:hostile_number:slice:0", REFUSED),
    pytest.param("scene:set_key:slice:0", REFUSED),
    pytest.param("scene:model_ref:slice:0", REFUSED),
    pytest.param("scene:swap_sections:slice:1", ACCEPTED),
    pytest.param("scene+model:truncate:slice:0", REFUSED),
    pytest.param("scene+model:remove_line:slice:0", ACCEPTED),
    pytest.param("special:scene-directory", REFUSED),
    pytest.param("special:model-unreadable", REFUSED),
    pytest.param("special:model-empty-ac", REFUSED),
    pytest.param("output:directory", REFUSED),
    pytest.param("signal:SIGINT", REFUSED),
    pytest.param("args:every-zero", REFUSED),
    # bugs the campaign found, fixed: each a regression guard now
    pytest.param("scene:deep_nesting:slice:0", REFUSED),
    pytest.param("scene:non_utf8:slice:0", REFUSED),
    pytest.param("scene:add_key:slice:1", REFUSED),
    pytest.param("scene+model:collapse:slice:1", REFUSED),
    pytest.param("scene+model:binary_floats:slice:0", REFUSED),
    pytest.param("model:garbage_token:slice:0", ACCEPTED),
    pytest.param("special:model-directory", REFUSED),
    pytest.param("special:scene-fifo", REFUSED),
    pytest.param("special:model-in-locked-directory", REFUSED),
    pytest.param("special:model-name-too-long", REFUSED),
    pytest.param("special:model-obj-latin1-comment", ACCEPTED),
    pytest.param("special:scene-model-is-not-a-model", REFUSED),
    pytest.param("special:model-polygon-20000-star", ACCEPTED),
    pytest.param("output:symlink", ACCEPTED),
    # refsim writes regular files only (refsim/storage/writing.py: an -o naming a device
    # is refused, not written through; nothing is replaced either way)
    pytest.param("output:device", REFUSED),
    pytest.param("signal:SIGTERM", REFUSED),
    pytest.param("args:every-fraction", REFUSED),
    pytest.param("args:duration-below-one-step", REFUSED),
    pytest.param("known:scene-scale-1e155", REFUSED),
    pytest.param("known:scene-scale-1e62", REFUSED),
    pytest.param("known:scene-mass-1e-320", REFUSED),
    pytest.param("known:scene-body-outside-cube", REFUSED),
    pytest.param("known:scene-duration-1e308", REFUSED),
    pytest.param("known:model-scale-1e154", ACCEPTED),
]


@pytest.fixture(scope="module")
def fork_server(tmp_path_factory):
    server = ForkServer(log=tmp_path_factory.mktemp("zygote") / "zygote.log")
    yield server
    server.close()


@pytest.fixture(scope="session")
def probe_runner():
    return shared_runner(SLICE_PROBE_CPU_LIMIT)


def _case_report(case, record, verdict) -> str:
    o = record.outcome
    lines = [f"case {case.id}: {case.family} {case.mutator} on {case.subject}",
             f"refsim {' '.join(case.argv)}",
             f"exit {o.returncode}{' (timed out)' if o.timed_out else ''}"
             f"{' (over its CPU limit)' if o.cpu_exceeded else ''}, "
             f"{o.elapsed:.2f} s; stderr:", o.stderr.rstrip()[-1500:] or "(empty)"]
    lines += [f"[{f.column}] {f.signature}" for f in verdict.failures]
    lines.append(f"reproduce: python -m tests.fuzz.campaign --replay {case.id}")
    return "\n".join(lines)


@pytest.mark.parametrize(("case_id", "expected"), CASES)
def test_command_line_keeps_the_error_laws(case_id, expected, fork_server, tmp_path):
    case = case_from_id(case_id)
    case = with_cpu_limit(case, min(case.cpu_limit,
                                    CASE_CPU_LIMIT.get(case_id, SLICE_CPU_LIMIT)))
    record = execute(case, fork_server, tmp_path)
    verdict = judge(case, record)
    report = _case_report(case, record, verdict)
    assert [f.signature for f in verdict.failures] == [], report
    outcome = ACCEPTED if verdict.accepted else REFUSED if verdict.refused_ok else None
    assert outcome == expected, report


def known(name: str, expected: str):
    """A probe of tests.fuzz.api_worker.KNOWN_PROBES: a bug the campaign found."""
    return pytest.param(KNOWN_PROBES[name], expected, id=name)


#: (probe, the outcome the law requires).
PROBES = [
    pytest.param(Probe("triangles_intersect", "triangles_intersect(None, "
                       "[[0, 0, 0], [1, 0, 0], [0, 1, 0]])", must_refuse=True), REFUSED,
                 id="triangle-none"),
    pytest.param(Probe("Mesh", "Mesh(np.full((3, 3), np.nan), [[0, 1, 2]])",
                       must_refuse=True), REFUSED, id="mesh-nan"),
    pytest.param(Probe("load_scene", "load_scene(DIR_TOML)", must_refuse=True), REFUSED,
                 id="scene-directory"),
    pytest.param(Probe("ParticleConfig", "ParticleConfig(count=-5)", must_refuse=True),
                 REFUSED, id="particles-negative"),
    pytest.param(Probe("integrate", "integrate(decay, [1.0], 0.0, 1.0, 0.1)",
                       must_accept=True, check="_result[1].shape == (11, 1)",
                       law="y has shape (11, 1)"), ACCEPTED, id="integrate-ten-steps"),
    pytest.param(Probe("simulate", "simulate(BOUNCE, duration=0.01)", must_accept=True,
                       check="_result.n_frames == 11", law="11 frames"), ACCEPTED,
                 id="simulate-ten-steps"),
    pytest.param(Probe("bodies_collide", "bodies_collide(CUBE, ID, CUBE, "
                       "(np.eye(3), np.array([0.5, 0.0, 0.0])))", must_accept=True,
                       check="_result is True", law="touching cubes collide"), ACCEPTED,
                 id="cubes-touch"),
    known("bvh-best-1e155", ACCEPTED),
    known("sphere-overflow", ACCEPTED),
    known("level-bogus", REFUSED),
    known("kernel-bogus", REFUSED),
    known("none-mesh", REFUSED),
    known("particles-1e10", REFUSED),
    known("integrate-1e9-steps", REFUSED),
    known("trajectory-missing", REFUSED),
    known("trajectory-partial", REFUSED),
    known("aabb-kernel-bogus", REFUSED),
    known("run-negative", REFUSED),
    known("duration-negative", REFUSED),
    known("every-fraction", REFUSED),
    known("toml-nested-500", REFUSED),
    known("step-y-none", REFUSED),
    known("obj-latin1", ACCEPTED),
    known("collinear-body", REFUSED),
]


@pytest.mark.parametrize(("probe", "expected"), PROBES)
def test_public_api_keeps_the_error_law(probe, expected, probe_runner):
    outcome = probe_runner.run(probe)
    failures = judge_probe(probe, outcome)
    facts = outcome.facts
    status = facts.get("status") or (f"signal {outcome.signal}" if outcome.signal
                                     else "over its CPU limit" if outcome.cpu_exceeded
                                     else "hang")
    said = facts.get("message", facts.get("repr", ""))[:300]
    report = "\n".join([f"{probe.function}: {probe.code}",
                        f"outcome: {status} {facts.get('type', '')} {said}",
                        *[f"[{f.column}] {f.signature}" for f in failures],
                        f"reproduce: {probe.reproducer()}"])
    assert [f.signature for f in failures] == [], report
    assert {"ok": ACCEPTED, "raised": REFUSED}.get(facts.get("status")) == expected, report
