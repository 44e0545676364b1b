"""The one switch between refsim's readable kernels and their compiled twins.

Every algorithm is written once as a plain, readable kernel. Where the
interpreter's overhead dominates (tree traversals, hill climbing, per-contact
loops, many small steps), numba compiles a twin that does the same arithmetic
in the same order, so the two agree bit for bit (docs/design.md, Speed). Each
public function that has both takes ``kernel=`` with one vocabulary:

- ``"readable"``: the plain kernel, always available;
- ``"compiled"``: the numba twin (numba is a core dependency);
- ``None`` (default): ``"compiled"`` when numba works here, else
  ``"readable"`` with one :class:`KernelWarning` per process saying so.

The environment variable ``REFSIM_KERNELS`` (``readable`` or ``compiled``)
changes the default for a whole run, e.g. to time or debug the readable path
under the command line; an explicit ``kernel=`` wins over it.

Three families whose first compile takes seconds to tens of seconds (the
exact collision query, the simulation loop, the fused particle step) start
tiered (:class:`Tier`): while numba's cache does not hold them, a default
call runs readable until the process has spent about one compile's time
that way, so that a short script does not wait for a compile.
``REFSIM_TIERED_START=0`` turns that off.

Each pair is a :class:`KernelPair`, defined at the end of this module and
registered in :data:`PAIRS`: the module that runs it dispatches through it
(``LINEAR_BOX_SCAN(kernel)`` is the function to call), and
tests/test_kernels.py walks the registry, checks each pair bit for bit on
its own cases and checks that those cases run through the pair. A
compiled twin is the readable function itself compiled
(:func:`compile_kernel`) wherever numba takes the readable source; the rest
are written as plain loops in a module of compiled kernels, and each such
function's docstring names the readable one it mirrors ("Mirrors: ...").

numba caches machine code on disk only for functions defined at module level
(``cache=True`` keys a function by its source and globals), so every
compiled kernel is a module-level function, compiled on first use.

numba's cache of a module is kept while that module's file keeps its time
and size, whatever happened to the modules it compiles code or constants in
from (the simulation loop compiles in the contact solve of
``refsim/dynamics/impulse.py``): after an edit there, the old machine code
would run. So each module of cached kernels that imports other refsim
modules holds ``SOURCES_DIGEST``, :func:`sources_digest` of them;
tests/test_kernels.py checks it, and the edit that updates it is an edit of
the kernel module itself, which renews its cache.
"""

from __future__ import annotations

import ast
import contextlib
import functools
import hashlib
import importlib
import os
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from refsim.errors import OptionError, check_option

KERNELS = ("readable", "compiled")

#: The environment variable that sets the default kernel for a run.
KERNELS_ENV = "REFSIM_KERNELS"


class KernelWarning(UserWarning):
    """numba does not work here: refsim runs its readable kernels."""


@functools.cache
def numba_error() -> str | None:
    """Why numba cannot be used here (one line), or None when it can.

    Tried once per process: a numba that is installed but built against
    another numpy fails at import, and counts as missing.
    """
    try:
        import numba  # noqa: F401
    except Exception as exc:  # ImportError, or a binary mismatch
        return f"{type(exc).__name__}: {exc}".splitlines()[0]
    return None


def numba_usable() -> bool:
    return numba_error() is None


def choose_kernel(kernel: str | None) -> str:
    """The kernel to run: ``kernel`` checked, or the default (module docstring).

    Raises
    ------
    OptionError
        An unknown kernel, or ``"compiled"`` where numba does not work.
    """
    if kernel is None:
        kernel = _environment_kernel()
        if kernel is not None:
            check_option(KERNELS_ENV, kernel, KERNELS)
    if kernel is None:
        if numba_usable():
            return "compiled"
        _warn_readable()
        return "readable"
    check_option("kernel", kernel, KERNELS)
    if kernel == "compiled" and not numba_usable():
        raise OptionError(f"kernel 'compiled' needs numba, which does not work here: "
                          f"{numba_error()}")
    return kernel


def _environment_kernel() -> str | None:
    """``REFSIM_KERNELS``'s value, or None when it is unset or empty; read
    at every call (a test or a user may set it mid-run)."""
    return _environment(KERNELS_ENV)


def _environment(name: str) -> str | None:
    """The environment variable ``name``'s value, or None when it is unset
    or empty. Looked up in ``os.environ``'s own mapping where it has one:
    ``os.environ.get`` raises and catches a KeyError inside when the
    variable is unset, which made the lookup a sixth of a small collision
    query (docs/decisions/query-fixed-cost.md)."""
    encodekey = getattr(os.environ, "encodekey", None)
    data = getattr(os.environ, "_data", None)
    if encodekey is None or data is None:                 # not CPython's os._Environ
        return os.environ.get(name) or None
    value = data.get(encodekey(name))
    if value is None:
        return None
    return os.environ.decodevalue(value) or None


@functools.cache
def _warn_readable() -> None:
    warnings.warn(f"numba does not work here ({numba_error()}); refsim runs its readable "
                  "kernels, tens of times slower (pip install numba)", KernelWarning,
                  stacklevel=3)


#: Set to "0" to silence :func:`compile_notices` (the test suite does, so
#: that a command's output does not depend on what numba's cache holds).
COMPILE_NOTICE_ENV = "REFSIM_COMPILE_NOTICE"


def notices_on() -> bool:
    """Whether the command line says what numba compiles (and what it does
    not wait for): not with ``REFSIM_COMPILE_NOTICE=0``,
    ``REFSIM_KERNELS=readable`` or without numba."""
    return (os.environ.get(COMPILE_NOTICE_ENV, "1") != "0"
            and os.environ.get(KERNELS_ENV) != "readable" and numba_usable())


@contextlib.contextmanager
def compile_notices(stream):
    """Within the body, the first time numba compiles a kernel (its disk
    cache empty or stale: a fresh install, an edited kernel) one line on
    ``stream`` says so before the wait; at the end, if anything compiled,
    one line says how many kernels took how long. Loads from numba's cache
    say nothing (numba emits its "numba:compile" event only for a compile).
    Nothing when numba is missing, ``REFSIM_COMPILE_NOTICE=0`` or
    ``REFSIM_KERNELS=readable`` (numba is then not even imported)."""
    if not notices_on():
        yield
        return
    from numba.core import event

    class Notice(event.Listener):
        """Counts top-level compiles (a kernel's callees compile inside it)."""

        def __init__(self):
            self.depth, self.count, self.seconds, self.began = 0, 0, 0.0, 0.0

        def on_start(self, ev):
            if self.depth == 0:
                if self.count == 0:
                    print("refsim: compiling kernels for this machine (once: numba keeps "
                          "them for later runs)...", file=stream, flush=True)
                self.count += 1
                self.began = time.perf_counter()
            self.depth += 1

        def on_end(self, ev):
            self.depth -= 1
            if self.depth == 0:
                self.seconds += time.perf_counter() - self.began

    notice = Notice()
    with event.install_listener("numba:compile", notice):
        yield
    if notice.count:
        print(f"refsim: compiled {notice.count} kernel{'s' * (notice.count > 1)} in "
              f"{notice.seconds:.1f} s", file=stream, flush=True)


def compiled_here(dispatcher) -> bool:
    """Whether numba holds machine code of ``dispatcher`` (a numba function)
    for this processor: compiled in this process, or in its disk cache and
    fresh for the source. Reads numba's cache index, whose layout is
    numba's own: when it cannot be read, False (a compile may follow).

    By processor, not by signature: a scene whose arguments numba types
    otherwise than the cached ones' would still compile (the simulation
    loop is called with one signature for every scene). A plain function
    (``NUMBA_DISABLE_JIT=1``) has nothing to compile: True."""
    signatures = getattr(dispatcher, "signatures", None)
    if signatures is None or signatures:
        return True
    try:
        index = dispatcher._cache._cache_file._load_index()
        machine = dispatcher.targetctx.codegen().magic_tuple()
    except Exception:    # no disk cache, or another numba's layout
        return False
    return any(key[1] == machine for key in index)


#: Set to "0" to turn the tiered start off (:class:`Tier`): a default call
#: then takes the compiled kernels at once, compiling them if numba's cache
#: does not hold them. The test suite does, so that the kernel a test runs
#: does not depend on what numba's cache holds.
TIERED_ENV = "REFSIM_TIERED_START"


class Tier:
    """A family of compiled kernels that a process can start without.

    numba compiles a family on its first call on a machine (seconds to
    tens of seconds: docs/decisions/cold-start.md) and keeps the machine
    code on disk for later processes. Until then a call
    with the default kernel (``kernel=None``) runs the readable kernels,
    which give the same answers bit for bit, as long as their time summed
    over the process stays under the family's compile time
    (``compile_seconds``); after that it compiles. This is the break-even
    rule of the ski-rental problem (Karlin, Manasse, Rudolph and Sleator,
    "Competitive snoopy caching", Algorithmica 3, 1988): whatever the
    calls still to come, the process never spends more than twice the time
    of the better of "compile at once" and "never compile", known in
    hindsight. A short script gets its answers without waiting for a
    compile; a long loop of calls pays at most one compile's worth of
    readable time before it runs compiled.

    The family counts as compiled when numba holds every kernel in
    ``dispatchers`` (dotted ``"module:function"`` names) for this processor,
    in memory or in its disk cache (:func:`compiled_here`). An explicit
    ``kernel=``, ``REFSIM_KERNELS``, a missing numba and
    ``REFSIM_TIERED_START=0`` (read until the tier settles) all bypass the
    tier; code that times refsim's
    calls should use one of them (``refsim report``, ``study`` and ``advise``
    set the variable), or it times readable calls on a cold cache. Its state is
    the process's: ``spent`` (readable seconds charged) and ``settled``
    (compiled from now on).
    """

    def __init__(self, name: str, dispatchers: tuple[str, ...], compile_seconds: float):
        self.name = name
        self.dispatchers = dispatchers
        self.compile_seconds = compile_seconds
        self.spent = 0.0
        self.settled = False

    def readable_first(self) -> bool:
        """Whether a default call should run the readable kernels now (and be
        charged: :meth:`charged`). Once it answers False for a compiled
        family, a spent budget, ``REFSIM_TIERED_START=0`` or a missing numba,
        the tier has settled and answers False at once from then on; for
        ``REFSIM_KERNELS`` it answers False call by call."""
        if self.settled:
            return False
        if (_environment(TIERED_ENV) == "0" or not numba_usable()
                or self.spent >= self.compile_seconds or self.cached()):
            # settled: from now on one attribute answers, not the environment
            # (a compiled query takes a few microseconds)
            self.settled = True
            return False
        return _environment_kernel() is None      # REFSIM_KERNELS chooses, call by call

    def cached(self) -> bool:
        """Whether numba holds every kernel of the family for this processor,
        in memory or in its disk cache, whatever the tier's settings."""
        return all(compiled_here(resolve(name)) for name in self.dispatchers)

    def remaining(self) -> float:
        """The readable seconds left before the family compiles."""
        return max(self.compile_seconds - self.spent, 0.0)

    def settle(self) -> None:
        """Compiled from now on (a caller that knows a long run comes)."""
        self.settled = True

    @contextlib.contextmanager
    def charged(self):
        """Adds the body's CPU time (this process's, ``time.process_time``)
        to the readable seconds spent: on a loaded machine the readable calls
        and the compile slow down alike, so the break-even point does not
        move with the load."""
        began = time.process_time()
        try:
            yield
        finally:
            self.spent += time.process_time() - began


@functools.cache
def compile_kernel(function):
    """``numba.njit(cache=True)(function)``: the readable kernel compiled as it
    stands (it must be a module-level function of plain loops over arrays).
    Compiled once per process, on first call; numba's disk cache then spares
    the next process the compile."""
    import numba

    return numba.njit(cache=True)(function)


def python_floats(args: tuple) -> tuple:
    """A readable kernel's arguments as the interpreter computes with them
    fastest: each float64 array as a ``memoryview`` of it (an item read is
    a Python float, an item written is stored in the array), each numpy
    float64 as a Python float; the rest as they are.

    A kernel of scalar arithmetic written for numba (items read one at a
    time, as ``R[i, j]``) then gives the same bits as on the arrays: a
    Python float is the IEEE double a numpy float64 is, and ``+ - * /``,
    comparisons and ``math``'s functions round alike; and it runs faster,
    as no item read makes a numpy scalar object. Items of arrays the
    kernel makes itself stay numpy scalars, and a division by zero among
    them gives numpy's infinity as before; one between two Python floats
    raises ZeroDivisionError, as the compiled twin does (numba's default
    error model).
    A ``memoryview`` of a two-dimensional array cannot be sliced: a kernel
    that slices its arrays is passed them as they are.
    """
    import numpy as np

    return tuple(a.data if isinstance(a, np.ndarray) and a.dtype == np.float64
                 else float(a) if isinstance(a, np.float64) else a for a in args)


def _source_file(module: str) -> Path | None:
    """The source file of a refsim module (``refsim.a.b``), or None."""
    base = Path(__file__).parent.joinpath(*module.split(".")[1:])
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _imported_modules(module: str) -> set[str]:
    """The refsim modules ``module`` imports when it is imported (its
    top-level imports, also inside ``try``; not those under ``if``, such as
    ``TYPE_CHECKING``, nor those inside functions)."""
    path = _source_file(module)
    if path is None:
        return set()
    found: set[str] = set()
    for statement in ast.parse(path.read_text(encoding="utf-8")).body:
        nodes = ast.walk(statement) if isinstance(statement, ast.Try) else [statement]
        for node in nodes:
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names if a.name.split(".")[0] == "refsim"}
            elif (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                  and node.module.split(".")[0] == "refsim"):
                found.add(node.module)
                # ``from refsim.models import ear_index``: a module too
                found |= {f"{node.module}.{a.name}" for a in node.names
                          if _source_file(f"{node.module}.{a.name}") is not None}
    return found


def imported_sources(module: str) -> list[str]:
    """Every refsim module that ``module`` (dotted name) imports, directly or
    through them (as :func:`_imported_modules` reads imports), sorted."""
    seen: set[str] = set()
    todo = [module]
    while todo:
        for name in _imported_modules(todo.pop()):
            if name not in seen and name != module:
                seen.add(name)
                todo.append(name)
    return sorted(seen)


def sources_digest(module: str) -> str:
    """SHA-256 (first 16 hex digits) of the source text of every module of
    :func:`imported_sources`, in name order, without their own
    ``SOURCES_DIGEST`` lines (so that an edit asks for new digests in one
    round, not one per level of imports); ``""`` when there is none.
    Newlines are read as ``\n``, so a checkout with other line endings gives
    the same digest."""
    names = imported_sources(module)
    if not names:
        return ""
    digest = hashlib.sha256()
    for name in names:
        path = _source_file(name)
        digest.update(name.encode())
        text = path.read_text(encoding="utf-8") if path else ""
        lines = [line for line in text.split("\n") if not line.startswith("SOURCES_DIGEST = ")]
        digest.update(b"\0" + "\n".join(lines).encode())
    return digest.hexdigest()[:16]


def resolve(dotted: str):
    """The object ``"package.module:name"`` names (``name`` may be dotted,
    ``Class.method``)."""
    module, name = dotted.split(":")
    found = importlib.import_module(module)
    for part in name.split("."):
        found = getattr(found, part)
    return found


COMPILED_FROM_SOURCE = "compiled from the readable source"
MIRRORS = "mirrors the readable kernel"

#: Every kernel pair by name (:class:`KernelPair` registers itself here).
#: tests/test_kernels.py walks it: it runs each pair on its cases through the
#: public path with ``kernel="readable"`` and ``"compiled"`` and checks the
#: answers bit for bit, checks that each pair dispatches to its two
#: functions, and that each mirror's docstring names the readable function
#: it mirrors.
PAIRS: dict[str, KernelPair] = {}


class KernelPair:
    """A readable kernel and its compiled twin: registered by name in
    :data:`PAIRS` (the parity tests walk it), and the one place that
    chooses between them.

    ``readable`` and ``compiled`` are the two functions a call dispatches
    to, with one signature, named ``"package.module:name"`` and imported on
    first use (so that importing refsim imports no numba kernel module, and
    this module, below every algorithm, names them without importing them).
    ``how``: :data:`COMPILED_FROM_SOURCE` (numba compiles the readable
    source) or :data:`MIRRORS` (a twin written as plain loops, whose
    docstring says "Mirrors" and names the readable function). ``mirror``:
    the ``(readable, compiled)`` functions whose docstrings tell that, or
    whose source numba compiles, where the dispatched two are thin callers
    of them (default: the dispatched two); a readable caller that passes
    Python floats (:func:`python_floats`) is one.

    :meth:`choose` (also the pair called: ``pair(kernel)``) takes the
    ``kernel=`` a user passes (None: the default of :func:`choose_kernel`,
    with ``REFSIM_KERNELS``); :meth:`pick` takes a kernel already chosen
    (a composition root, such as the simulation loop or a tracker, chooses
    once and passes the choice down) and costs one comparison.
    """

    def __init__(self, name: str, readable: str, compiled: str, how: str = MIRRORS, *,
                 mirror: tuple[str, str] | None = None):
        if name in PAIRS:
            raise ValueError(f"a kernel pair named {name!r} exists already")
        self.name = name
        self.readable_path, self.compiled_path, self.how = readable, compiled, how
        self.mirror = mirror or (readable, compiled)
        self._readable: Callable | None = None
        self._compiled: Callable | None = None
        PAIRS[name] = self

    def __repr__(self) -> str:
        return f"KernelPair({self.name!r}, {self.readable_path!r}, {self.compiled_path!r})"

    @property
    def readable(self) -> Callable:
        """The readable function (imported on first use)."""
        if self._readable is None:
            self._readable = resolve(self.readable_path)
        return self._readable

    @property
    def compiled(self) -> Callable:
        """The compiled twin (imported on first use: numba loads then)."""
        if self._compiled is None:
            self._compiled = resolve(self.compiled_path)
        return self._compiled

    def pick(self, chosen: str) -> Callable:
        """The function for a kernel already chosen by :func:`choose_kernel`
        (``"readable"`` or ``"compiled"``; not checked again)."""
        if chosen == "compiled":
            found = self._compiled
            return found if found is not None else self.compiled
        found = self._readable
        return found if found is not None else self.readable

    def choose(self, kernel: str | None) -> Callable:
        """The function for ``kernel=`` as a user passes it (None: the
        default); an unknown kernel, or "compiled" without numba, raises
        OptionError (:func:`choose_kernel`)."""
        return self.pick(choose_kernel(kernel))

    __call__ = choose


# The pairs, by area. A module that dispatches takes its pair from here.

BROAD_PHASE_SWEEP = KernelPair(
    "broad-phase sweep", "refsim.collision.broad_phase:overlapping_pairs_sweep",
    "refsim.collision.broad_phase:overlapping_pairs_sweep_compiled", COMPILED_FROM_SOURCE)
HIERARCHY_BUILD = KernelPair(
    "hierarchy build", "refsim.collision.bvh:build_tree_by_name",
    "refsim.collision.bvh:build_tree_compiled",
    mirror=("refsim.collision.bvh:build_tree", "refsim.collision._numba_build:build_tree"))
ORIENTED_NODE_BOXES = KernelPair(
    "oriented node boxes", "refsim.collision.bvh_exact:build_frame_tree",
    "refsim.collision.bvh_exact:build_frame_tree_compiled",
    mirror=("refsim.collision.bvh_exact:build_frame_tree",
            "refsim.collision._numba_build:frame_boxes"))
HIERARCHY_REFIT = KernelPair(
    "hierarchy refit", "refsim.collision.bvh:prepare", "refsim.collision._numba_kernels:prepare",
    mirror=("refsim.collision.bvh:refit", "refsim.collision._numba_kernels:prepare"))
HIERARCHY_TRAVERSAL = KernelPair(
    "hierarchy traversal", "refsim.collision.bvh:traverse",
    "refsim.collision._numba_kernels:traverse",
    mirror=("refsim.collision.bvh:_pairs_python", "refsim.collision._numba_kernels:traverse"))
CERTIFIED_FILTER = KernelPair(
    "certified triangle filter", "refsim.collision.seed_levels:intersecting_batch",
    "refsim.collision.seed_levels:intersecting_compiled",
    mirror=("refsim.collision.triangle_batch:triangles_intersect_batch",
            "refsim.collision._numba_kernels:certified"))
EXACT_HIERARCHY_QUERY = KernelPair(
    "exact hierarchy query", "refsim.collision.bvh_exact:pairs_readable",
    "refsim.collision.bvh_exact:pairs_compiled",
    mirror=("refsim.collision.bvh_exact:descend", "refsim.collision._numba_kernels:exact_query"))
EXACT_HIERARCHY_COLLIDE = KernelPair(
    "exact hierarchy collide", "refsim.collision.bvh_exact:collide_readable",
    "refsim.collision.bvh_exact:collide_compiled",
    mirror=("refsim.collision.bvh_exact:descend",
            "refsim.collision._numba_kernels:exact_collide"))
EXACT_TRIANGLE_STAGE = KernelPair(
    "exact triangle stage", "refsim.collision.triangle:_triangle_vs_triangle",
    "refsim.collision._numba_exact:triangle_vs_triangle")
LINEAR_BOX_SCAN = KernelPair(
    "linear box scan", "refsim.bounds.aabb_linear:aabb_linear_kernel",
    "refsim.bounds._numba_kernels:aabb_linear_numba")
INCREMENTAL_BOX = KernelPair(
    "incremental box", "refsim.bounds.aabb_incremental:IncrementalAABB._update_python",
    "refsim.bounds.aabb_incremental:IncrementalAABB._update_numba",
    mirror=("refsim.bounds.aabb_incremental:IncrementalAABB",
            "refsim.bounds._numba_kernels:incremental_update_numba"))
CORNER_TREE = KernelPair(
    "indexed corner tree", "refsim.models.ear_index:build_tree",
    "refsim.models._numba_kernels:build_tree", COMPILED_FROM_SOURCE)
EAR_CLIPPING = KernelPair(
    "indexed ear clipping", "refsim.models.ear_index:clip_ears",
    "refsim.models._numba_kernels:clip_ears", COMPILED_FROM_SOURCE)
PARTICLE_STEPS = KernelPair(
    "fused particle steps", "refsim.particles.system:ParticleSystem._advance_readable",
    "refsim.particles.system:ParticleSystem._advance_fused",
    mirror=("refsim.particles.system:ParticleSystem",
            "refsim.particles._numba_kernels:rk_steps_fused"))
CONTACT_IMPULSES = KernelPair(
    "contact impulses", "refsim.dynamics.impulse:solve_contacts_readable",
    "refsim.dynamics.impulse:solve_contacts_compiled", COMPILED_FROM_SOURCE,
    mirror=("refsim.dynamics.impulse:solve_contacts_python",
            "refsim.dynamics.impulse:solve_contacts_compiled"))
ISLAND_IMPULSES = KernelPair(
    "island contact impulses", "refsim.dynamics.impulse:solve_island_python",
    "refsim.dynamics.impulse:solve_island_compiled", COMPILED_FROM_SOURCE)
FREE_ROTATION_STEPS = KernelPair(
    "free rotation steps", "refsim.dynamics.rotation_impulse:free_rotation_steps_readable",
    "refsim.dynamics.rotation_impulse:free_rotation_steps_compiled", COMPILED_FROM_SOURCE,
    mirror=("refsim.dynamics.rotation_impulse:free_rotation_steps",
            "refsim.dynamics.rotation_impulse:free_rotation_steps_compiled"))
SEED_ORIENTATION_STEP = KernelPair(
    "seed orientation step", "refsim.dynamics.rotation_seed:orientation_step_seed",
    "refsim.dynamics.rotation_seed:orientation_step_seed_compiled")
BATCHED_BOXES = KernelPair(
    "batched boxes", "refsim.dynamics.boxes:boxes_numpy", "refsim.dynamics.boxes:boxes_compiled")
CONTACT_GEOMETRY = KernelPair(
    "contact geometry", "refsim.dynamics.body_response:contact_geometry_readable",
    "refsim.dynamics.body_response:contact_geometry_compiled",
    mirror=("refsim.dynamics.body_response:contact_geometry",
            "refsim.dynamics._numba_contact:contact_geometry_numba"))
CONTACT_REGION = KernelPair(
    "contact region", "refsim.collision.contact:contact_region_readable",
    "refsim.collision.contact:contact_region_compiled",
    mirror=("refsim.collision.contact:contact_points",
            "refsim.collision._numba_contact:contact_region_numba"))
SIMULATION_LOOP = KernelPair(
    "simulation loop", "refsim.dynamics.simulation:Simulation",
    "refsim.dynamics._numba_kernels:advance")
