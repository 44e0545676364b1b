"""The one kernel switch (refsim.kernels) and its registry of kernel pairs:
every pair gives the same answers, bit for bit, on the readable and the
compiled kernel; every mirror names the readable function it mirrors; the
default and the switch behave as documented."""

from __future__ import annotations

import inspect
import os
import subprocess
import sys

import numpy as np
import pytest

import refsim
from refsim import kernels
from refsim.collision.broad_phase import overlapping_pairs
from refsim.collision.seed_levels import exact_pairs, triangle_box_pairs
from refsim.dynamics import impulse
from refsim.dynamics.body_response import contact_geometry
from refsim.dynamics.boxes import boxes_kernel
from refsim.dynamics.rotation_seed import orientation_step_seed_kernel
from refsim.errors import OptionError
from refsim.kernels import compiled_here
from refsim.models import polygons
from refsim.models.triangulate import ear_clip_indexed
from refsim.types import random_rotation

RNG_SEED = 20261130


def _same(a, b) -> bool:
    """Bitwise equality of nested tuples/lists of arrays and numbers."""
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return np.asarray(a).tobytes() == np.asarray(b).tobytes() and \
        np.asarray(a).shape == np.asarray(b).shape


def _poses(n, reach=1.2):
    rng = np.random.default_rng(RNG_SEED)
    return [(random_rotation(rng), rng.uniform(-reach, reach, 3)) for _ in range(n)]


TORUS, STAR, CUBE = (refsim.load_model(m) for m in ("torus.ac", "star.ac", "cube.ac"))
IDENTITY = (np.eye(3), np.zeros(3))


def _broad_phase(kernel):
    rng = np.random.default_rng(RNG_SEED)
    out = []
    for n in (0, 1, 7, 40):
        lo = rng.integers(-5, 5, (n, 3)).astype(float)
        out.append(overlapping_pairs(lo, lo + rng.integers(0, 4, (n, 3)), kernel=kernel))
    return out


def _impulses(kernel):
    rng = np.random.default_rng(RNG_SEED)
    out = []
    for _ in range(20):
        v, w = rng.normal(size=3), rng.normal(size=3)
        r_a = rng.normal(size=(4, 3))
        n = np.array([0.0, 1.0, 0.0])
        P = impulse.wall_impulses(r_a, n, 0.5, np.eye(3) * 2.0, v, w, 0.8, 0.3, kernel=kernel)
        out.append((P, v, w))
    return out


def _island_impulses(kernel):
    """Random islands: three bodies and a wall (the static fourth row), sets
    of one to four contacts between random pairs and against the wall."""
    rng = np.random.default_rng(RNG_SEED)
    out = []
    for _ in range(20):
        v, w = np.zeros((4, 3)), np.zeros((4, 3))
        v[:3], w[:3] = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
        I_inv = np.zeros((4, 3, 3))
        I_inv[:3] = np.eye(3) * rng.uniform(0.5, 2.0, size=(3, 1, 1))
        body_a = np.array([0, 1, 2, 0], dtype=np.int64)
        body_b = np.array([3, 0, 1, 2], dtype=np.int64)
        sizes = rng.integers(1, 5, size=4)
        starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        r_a = rng.normal(size=(starts[-1], 3))
        r_b = rng.normal(size=(starts[-1], 3))
        r_b[:starts[1]] = 0.0                                    # the wall's
        normals = rng.normal(size=(4, 3))
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        P = np.empty((starts[-1], 4))
        m_inv = np.array([1.0, 0.5, 2.0, 0.0])
        count = impulse.solve_island(starts, body_a, body_b, r_a, r_b, normals, m_inv, I_inv,
                                     v, w, np.full(4, 0.7), np.full(4, 0.4),
                                     impulse.RESTITUTION_THRESHOLD,
                                     impulse.ITERATIONS, P, kernel=kernel)
        out.append((count, P, v, w))
    return out


def _ear_clipping(kernel):
    return [ear_clip_indexed(polygons.star(200), kernel=kernel),
            ear_clip_indexed(polygons.comb(120), kernel=kernel)]


def _seed_rotation(kernel):
    rng = np.random.default_rng(RNG_SEED)
    R = np.stack([random_rotation(rng) for _ in range(12)])
    w = rng.normal(size=(12, 3)) * 5.0
    return [orientation_step_seed_kernel(R, w, h, kernel=kernel) for h in (1e-3, 0.05)]


def _batched_boxes(kernel):
    rng = np.random.default_rng(RNG_SEED)
    R = np.stack([random_rotation(rng) for _ in range(9)])
    origin = rng.normal(size=(9, 3))
    return boxes_kernel(np.ascontiguousarray(CUBE.vertices.T), R, origin, kernel=kernel)


def _contact_geometry(kernel):
    """Two cubes turned at random, their centres 0.8 to 1.6 apart: touching,
    overlapping and apart (a negative depth)."""
    rng = np.random.default_rng(RNG_SEED)
    out = []
    for _ in range(30):
        R_a, R_b = random_rotation(rng), random_rotation(rng)
        c_a = rng.normal(size=3)
        c_a *= rng.uniform(0.8, 1.6) / np.linalg.norm(c_a)
        c_b = np.zeros(3)
        world_a = CUBE.vertices @ R_a.T + c_a
        world_b = CUBE.vertices @ R_b.T + c_b
        g = contact_geometry(world_a, world_b, c_a, c_b, R_a, R_b, kernel=kernel)
        out.append((g.n, g.depth, g.point, g.extent))
    return out


def _free_rotation(kernel):
    """The spinning cube's scene with a brick (three distinct moments) under
    the corrected rotation, 300 steps of the readable step (its rotation
    stage calls the pair the simulation chose), landing on the floor."""
    import tomllib
    from pathlib import Path

    from refsim.dynamics.simulation import Simulation
    from refsim.scenes.loader import scene_from_dict

    path = Path(__file__).parents[1] / "scenes" / "spinning-cube.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["dynamics"]["rotation"] = "impulse"
    data["body"][0].update(model="brick.ac", position=[0.0, -4.2, 0.0])   # lands in the run
    sim = Simulation(scene_from_dict(data), kernel=kernel)
    for _ in range(300):
        sim.step()
    return sim.R.copy(), sim.w.copy(), sim.x.copy()


def _linear_scan(kernel):
    return [refsim.aabb_linear(TORUS, pose, kernel=kernel) for pose in _poses(10)]


def _incremental(kernel):
    tracker = refsim.IncrementalAABB(refsim.load_model("sphere-2k.ac"), kernel=kernel)
    out = []
    for pose in _poses(20):
        out.append((tracker.update(pose), tracker.extremes.copy(), tracker.visits))
    return out


def _fresh(mesh):
    """A copy of ``mesh`` with nothing derived yet (its trees unbuilt)."""
    return refsim.Mesh(mesh.vertices.copy(), mesh.faces.copy())


def _hierarchy_build(kernel):
    from refsim.collision.bvh import tree_of
    from refsim.collision.bvh_exact import frame_topology_of

    out = []
    for mesh in (TORUS, STAR, CUBE):
        for tree in (tree_of(_fresh(mesh), kernel), frame_topology_of(_fresh(mesh), kernel)):
            out.append((tree.left, tree.right, tree.start, tree.count, tree.order))
    return out


def _oriented_boxes(kernel):
    from refsim.collision.bvh_exact import frame_tree_of

    frames = [frame_tree_of(_fresh(mesh), kernel) for mesh in (TORUS, STAR, CUBE)]
    return [(f.links, f.tree.order, f.boxes, f.reach, f.axes_deviation) for f in frames]


def _hierarchy_boxes(kernel):
    return [refsim.intersecting_pairs(TORUS, IDENTITY, STAR, pose, level="triangle-aabb",
                                      kernel=kernel) for pose in _poses(6)]


def _certified_filter(kernel):
    out = []
    for pose in _poses(6):
        wa = refsim.collision.boxes.world_vertices(TORUS, IDENTITY)
        wb = refsim.collision.boxes.world_vertices(STAR, pose)
        candidates = triangle_box_pairs(wa, TORUS.faces, wb, STAR.faces)
        out.append(exact_pairs(wa, TORUS.faces, wb, STAR.faces, candidates, kernel))
    return out


def _exact_hierarchy(kernel):
    return [refsim.intersecting_pairs(TORUS, IDENTITY, STAR, pose, kernel=kernel)
            for pose in _poses(6)] + [
        refsim.bodies_collide(CUBE, IDENTITY, CUBE, (np.eye(3), np.array([1.0, 0.0, 0.0])),
                              kernel=kernel)]


def _exact_collide(kernel):
    """Unit cubes touching, 2^-40 apart, overlapping and far apart; then
    the torus and the star at the shared poses (both answers occur)."""
    offsets = ([1.0, 0.0, 0.0], [1.0 + 2.0 ** -40, 0.0, 0.0], [0.5, 0.5, 0.0], [3.0, 0.0, 0.0])
    return [refsim.bodies_collide(CUBE, IDENTITY, CUBE, (np.eye(3), np.array(offset)),
                                  kernel=kernel) for offset in offsets] + [
        refsim.bodies_collide(TORUS, IDENTITY, STAR, pose, kernel=kernel) for pose in _poses(6)]


def _exact_stage(kernel):
    """Touching bodies, where every candidate pair reaches the exact stage."""
    sphere = refsim.load_model("sphere-2k.ac")
    on_top = (np.eye(3), np.array([0.0, 1.5, 0.0]))
    return [refsim.intersecting_pairs(CUBE, IDENTITY, CUBE, (np.eye(3), offset), kernel=kernel)
            for offset in np.array([[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.5, 1.0, 0.25]])] + [
        refsim.intersecting_pairs(sphere, IDENTITY, CUBE, on_top, kernel=kernel),
        refsim.bodies_collide(sphere, IDENTITY, CUBE, on_top, kernel=kernel)]


def _contact_region(kernel):
    """A cube resting on a cube (face, edge and corner overlaps), a sphere
    sunk into a cube, and two cubes apart (no points)."""
    from refsim.collision.contact import contact_points

    sphere = refsim.load_model("sphere-2k.ac")
    up = np.array([0.0, 1.0, 0.0])
    tilted = np.array([[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    poses = [(np.eye(3), np.array([0.0, 0.99, 0.0])), (tilted, np.array([0.4, 1.2, 0.3])),
             (np.eye(3), np.array([0.0, 3.0, 0.0]))]
    return [contact_points(CUBE, pose, CUBE, IDENTITY, up, kernel=kernel) for pose in poses] + [
        contact_points(sphere, (np.eye(3), np.array([0.0, 1.45, 0.0])), CUBE, IDENTITY, up,
                       kernel=kernel)]


def _particles(kernel):
    out = []
    for solver in sorted(refsim.SOLVERS):
        for drag_model in ("linear", "quadratic"):
            config = refsim.ParticleConfig(count=300, seed=4, solver=solver, step=0.01,
                                           drag=0.7, drag_model=drag_model, half_size=0.5,
                                           speed_min=5.0, speed_max=40.0,
                                           box_lo=(-0.5,) * 3, box_hi=(0.5,) * 3)
            system = refsim.ParticleSystem(config, kernel=kernel)
            system.run(30)
            out.append((system.state, system.bounces, system.t))
    return out


def _simulation_loop(kernel):
    from refsim.dynamics.simulation import Simulation
    from refsim.studies.bounce_scenes import cubes_scene

    out = []
    for rotation in ("off", "seed"):
        sim = Simulation(cubes_scene(12, rotation, seed=8), kernel=kernel)
        sim.advance(1500)
        events = [(e.kind, e.step, e.time, e.body, e.other) for e in sim.events]
        out.append((sim.x, sim.v, sim.w, sim.R, events))
    return out


#: The cases of each registry entry, run with each kernel.
CASES = {
    "broad-phase sweep": _broad_phase,
    "contact impulses": _impulses,
    "island contact impulses": _island_impulses,
    "indexed ear clipping": _ear_clipping,
    "indexed corner tree": _ear_clipping,
    "seed orientation step": _seed_rotation,
    "batched boxes": _batched_boxes,
    "contact geometry": _contact_geometry,
    "contact region": _contact_region,
    "free rotation steps": _free_rotation,
    "linear box scan": _linear_scan,
    "incremental box": _incremental,
    "hierarchy build": _hierarchy_build,
    "oriented node boxes": _oriented_boxes,
    "hierarchy refit": _hierarchy_boxes,
    "hierarchy traversal": _hierarchy_boxes,
    "certified triangle filter": _certified_filter,
    "exact hierarchy query": _exact_hierarchy,
    "exact hierarchy collide": _exact_collide,
    "exact triangle stage": _exact_stage,
    "fused particle steps": _particles,
    "simulation loop": _simulation_loop,
}


def test_every_registered_pair_has_cases_and_every_case_a_pair():
    assert set(CASES) == set(kernels.PAIRS)


@pytest.mark.parametrize("name", sorted(kernels.PAIRS))
def test_readable_and_compiled_agree_bit_for_bit(name):
    readable, compiled = CASES[name]("readable"), CASES[name]("compiled")
    assert _same(readable, compiled), name


#: The pairs whose callers still choose by hand rather than through the
#: pair (``pair(kernel)`` or ``pair.pick``), with the reason; every other
#: pair's cases must run through it (:func:`test_each_pair_dispatches_its_cases`).
CHOSEN_BY_HAND = {
    "simulation loop": "the simulation runs the compiled loop only where it does the "
                       "scene's choices (loop_support): a choice of the scene as much as of "
                       "the kernel",
    "exact triangle stage": "called from inside the compiled query",
}


def test_every_pair_is_a_kernel_pair_under_its_name():
    for name, pair in kernels.PAIRS.items():
        assert isinstance(pair, kernels.KernelPair) and pair.name == name
    assert set(CHOSEN_BY_HAND) <= set(kernels.PAIRS)


@pytest.mark.parametrize("name", sorted(set(kernels.PAIRS) - set(CHOSEN_BY_HAND)))
@pytest.mark.parametrize("kernel", kernels.KERNELS)
def test_each_pair_dispatches_its_cases(name, kernel, monkeypatch):
    """The public path of each pair's cases calls the pair's function for
    the kernel asked, and never the other: the registry is what chooses."""
    pair = kernels.PAIRS[name]
    calls = {"readable": 0, "compiled": 0}

    def spy(side):
        function = getattr(pair, side)

        def counted(*args, **kwargs):
            calls[side] += 1
            return function(*args, **kwargs)
        return counted

    for side in kernels.KERNELS:
        monkeypatch.setattr(pair, f"_{side}", spy(side))
    CASES[name](kernel)
    other = "compiled" if kernel == "readable" else "readable"
    assert calls[kernel] > 0 and calls[other] == 0, (name, calls)


def test_a_pair_chooses_as_the_switch_does(monkeypatch):
    pair = kernels.BROAD_PHASE_SWEEP
    assert pair("readable") is pair.pick("readable") is pair.readable
    assert pair("compiled") is pair.pick("compiled") is pair.compiled
    monkeypatch.setenv(kernels.KERNELS_ENV, "readable")
    assert pair(None) is pair.readable
    monkeypatch.setenv(kernels.KERNELS_ENV, "compiled")
    assert pair(None) is pair.compiled
    with pytest.raises(OptionError, match="kernel"):
        pair("fast")
    with pytest.raises(ValueError, match="exists already"):
        kernels.KernelPair(pair.name, pair.readable_path, pair.compiled_path)


@pytest.mark.parametrize("name", sorted(kernels.PAIRS))
def test_each_pair_resolves_and_each_mirror_names_its_readable_function(name):
    pair = kernels.PAIRS[name]
    readable_path, compiled_path, how = pair.readable_path, pair.compiled_path, pair.how
    assert callable(pair.readable) and callable(pair.compiled)
    assert how in (kernels.COMPILED_FROM_SOURCE, kernels.MIRRORS)
    if how == kernels.MIRRORS:
        readable_path, compiled_path = pair.mirror
        compiled = kernels.resolve(compiled_path)
        kernels.resolve(readable_path)
        doc = inspect.getdoc(getattr(compiled, "py_func", compiled)) or ""
        readable_name = readable_path.split(":")[1].split(".")[-1]
        assert doc.startswith("Mirrors") and readable_name in doc, (name, doc[:120])
        return
    assert pair.mirror[1] == compiled_path, name       # the compiled side is the one dispatched
    readable, compiled = kernels.resolve(pair.mirror[0]), pair.compiled
    if pair.readable is not readable:
        # a thin readable caller: the source itself, or the one function the
        # source calls for each body, on Python floats
        used = inspect.getclosurevars(pair.readable).globals
        assert used.get("python_floats") is kernels.python_floats, (name, used)
        called = [f for f in used.values() if inspect.isfunction(f) and f is not
                  kernels.python_floats]
        inner = inspect.getclosurevars(readable).globals.values()
        assert len(called) == 1 and (called[0] is readable or called[0] in inner), (name, used)
    if hasattr(compiled, "py_func"):
        # compiled from the readable source: numba's dispatcher wraps that very function
        assert compiled.py_func is readable, name
    else:
        # a plain function that calls compile_kernel(the readable function): the
        # names its code looks up are refsim.kernels's compile_kernel and that function
        used = inspect.getclosurevars(compiled).globals
        assert used.get("compile_kernel") is kernels.compile_kernel, (name, used)
        assert readable in used.values(), (name, used)
        assert "compile_kernel(" + readable.__name__ + ")" in inspect.getsource(compiled), name


def test_the_default_is_compiled_here_and_the_switch_is_one_word(monkeypatch):
    assert kernels.choose_kernel(None) == "compiled"
    monkeypatch.setenv(kernels.KERNELS_ENV, "readable")
    assert kernels.choose_kernel(None) == "readable"
    assert kernels.choose_kernel("compiled") == "compiled"         # explicit wins
    monkeypatch.setenv(kernels.KERNELS_ENV, "fast")
    with pytest.raises(OptionError, match="REFSIM_KERNELS must be one of"):
        kernels.choose_kernel(None)
    with pytest.raises(OptionError, match="kernel must be one of 'readable', 'compiled'"):
        kernels.choose_kernel("numba")


def test_without_numba_compiled_is_refused_and_readable_is_the_default(monkeypatch):
    monkeypatch.setattr(kernels, "numba_error", lambda: "ImportError: no numba here")
    monkeypatch.delenv(kernels.KERNELS_ENV, raising=False)
    with pytest.raises(OptionError, match="no numba here"):
        kernels.choose_kernel("compiled")
    kernels._warn_readable.cache_clear()
    with pytest.warns(kernels.KernelWarning, match="readable kernels"):
        assert kernels.choose_kernel(None) == "readable"


# -- numba's cache and the sources a cached module compiles in -----------------------------

def _cached_kernel_modules() -> dict[str, str]:
    """Every refsim module with a function numba caches on disk (by its
    decorator's ``cache=True``): dotted name -> source. (refsim.kernels's
    compile_kernel caches the readable functions of other modules, each
    keyed by its own file; they call no compiled code of another module.)"""
    from pathlib import Path

    root = Path(refsim.__file__).parent
    found = {}
    for path in sorted(root.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        dotted = ".".join(("refsim", *path.relative_to(root).with_suffix("").parts))
        if "cache=True" in text and dotted != "refsim.kernels":
            found[dotted] = text
    return found


def test_each_cached_kernel_module_holds_the_digest_of_what_it_compiles_in():
    # an edit of a module that a cached kernel compiles in (the contact solve
    # in the simulation loop) must come with an edit of the kernel's module,
    # or numba would go on running the old machine code
    import re

    modules = _cached_kernel_modules()
    assert {"refsim.dynamics._numba_kernels", "refsim.collision._numba_kernels",
            "refsim.collision._numba_exact", "refsim.bounds._numba_kernels"} <= set(modules)
    stale = []
    for name, text in modules.items():
        expected = kernels.sources_digest(name)
        written = re.findall(r'^SOURCES_DIGEST = "([0-9a-f]*)"$', text, flags=re.M)
        if expected and written != [expected]:
            stale.append(f'{name}: SOURCES_DIGEST = "{expected}" (written: {written})')
        if not expected:
            assert not written, name                       # imports no refsim module
    assert not stale, "\n".join(stale)


def test_the_digest_covers_what_the_loop_compiles_in_and_changes_with_it(monkeypatch,
                                                                         tmp_path):
    loop = "refsim.dynamics._numba_kernels"
    names = kernels.imported_sources(loop)
    assert {"refsim.dynamics.impulse", "refsim.bounds._numba_kernels",
            "refsim.dynamics.rotation_impulse"} <= set(names)
    assert "refsim.models.ear_index" in kernels.imported_sources("refsim.models._numba_kernels")
    assert kernels.imported_sources("refsim.bounds._numba_kernels") == []
    before = kernels.sources_digest(loop)
    source = kernels._source_file("refsim.dynamics.impulse")
    edited = tmp_path / "impulse.py"
    edited.write_text(source.read_text(encoding="utf-8").replace("ITERATIONS = 32",
                                                                  "ITERATIONS = 33"))
    real = kernels._source_file
    monkeypatch.setattr(kernels, "_source_file",
                        lambda m: edited if m == "refsim.dynamics.impulse" else real(m))
    assert kernels.sources_digest(loop) != before


COMPILED_HERE_CHILD = """
import sys
sys.path.insert(0, sys.argv[1])
import numba
from refsim.kernels import compiled_here
import tiny
if sys.argv[2] == "call":
    tiny.twice(1.5)
print(compiled_here(tiny.twice))
"""


def test_compiled_here_reads_numbas_disk_cache(tmp_path):
    """``compiled_here``: False on an empty cache, True in the process that
    compiled and in a later one reading the same cache, False on another."""
    (tmp_path / "tiny.py").write_text("import numba\n\n\n@numba.njit(cache=True)\n"
                                      "def twice(x):\n    return 2.0 * x\n")

    def child(cache: str, action: str) -> str:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / cache))
        env.pop("NUMBA_DISABLE_JIT", None)
        done = subprocess.run([sys.executable, "-c", COMPILED_HERE_CHILD, str(tmp_path), action],
                              env=env, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        return done.stdout.strip()

    assert child("a", "look") == "False"
    assert child("a", "call") == "True"
    assert child("a", "look") == "True"
    assert child("b", "look") == "False"


def test_compiled_here_without_the_jit_is_true():
    # NUMBA_DISABLE_JIT=1: njit gives the plain function, which compiles nothing
    def plain(x):
        return x

    assert compiled_here(plain)
