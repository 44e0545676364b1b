"""Fuzz cases: a ``refsim`` command line, its input files, and what a refusal must name.

A :class:`Case` is plain data. Paths in it hold the placeholders ``{in}``
(the directory of the input files) and ``{out}`` (the working directory, where
the output goes); :mod:`tests.fuzz.execute` fills them in.

Families:

==============  ==============================================================
model           ``refsim info MODEL`` on a mutant of a bundled model or of a
                trimesh export (OBJ, STL, PLY, OFF)
scene           ``refsim run SCENE -o out.npz --duration 0.02`` on a mutant
                of a bundled scene
scene+model     a bundled scene whose bodies use a mutant model
special         special files as the model or the scene: a directory, a FIFO,
                /dev/null, /dev/zero, a symlink loop, an unreadable file, an
                empty file, odd names
output          ``-o`` onto a symlink, a device node, a FIFO, a directory, a
                read-only directory
signal          SIGTERM, SIGHUP, SIGINT while the output's temporary file exists
args            hostile command-line arguments
known           the findings of the earlier manual campaign, one case each
==============  ==============================================================

The first three are random: :func:`make_case` builds case ``index`` of a
mutator from ``random.Random("family/mutator/seed/index")``, so a case id
(``scene:set_key:1:42``) rebuilds the same case anywhere
(:func:`case_from_id`). The others are fixed lists.
"""

from __future__ import annotations

import random
import signal
from collections.abc import Iterator
from dataclasses import dataclass, replace

from tests.fuzz import corpus, mutate
from tests.fuzz.runner import CPU_LIMIT

RANDOM_FAMILIES = ("model", "scene", "scene+model")
FIXED_FAMILIES = ("special", "output", "signal", "args", "known")

#: The override that keeps every scene run short (``refsim run --duration``);
#: the scene's own duration is still validated when it loads.
RUN_ARGS = ("-o", "out.npz", "--duration", "0.02")

#: Scenes that reference a mutant model (scene+model), with their bodies: every
#: body of these scenes gets the mutant except in mixed.toml, where one does.
MODEL_HOSTS = ("bounce.toml", "head-on.toml", "spinning-cube.toml", "mixed.toml")

#: Seconds a long polygon may take (the ear clipper must be fast: a 20 000
#: corner polygon is a fraction of a second of work for an O(n log n) or a
#: well-pruned O(n^2) clipper); past this much CPU time the case counts as
#: over its CPU limit.
FAST = 5.0

#: Model refusals that concern the whole file and so name no line.
WHOLE_FILE_MODEL = (r"no such file", r"cannot read the file", r"unknown model format",
                    r"has no polygon surfaces", r"trimesh cannot read it",
                    r"holds no triangles")


@dataclass(frozen=True)
class Special:
    """A file system node created before the run.

    kind: "dir", "fifo", "symlink" (to ``target``), "device" (a character
    device with the numbers of /dev/null), "unreadable" (``content``, mode
    000), "readonly-dir" (mode 555), "locked-dir" (holding ``target``, a
    file of ``content``, then mode 000: not searchable), "file" (``content``).
    """

    kind: str
    path: str
    target: str = ""
    content: bytes = b""


@dataclass(frozen=True)
class Case:
    """One command line and the facts the judge needs (see the module docstring).

    names: (path, what) pairs; a refusal must name one of the paths with
    ``what``: "line" (``path:LINE:``), "key" (``path: key.path:`` or a
    TOML line), "file" (``path:``), or "model" (a model inside a scene:
    ``path:LINE:`` or a whole-file model message other than an unknown
    format). No pairs: the message must only be one ``refsim: error:`` line.
    forbid: regexes a refusal must not match (a wrong reason).
    watch: output nodes that existed before the run and must not be replaced.
    output: the file the command writes when it succeeds (or diverges).
    facts: ``refsim info`` lines an accepted model must print.
    must_refuse: accepting the input is a failure.
    unprivileged: run without root's file-permission override (a permission
    case: root reads every file otherwise).
    cpu_limit: the seconds of CPU time the command may use (its wall-clock
    backstop is :data:`tests.fuzz.runner.WALL_FACTOR` times that).
    """

    id: str
    family: str
    mutator: str
    subject: str
    argv: tuple[str, ...]
    files: tuple[tuple[str, bytes], ...] = ()
    specials: tuple[Special, ...] = ()
    names: tuple[tuple[str, str], ...] = ()
    forbid: tuple[str, ...] = ()
    watch: tuple[str, ...] = ()
    output: str | None = None
    facts: tuple[tuple[str, str], ...] = ()
    must_refuse: bool = False
    unprivileged: bool = False
    interrupt: tuple[int, str, float] | None = None
    cpu_limit: float = CPU_LIMIT


# -- the random families ----------------------------------------------------------------

MODEL_FORMATS = ("ac", "obj", "stl-ascii", "stl-binary", "ply-ascii", "ply-binary", "off")


def family_mutators(family: str) -> list[str]:
    """The mutators of a random family, in a fixed order."""
    formats = ("toml",) if family == "scene" else MODEL_FORMATS
    return [name for name, m in mutate.MUTATORS.items() if m.formats & set(formats)]


def _mutant(name: str, data: bytes, fmt: str, rng: random.Random) -> bytes:
    """A mutant that differs from ``data`` (a mutator can draw a no-op, such
    as a count replaced by its own value: then it draws again, up to 8 times)."""
    out = data
    for _ in range(8):
        out = mutate.mutate(name, data, fmt, rng.random())
        if out != data:
            break
    return out


def _model_subject(mutator: str, rng: random.Random) -> tuple[str, str, bytes]:
    """(format, subject name, bytes) of a model the mutator applies to."""
    formats = [f for f in MODEL_FORMATS if f in mutate.MUTATORS[mutator].formats]
    fmt = rng.choice(formats)
    if fmt == "ac":
        name = rng.choice(sorted(corpus.models()))
        return fmt, name, corpus.models()[name]
    return fmt, f"{corpus.EXPORTED_MODEL}:{fmt}", corpus.exports()[fmt]


def _model_mutant(mutator: str, rng: random.Random):
    """(format, subject, mutant bytes, info facts it must keep)."""
    fmt, subject, data = _model_subject(mutator, rng)
    facts = ()
    if mutator == "scale_vertices":
        # Drawn here rather than inside the mutator so that the judge knows
        # when the scale keeps the shape: convex and closed must not change.
        factor = rng.choice(mutate.SCALE_FACTORS)
        mutant = mutate.scale_by(data, fmt, factor)
        if factor in mutate.SHAPE_KEEPING_FACTORS:
            base = subject if fmt == "ac" else corpus.EXPORTED_MODEL
            facts = tuple(sorted((key, value) for key, value in corpus.model_facts(base).items()
                                 if factor > 0 or key != "convex"))
    else:
        mutant = _mutant(mutator, data, fmt, rng)
    return fmt, subject, mutant, facts


def _model_names(path: str, fmt: str, within_scene: bool) -> tuple[str, str]:
    if within_scene:
        return (path, "model") if fmt == "ac" else (path, "model-file")
    return (path, "line") if fmt == "ac" else (path, "file")


def make_case(family: str, mutator: str, seed, index: int) -> Case:
    """Case ``index`` of ``mutator`` in a random family (module docstring)."""
    case_id = f"{family}:{mutator}:{seed}:{index}"
    rng = random.Random(f"{family}/{mutator}/{seed}/{index}")
    if family == "model":
        fmt, subject, data, facts = _model_mutant(mutator, rng)
        path = "{in}/m" + corpus.FORMAT_SUFFIX[fmt]
        return Case(case_id, family, mutator, subject, ("info", path),
                    files=((path, data),), names=(_model_names(path, fmt, False),),
                    facts=facts, cpu_limit=FAST if mutator == "long_polygon" else CPU_LIMIT)
    if family == "scene":
        subject = rng.choice(sorted(corpus.scenes()))
        path = "{in}/" + subject
        data = _mutant(mutator, corpus.scenes()[subject], "toml", rng)
        return Case(case_id, family, mutator, subject, ("run", path, *RUN_ARGS),
                    files=((path, data),), names=((path, "key"),), output="{out}/out.npz")
    if family == "scene+model":
        host = rng.choice(MODEL_HOSTS)
        fmt, subject, data, _ = _model_mutant(mutator, rng)
        model = "mutant" + corpus.FORMAT_SUFFIX[fmt]
        scene = _reference(corpus.scenes()[host], model, rng)
        scene_path, model_path = "{in}/scene.toml", "{in}/" + model
        return Case(case_id, family, mutator, f"{host} with {subject}",
                    ("run", scene_path, *RUN_ARGS),
                    files=((scene_path, scene), (model_path, data)),
                    names=((scene_path, "key"), _model_names(model_path, fmt, True)),
                    output="{out}/out.npz",
                    cpu_limit=2 * FAST if mutator == "long_polygon" else CPU_LIMIT)
    raise ValueError(f"not a random family: {family!r}")


def _reference(scene: bytes, model: str, rng: random.Random) -> bytes:
    """The scene with its bodies' models replaced by ``model`` (one body of
    several different models, every body of a scene with one model)."""
    lines = scene.decode().split("\n")
    refs = [i for i, line in enumerate(lines) if line.startswith("model =")]
    distinct = {lines[i] for i in refs}
    chosen = refs if len(distinct) == 1 else [rng.choice(refs)]
    for i in chosen:
        lines[i] = f'model = "{model}"'
    return "\n".join(lines).encode()


def schedule(seed) -> Iterator[tuple[str, str]]:
    """(family, mutator) of each random case, forever: every mutator of every
    random family once per round, in an order shuffled per round by ``seed``."""
    pairs = [(family, m) for family in RANDOM_FAMILIES for m in family_mutators(family)]
    round_ = 0
    while True:
        order = list(pairs)
        random.Random(f"schedule/{seed}/{round_}").shuffle(order)
        yield from order
        round_ += 1


# -- the fixed families -------------------------------------------------------------------

def _cube() -> bytes:
    return corpus.models()["cube.ac"]


def _bounce() -> bytes:
    return corpus.scenes()["bounce.toml"]


def _fixed(family: str, name: str, **fields) -> Case:
    return Case(id=f"{family}:{name}", family=family, mutator=name,
                subject=fields.pop("subject", name), **fields)


def special_cases() -> list[Case]:
    """Special files given as the model or the scene (module docstring)."""
    not_missing = (r"no such file", r"not found")
    scene_with = lambda model: _bounce().replace(b'"sphere-2k.ac"', f'"{model}"'.encode())  # noqa: E731
    cases = []

    def model(name, path, *, specials=(), files=(), forbid=not_missing, unprivileged=False,
              names=None, must_refuse=True, cpu_limit=CPU_LIMIT):
        cases.append(_fixed("special", "model-" + name, argv=("info", path),
                            specials=specials, files=files, forbid=forbid,
                            unprivileged=unprivileged,
                            names=((path, "file"),) if names is None else names,
                            must_refuse=must_refuse, cpu_limit=cpu_limit))

    def scene(name, path, *, specials=(), files=(), forbid=not_missing, unprivileged=False,
              names=None, must_refuse=True, cpu_limit=CPU_LIMIT):
        cases.append(_fixed("special", "scene-" + name, argv=("run", path, *RUN_ARGS),
                            specials=specials, files=files, forbid=forbid,
                            unprivileged=unprivileged,
                            names=((path, "file"),) if names is None else names,
                            output="{out}/out.npz", must_refuse=must_refuse,
                            cpu_limit=cpu_limit))

    for role, add, suffix in (("model", model, ".ac"), ("scene", scene, ".toml")):
        p = "{in}/x" + suffix
        add("directory", p, specials=(Special("dir", p),))
        add("fifo", p, specials=(Special("fifo", p),), cpu_limit=10.0)
        add("dev-null-link", p, specials=(Special("symlink", p, "/dev/null"),))
        add("dev-zero-link", p, specials=(Special("symlink", p, "/dev/zero"),), cpu_limit=20.0)
        add("symlink-loop", p, specials=(Special("symlink", p, p),))
        add("dangling-symlink", p, specials=(Special("symlink", p, "{in}/gone" + suffix),),
            forbid=())
        add("unreadable", p, unprivileged=True,
            specials=(Special("unreadable", p, content=_cube() if role == "model"
                              else _bounce()),))
        add("missing-directory", "{in}/no/x" + suffix, forbid=())
        add("in-locked-directory", "{in}/locked/x" + suffix, unprivileged=True, forbid=(),
            specials=(Special("locked-dir", "{in}/locked", "x" + suffix,
                              _cube() if role == "model" else _bounce()),))
        add("name-too-long", "{in}/" + "x" * 300 + suffix, forbid=())
        newline = "{in}/new\nline" + suffix
        add("newline-in-name", newline, files=((newline, b"junk\n"),), forbid=(),
            names=((newline, "file"),))
        odd = "{in}/\udcff" + suffix                    # the byte 0xff, not UTF-8
        add("non-utf8-name", odd, files=((odd, b"junk\n"),), forbid=(),
            names=((odd, "file"),))
    model("empty-ac", "{in}/e.ac", files=(("{in}/e.ac", b""),), forbid=())
    for suffix in (".obj", ".stl", ".ply", ".off"):
        model("empty" + suffix, "{in}/e" + suffix, files=(("{in}/e" + suffix, b""),),
              forbid=())
    model("dev-null", "/dev/null", forbid=())
    model("obj-latin1-comment", "{in}/l.obj", forbid=(r"No module named",),
          files=(("{in}/l.obj", b"# caf\xe9\n" + corpus.exports()["obj"]),),
          must_refuse=False)
    model("polygon-20000-star", "{in}/p.ac", must_refuse=False, forbid=(),
          files=(("{in}/p.ac", corpus.long_polygon_ac3d(20_000, star=True)),),
          names=(("{in}/p.ac", "line"),), cpu_limit=FAST)
    model("polygon-4000-star", "{in}/p.ac", must_refuse=False, forbid=(),
          files=(("{in}/p.ac", corpus.long_polygon_ac3d(4000, star=True)),),
          names=(("{in}/p.ac", "line"),), cpu_limit=FAST)
    scene("empty", "{in}/e.toml", files=(("{in}/e.toml", b""),), forbid=(),
          names=(("{in}/e.toml", "key"),))
    scene("dev-null", "/dev/null", forbid=(), names=(("/dev/null", "file"),))
    for name, node in (("fifo", Special("fifo", "{in}/m.ac")),
                       ("directory", Special("dir", "{in}/m.ac")),
                       ("dev-null-link", Special("symlink", "{in}/m.ac", "/dev/null"))):
        scene("model-is-" + name, "{in}/s.toml", specials=(node,),
              files=(("{in}/s.toml", scene_with("m.ac")),), names=(("{in}/s.toml", "key"),))
    scene("model-is-not-a-model", "{in}/s.toml", forbid=(),
          files=(("{in}/s.toml", scene_with("notes.txt")), ("{in}/notes.txt", b"hello\n")),
          names=(("{in}/s.toml", "key"),))
    scene("model-is-the-scene", "{in}/s.toml", forbid=(),
          files=(("{in}/s.toml", scene_with("s.toml")),), names=(("{in}/s.toml", "key"),))
    return cases


def output_cases() -> list[Case]:
    """``-o`` onto nodes that are not a plain new file (module docstring).

    Never ``-o /dev/null`` itself: a writer that replaces its target would
    replace the machine's /dev/null. A device node with the same numbers,
    made in the case's directory, shows the same thing safely.
    """
    scene = "{in}/bounce.toml"
    files = ((scene, _bounce()), ("{in}/target.npz", b"keep me\n"))
    out = "{out}/out.npz"
    cases = []
    for name, special in (
            ("symlink", Special("symlink", out, "{in}/target.npz")),
            ("dangling-symlink", Special("symlink", out, "{in}/nowhere/t.npz")),
            ("device", Special("device", out)),
            ("fifo", Special("fifo", out)),
            ("directory", Special("dir", out))):
        cases.append(_fixed("output", name, argv=("run", scene, *RUN_ARGS), files=files,
                            specials=(special,), watch=(out,), output=out, cpu_limit=20.0,
                            must_refuse=name == "directory"))
    cases.append(_fixed("output", "missing-directory", argv=(
        "run", scene, "-o", "{out}/no/out.npz", "--duration", "0.02"), files=files,
        output="{out}/no/out.npz", must_refuse=True))
    cases.append(_fixed("output", "read-only-directory", argv=(
        "run", scene, "-o", "{out}/ro/out.npz", "--duration", "0.02"), files=files,
        specials=(Special("readonly-dir", "{out}/ro"),), output="{out}/ro/out.npz",
        unprivileged=True, must_refuse=True))
    return cases


#: Seconds between the temporary file's appearance and the signal: well
#: inside the write of the signal scene's frames (about 150 MB, 0.5 s).
INTO_THE_WRITE = 0.03


def signal_cases() -> list[Case]:
    """A signal while the output is being written: no temporary file may stay.

    The particle scene with 30 000 particles writes about 150 MB of frames,
    so its temporary file exists for about half a second. SIGTERM and SIGHUP
    are sent the moment it appears (nothing in the process can clean up
    after them, so the moment does not matter, and sending at once leaves a
    slow poll the least room to miss the write). SIGINT is sent 30 ms later,
    inside the write, where ``write_atomic``'s cleanup runs; for
    ``SIGINT-at-mkstemp`` at once, racing the start of that ``try`` (the
    outcome depends on timing, so that case is in the campaign, not the slice).
    """
    scene = "{in}/particles.toml"
    particles = corpus.scenes()["particles.toml"].replace(b"count = 10000", b"count = 30000")
    files = ((scene, particles),)
    argv = ("run", scene, "-o", "out.npz", "--duration", "0.4")
    cases = [_fixed("signal", signal.Signals(signum).name, files=files, argv=argv,
                    output="{out}/out.npz", cpu_limit=60.0,
                    interrupt=(signum, ".out.npz.*.tmp", delay))
             for signum, delay in ((signal.SIGTERM, 0.0), (signal.SIGHUP, 0.0),
                                   (signal.SIGINT, INTO_THE_WRITE))]
    cases.append(_fixed("signal", "SIGINT-at-mkstemp", files=files, argv=argv,
                        output="{out}/out.npz", cpu_limit=60.0,
                        interrupt=(signal.SIGINT, ".out.npz.*.tmp", 0.0)))
    return cases


def args_cases() -> list[Case]:
    """Hostile command-line arguments around a good scene and a good model."""
    scene = "{in}/bounce.toml"
    files = ((scene, _bounce()), ("{in}/cube.ac", _cube()))
    run = ("run", scene, "-o", "out.npz")
    table = {
        "no-command": (), "unknown-command": ("bogus",), "run-no-scene": ("run",),
        "info-no-model": ("info",), "unknown-option": (*run, "--bogus"),
        "every-zero": (*run, "--every", "0"), "every-negative": (*run, "--every", "-1"),
        "every-fraction": (*run, "--every", "2.5"),
        "every-huge": (*run, "--every", "99999999999999999999", "--duration", "0.02"),
        "duration-nan": (*run, "--duration", "nan"), "duration-inf": (*run, "--duration", "inf"),
        "duration-negative": (*run, "--duration", "-1"), "duration-zero": (*run, "--duration", "0"),
        "duration-tiny": (*run, "--duration", "1e-300"),
        "duration-below-one-step": (*run, "--duration", "0.0004"),
        "duration-huge": (*run, "--duration", "1e300"),
        "duration-hex": (*run, "--duration", "0x10"),
        "output-missing-value": (*run[:2], "-o"),
        "info-second-model-missing": ("info", "{in}/cube.ac", "{in}/missing.ac"),
    }
    refused = set(table) - {"every-huge", "info-second-model-missing"}
    return [_fixed("args", name, argv=argv, files=files, output="{out}/out.npz",
                   must_refuse=name in refused,
                   names=((("{in}/missing.ac", "file"),) if name.startswith("info-second")
                          else ()))
            for name, argv in table.items()]


def _with_body_keys(scene: bytes, *assignments: str) -> bytes:
    """``scene`` with ``assignments`` added to every ``[[body]]`` table."""
    lines = scene.decode().split("\n")
    out = []
    for line in lines:
        out.append(line)
        if line.strip() == "[[body]]":
            out.extend(assignments)
    return "\n".join(out).encode()


def _with_table_key(scene: bytes, table: str, assignment: str) -> bytes:
    """``scene`` with ``assignment`` replacing its key in ``[table]`` (or added)."""
    return mutate._set_scene_key(scene, random.Random(0), table, assignment)


def known_cases() -> list[Case]:
    """The findings of the earlier manual campaign, one deterministic case each,
    so that every campaign confirms or clears each of them (the random
    families find them too, when their draws hit the same values)."""
    bounce, head_on = _bounce(), corpus.scenes()["head-on.toml"]
    sphere = corpus.models()["sphere-2k.ac"]
    scene_path, model_path = "{in}/s.toml", "{in}/m.ac"
    collinear = (b"AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n2 0 0\nnumsurf 1\n"
                 b"SURF 0x0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n")
    point = collinear.replace(b"1 0 0\n2 0 0\nnumsurf", b"0 0 0\n0 0 0\nnumsurf")
    rot_zero = _cube().replace(b'name "cube"', b'name "cube"\nrot 0 0 0 0 0 0 0 0 0')
    rot_huge = sphere.replace(b"OBJECT poly\n", b"OBJECT poly\nrot 1e155 0 0 0 1e155 0 0 0 1e155\n",
                              1)
    scenes = {
        "scene-scale-1e155": _with_body_keys(bounce, "scale = 1e155"),
        "scene-scale-1e154-head-on": _with_body_keys(head_on, "scale = 1e154"),
        "scene-scale-1e62": _with_body_keys(bounce, "scale = 1e62"),
        "scene-scale-1e-65": _with_body_keys(bounce, "scale = 1e-65"),
        "scene-mass-5e-324": _with_body_keys(bounce, "mass = 5e-324"),
        "scene-mass-1e-320": _with_body_keys(corpus.scenes()["mixed.toml"], "mass = 1e-320"),
        "scene-body-outside-cube": _with_body_keys(bounce, "velocity = [0.0, 0.0, 0.0]")
        .replace(b"position = [0.0, 2.0, 0.0]", b"position = [100.0, 2.0, 0.0]"),
        "scene-body-larger-than-cube": _with_body_keys(bounce, "scale = 100.0"),
        "scene-body-at-1e100-m-per-s": _with_body_keys(bounce, "velocity = [1e100, 0.0, 0.0]"),
        "scene-duration-1e308": _with_table_key(bounce, "integration", "duration = 1e308"),
        "scene-diverges": _with_table_key(bounce, "world", "gravity = 1e300"),
        "scene-toml-nested-500": b"x = " + b"[" * 500 + b"]" * 500 + b"\n" + bounce,
        "scene-latin1-comment": b"# caf\xe9\n" + bounce,
    }
    must_refuse = {"scene-body-outside-cube", "scene-body-larger-than-cube",
                   "scene-body-at-1e100-m-per-s"}
    forbid = {"scene-duration-1e308": (r"integration\.step:",),
              "scene-mass-1e-320": (r"world cube",)}
    cases = [_fixed("known", name, argv=("run", scene_path, *RUN_ARGS),
                    files=((scene_path, text),), names=((scene_path, "key"),),
                    forbid=forbid.get(name, ()), output="{out}/out.npz",
                    must_refuse=name in must_refuse)
             for name, text in scenes.items()]
    for name, model in (("collinear", collinear), ("point", point), ("rot-zero", rot_zero)):
        cases.append(_fixed("known", f"scene-model-{name}", argv=("run", scene_path, *RUN_ARGS),
                            files=((scene_path, bounce.replace(b'"sphere-2k.ac"', b'"m.ac"')),
                                   (model_path, model)),
                            names=((scene_path, "key"), (model_path, "model")),
                            output="{out}/out.npz"))
    for name, model, facts in (
            ("model-rot-1e155", rot_huge, ()),
            ("model-scale-1e154", mutate.scale_by(sphere, "ac", 1e154),
             tuple(sorted(corpus.model_facts("sphere-2k.ac").items())))):
        cases.append(_fixed("known", name, argv=("info", model_path),
                            files=((model_path, model),), names=((model_path, "line"),),
                            facts=facts))
    return cases


def fixed_cases() -> list[Case]:
    """Every case of the fixed families."""
    return special_cases() + output_cases() + signal_cases() + args_cases() + known_cases()


def case_from_id(case_id: str) -> Case:
    """The case of ``case_id`` (``family:mutator:seed:index`` or ``family:name``)."""
    family, _, rest = case_id.partition(":")
    if family in RANDOM_FAMILIES:
        mutator, seed, index = rest.rsplit(":", 2)
        return make_case(family, mutator, seed, int(index))
    for case in fixed_cases():
        if case.id == case_id:
            return case
    raise KeyError(f"no case {case_id!r}")


def with_cpu_limit(case: Case, cpu_limit: float) -> Case:
    """``case`` with another CPU-time limit (the slice uses smaller ones)."""
    return replace(case, cpu_limit=cpu_limit)
