"""A fixed slice of the fuzz campaign, run by ``make test``.

Each case is one command line (a mutant model or scene, a special file, an
``-o`` target, a signal, hostile arguments: see :mod:`tests.fuzz.cases`) or
one call of the public API (:mod:`tests.fuzz.api_worker`), with the outcome
the laws require: refused with exactly one line naming the file and the
line or key, or accepted with a sound result; never a traceback, a signal,
a hang, a stray file or a replaced one (:mod:`tests.fuzz.judge`).

The random cases are built from the seed ``"slice"`` and their index, so the
slice is the same on every run. Where a case fails today because of a bug in
refsim, it is marked ``xfail(strict=True)`` with the root cause: it turns
into a failure (XPASS) once the bug is fixed, and the mark must then go.

Every failure message ends with the case's reproducer:
``python -m tests.fuzz.campaign --replay ID`` (a command line) or
``python -m tests.fuzz.api_worker --probe EXPR`` (an API call).
"""

from __future__ import annotations

import pytest

from tests.fuzz.api_worker import KNOWN_PROBES, Probe, judge_probe, shared_runner
from tests.fuzz.cases import case_from_id, with_timeout
from tests.fuzz.execute import execute
from tests.fuzz.judge import judge
from tests.fuzz.runner import ForkServer

#: Seconds a slice case may take before it counts as a hang: the slice's
#: cases take 0.02-0.6 s each on a loaded two-core machine, and the hangs
#: it keeps (a FIFO, a long polygon) must not cost the suite more than this.
SLICE_TIMEOUT = 3.0

#: Shorter limits for cases that hang today: opening a FIFO blocks at once,
#: so any correct refusal takes milliseconds; a 20 000-corner polygon is a
#: fraction of a second for an ear clipper that prunes its tests.
CASE_TIMEOUT = {"special:scene-fifo": 1.0, "special:model-polygon-20000-star": 2.0}

#: The same for an API probe (each probe takes milliseconds; a worker
#: restart after a crash takes about a second and is not counted here).
SLICE_PROBE_TIMEOUT = 3.0

REFUSED, ACCEPTED = "refused", "accepted"

# Root causes, as the campaign groups them (exception type, refsim frame).
QHULL_SEGFAULT = ("SIGSEGV in scipy's ConvexHull (Qhull) called by Mesh.is_convex "
                  "(refsim/models/mesh.py) for coordinates near 1e155")
SINGULAR_INERTIA = ("LinAlgError (Singular matrix / Eigenvalues did not converge) from "
                    "np.linalg.inv / eigvalsh of the inertia in Simulation.__init__ "
                    "(refsim/dynamics/simulation.py)")
TOML_RECURSION = "RecursionError in tomllib under load_scene (refsim/scenes/loader.py)"
NUMPY_WARNING_LINES = ("numpy RuntimeWarnings printed as extra 'refsim: warning:' lines "
                       "(refsim/cli.py shows every warning)")
BODY_TWICE = ("divergence message names the body twice: cli._run_bodies re-raises "
              "DivergenceError with body= after keeping 'body ...' in the text")
NOT_A_FILE_IS_MISSING = ("load_model calls a directory, FIFO, device or symlink loop "
                         "'no such file' (Path.is_file in refsim/models/loading.py)")
TEMP_LEFT = ("SIGTERM/SIGHUP end the process inside write_atomic (refsim/io.py) without "
             "removing its temporary file")
REPLACES_NODE = "write_atomic's os.replace replaces a symlink/device/FIFO given as -o"
ARGPARSE_TWO_LINES = "argparse errors print a usage line and an error line (refsim/cli.py)"
ZERO_STEPS = ("a duration below one step runs zero steps with status 0 "
              "(IntegrationConfig.n_steps rounds to 0; nothing refuses it)")
NON_UTF8_SCENE = ("a non-UTF-8 scene is reported by byte position, not line "
                  "(load_scene decodes the whole file, refsim/scenes/loader.py)")
CHARSET = ("trimesh needs charset_normalizer for an OBJ with a non-UTF-8 byte: "
           "'No module named ...' (refsim/models/loading.py _load_with_trimesh)")
TRIMESH_LOG = "trimesh logs a traceback to stderr on a run that succeeds"
EAR_CLIP = "ear clipping is too slow for a 20 000-corner polygon (refsim/models/triangulate.py)"
FIFO_SCENE = "load_scene reads a FIFO and blocks forever (read_bytes in refsim/scenes/loader.py)"
PERMISSION = ("PermissionError from Path.exists() on a path through an unsearchable "
              "directory (_bundled_if_bare in refsim/models/loading.py)")
NAME_TOO_LONG = "OSError (ENAMETOOLONG) from Path.exists() in _bundled_if_bare"
UNKNOWN_FORMAT_NO_KEY = ("a scene's model naming a non-model file is reported by the model "
                         "path alone, without the scene and its key (load_model's ModelError)")
BODY_OUTSIDE = "bodies outside the world cube are accepted (refsim/scenes/loader.py)"
DURATION_KEY = ("a bad duration is reported under integration.step "
                "(scene_from_dict's MAX_STEPS check)")
WORLD_CUBE_NO_FILE = ("mass = 1e-320 ends as 'world cube: lo has a non-finite value', "
                      "naming neither file nor key (refsim/bounds/world_cube.py)")
NONFINITE_FACTS = "refsim info prints volume nan and 'convex no' (Qhull fails) with status 0"


def xfail(reason: str):
    return pytest.mark.xfail(strict=True, reason=reason)


#: (case id, the outcome the laws require), with the mark of a known bug.
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
    # known bugs: each flips to XPASS (a failure) once fixed
    pytest.param("scene:deep_nesting:slice:0", REFUSED, marks=xfail(TOML_RECURSION)),
    pytest.param("scene:non_utf8:slice:0", REFUSED, marks=xfail(NON_UTF8_SCENE)),
    pytest.param("scene:add_key:slice:1", REFUSED, marks=xfail(BODY_TWICE)),
    pytest.param("scene+model:collapse:slice:1", REFUSED, marks=xfail(SINGULAR_INERTIA)),
    pytest.param("scene+model:binary_floats:slice:0", REFUSED,
                 marks=xfail(NUMPY_WARNING_LINES)),
    pytest.param("model:garbage_token:slice:0", ACCEPTED, marks=xfail(TRIMESH_LOG)),
    pytest.param("special:model-directory", REFUSED, marks=xfail(NOT_A_FILE_IS_MISSING)),
    pytest.param("special:scene-fifo", REFUSED, marks=xfail(FIFO_SCENE)),
    pytest.param("special:model-in-locked-directory", REFUSED, marks=xfail(PERMISSION)),
    pytest.param("special:model-name-too-long", REFUSED, marks=xfail(NAME_TOO_LONG)),
    pytest.param("special:model-obj-latin1-comment", ACCEPTED, marks=xfail(CHARSET)),
    pytest.param("special:scene-model-is-not-a-model", REFUSED,
                 marks=xfail(UNKNOWN_FORMAT_NO_KEY)),
    pytest.param("special:model-polygon-20000-star", ACCEPTED, marks=xfail(EAR_CLIP)),
    pytest.param("output:symlink", ACCEPTED, marks=xfail(REPLACES_NODE)),
    pytest.param("output:device", ACCEPTED, marks=xfail(REPLACES_NODE)),
    pytest.param("signal:SIGTERM", REFUSED, marks=xfail(TEMP_LEFT)),
    pytest.param("args:every-fraction", REFUSED, marks=xfail(ARGPARSE_TWO_LINES)),
    pytest.param("args:duration-below-one-step", REFUSED, marks=xfail(ZERO_STEPS)),
    pytest.param("known:scene-scale-1e155", REFUSED, marks=xfail(QHULL_SEGFAULT)),
    pytest.param("known:scene-scale-1e62", REFUSED, marks=xfail(SINGULAR_INERTIA)),
    pytest.param("known:scene-mass-1e-320", REFUSED, marks=xfail(WORLD_CUBE_NO_FILE)),
    pytest.param("known:scene-body-outside-cube", REFUSED, marks=xfail(BODY_OUTSIDE)),
    pytest.param("known:scene-duration-1e308", REFUSED, marks=xfail(DURATION_KEY)),
    pytest.param("known:model-scale-1e154", ACCEPTED, marks=xfail(NONFINITE_FACTS)),
]


@pytest.fixture(scope="module")
def fork_server(tmp_path_factory):
    server = ForkServer(log=tmp_path_factory.mktemp("zygote") / "zygote.log")
    yield server
    server.close()


@pytest.fixture(scope="session")
def probe_runner():
    return shared_runner(SLICE_PROBE_TIMEOUT)


def _case_report(case, record, verdict) -> str:
    o = record.outcome
    lines = [f"case {case.id}: {case.family} {case.mutator} on {case.subject}",
             f"refsim {' '.join(case.argv)}",
             f"exit {o.returncode}{' (timed out)' if o.timed_out else ''}, "
             f"{o.elapsed:.2f} s; stderr:", o.stderr.rstrip()[-1500:] or "(empty)"]
    lines += [f"[{f.column}] {f.signature}" for f in verdict.failures]
    lines.append(f"reproduce: python -m tests.fuzz.campaign --replay {case.id}")
    return "\n".join(lines)


@pytest.mark.parametrize(("case_id", "expected"), CASES)
def test_command_line_keeps_the_error_laws(case_id, expected, fork_server, tmp_path):
    case = case_from_id(case_id)
    case = with_timeout(case, min(case.timeout, CASE_TIMEOUT.get(case_id, SLICE_TIMEOUT)))
    record = execute(case, fork_server, tmp_path)
    verdict = judge(case, record)
    report = _case_report(case, record, verdict)
    assert [f.signature for f in verdict.failures] == [], report
    outcome = ACCEPTED if verdict.accepted else REFUSED if verdict.refused_ok else None
    assert outcome == expected, report


ALLOCATION = "MemoryError: an allocation of many GB is attempted, not refused"
OPTION_VALUE_ERROR = ("ValueError, not OptionError, for an unknown level/method/kernel "
                      "(_check in refsim/collision/bodies.py, check_kernel in bvh.py)")
BVH_BEST = ("UnboundLocalError 'best' in build_tree (refsim/collision/bvh.py) for "
            "coordinates >= 1e154")
NONE_MESH = "AttributeError for None as a mesh (no type check before mesh.derived)"
TRAJECTORY_LOAD = ("Trajectory.load lets FileNotFoundError/KeyError through "
                   "(refsim/dynamics/trajectory.py)")
PLAIN_REFSIM_ERROR = ("plain RefsimError (neither ValueError nor TypeError) for an unknown "
                      "kernel (refsim/bounds/aabb_linear.py)")
SPHERE_OVERFLOW = ("level='sphere' says apart for overlapping cubes at +-2.5e307: the "
                   "squared centre distance overflows (refsim/collision/spheres.py)")
SILENT_ACCEPT = "a forbidden argument is accepted silently"
STEP_TYPE = "TypeError from rk_step for y=None (refsim/solvers/explicit_rk.py)"


def known(name: str, expected: str, reason: str):
    """A probe of tests.fuzz.api_worker.KNOWN_PROBES, marked with its root cause."""
    return pytest.param(KNOWN_PROBES[name], expected, marks=xfail(reason), id=name)


#: (probe, the outcome the law requires), with the mark of a known bug.
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
    known("bvh-best-1e155", ACCEPTED, BVH_BEST),
    known("sphere-overflow", ACCEPTED, SPHERE_OVERFLOW),
    known("level-bogus", REFUSED, OPTION_VALUE_ERROR),
    known("kernel-bogus", REFUSED, OPTION_VALUE_ERROR),
    known("none-mesh", REFUSED, NONE_MESH),
    known("particles-1e10", REFUSED, ALLOCATION),
    known("integrate-1e9-steps", REFUSED, ALLOCATION),
    known("trajectory-missing", REFUSED, TRAJECTORY_LOAD),
    known("trajectory-partial", REFUSED, TRAJECTORY_LOAD),
    known("aabb-kernel-bogus", REFUSED, PLAIN_REFSIM_ERROR),
    known("run-negative", REFUSED, SILENT_ACCEPT),
    known("duration-negative", REFUSED, SILENT_ACCEPT),
    known("every-fraction", REFUSED, SILENT_ACCEPT),
    known("toml-nested-500", REFUSED, TOML_RECURSION),
    known("step-y-none", REFUSED, STEP_TYPE),
    known("obj-latin1", ACCEPTED, CHARSET),
    known("collinear-body", REFUSED, SINGULAR_INERTIA),
]


@pytest.mark.parametrize(("probe", "expected"), PROBES)
def test_public_api_keeps_the_error_law(probe, expected, probe_runner):
    outcome = probe_runner.run(probe)
    failures = judge_probe(probe, outcome)
    facts = outcome.facts
    status = facts.get("status") or (f"signal {outcome.signal}" if outcome.signal else "hang")
    said = facts.get("message", facts.get("repr", ""))[:300]
    report = "\n".join([f"{probe.function}: {probe.code}",
                        f"outcome: {status} {facts.get('type', '')} {said}",
                        *[f"[{f.column}] {f.signature}" for f in failures],
                        f"reproduce: {probe.reproducer()}"])
    assert [f.signature for f in failures] == [], report
    assert {"ok": ACCEPTED, "raised": REFUSED}.get(facts.get("status")) == expected, report
