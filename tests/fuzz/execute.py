"""Running a case: its files made, the command run, what it left observed.

:func:`execute` makes a fresh directory for the case (``in/`` for the input
files and special nodes, ``out/`` as the working directory), runs the
command through a runner, records what the judge needs (:class:`Record`)
and removes the directory. Everything is observed here, nothing is judged:
the laws are in :mod:`tests.fuzz.judge`.

Observations:

- the nodes left in ``out/`` other than the nodes made before the run and
  the command's output;
- for each watched output node (a symlink, device or FIFO made before the
  run), its type before and after;
- for an accepted ``refsim run``, what is wrong with its output file, if
  anything (missing, unreadable, fewer than two frames, non-finite values);
  and, read back with refsim's own loader, whether the scene it accepted
  is physically absurd (a body outside the world cube, a body that crosses
  more than half the cube in one step);
- for ``refsim info``, the facts it printed.

Cost: the command's, plus O(size of the output) to check it.
"""

from __future__ import annotations

import math
import os
import shutil
import stat
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from tests.fuzz.cases import Case, Special
from tests.fuzz.runner import Command, Outcome

#: Kinds of file system node, for the "replaced" check.
_KINDS = {stat.S_IFREG: "file", stat.S_IFDIR: "directory", stat.S_IFLNK: "symlink",
          stat.S_IFCHR: "device", stat.S_IFIFO: "fifo", stat.S_IFBLK: "block device",
          stat.S_IFSOCK: "socket"}


@dataclass(frozen=True)
class Record:
    """What one case did (see the module docstring). Paths are relative to
    ``out/``; ``places`` maps the placeholders to the directories used."""

    case_id: str
    outcome: Outcome
    places: dict
    left: tuple[str, ...] = ()
    replaced: tuple[str, ...] = ()
    output_problem: str | None = None
    scene_problem: str | None = None
    facts: dict = field(default_factory=dict)


def fill(path: str, places: dict) -> str:
    """``path`` with ``{in}`` and ``{out}`` replaced."""
    for key, value in places.items():
        path = path.replace(key, value)
    return path


def _kind(path: str) -> str:
    try:
        return _KINDS.get(stat.S_IFMT(os.lstat(path).st_mode), "other")
    except OSError:
        return "absent"


def _make(special: Special, places: dict) -> None:
    path = fill(special.path, places)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if special.kind == "dir":
        os.mkdir(path)
    elif special.kind == "readonly-dir":
        os.mkdir(path)
        os.chmod(path, 0o555)
    elif special.kind == "fifo":
        os.mkfifo(path)
    elif special.kind == "symlink":
        os.symlink(fill(special.target, places), path)
    elif special.kind == "device":              # the numbers of /dev/null
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    elif special.kind == "locked-dir":
        os.mkdir(path)
        with open(os.path.join(path, special.target), "wb") as handle:
            handle.write(special.content)
        os.chmod(path, 0)
    elif special.kind in ("unreadable", "file"):
        with open(path, "wb") as handle:
            handle.write(special.content)
        if special.kind == "unreadable":
            os.chmod(path, 0)
    else:
        raise ValueError(f"unknown special kind {special.kind!r}")


def materialize(case: Case, root: Path) -> dict:
    """Make the case's directories, files and special nodes under ``root``."""
    places = {"{in}": str(root / "in"), "{out}": str(root / "out")}
    (root / "in").mkdir()
    (root / "out").mkdir()
    for path, data in case.files:
        real = fill(path, places)
        os.makedirs(os.path.dirname(real), exist_ok=True)
        with open(real, "wb") as handle:
            handle.write(data)
    for special in case.specials:
        _make(special, places)
    return places


def _tree(directory: str) -> dict[str, str]:
    """Every node under ``directory`` (not following symlinks) and its kind."""
    nodes = {}
    for parent, dirs, files in os.walk(directory):
        for name in dirs + files:
            full = os.path.join(parent, name)
            nodes[os.path.relpath(full, directory)] = _kind(full)
    return nodes


def check_output(path: str) -> str | None:
    """What is wrong with the .npz an accepted ``refsim run`` wrote, or None."""
    import numpy as np

    if _kind(path) != "file":
        return f"no output file ({_kind(path)})"
    try:
        with np.load(path) as data:
            arrays = {key: data[key] for key in data.files}
    except Exception as exc:  # any reason the file cannot be read is the finding
        return f"output cannot be read: {type(exc).__name__}"
    t = arrays.get("t")
    if t is None or t.ndim != 1:
        return "output has no time axis"
    if len(t) < 2:
        return f"ran zero steps ({len(t)} frame)"
    for key in ("t", "position", "velocity", "angular_velocity", "orientation"):
        if key in arrays and not np.isfinite(arrays[key]).all():
            return f"output {key} is not finite"
    if "status" in arrays and str(arrays["status"]) != "complete":
        return f"output status {str(arrays['status'])!r}"
    return None


def check_scene(path: str) -> str | None:
    """:func:`scene_absurdity` of the scene file at ``path``, read with
    refsim's loader (None when it does not load here)."""
    import logging

    from refsim.scenes.loader import load_scene

    logging.disable(logging.CRITICAL)         # trimesh logs what the child already logged
    try:
        scene = load_scene(path)
    except Exception:  # refsim accepted it in the child; a difference is not ours to judge
        return None
    finally:
        logging.disable(logging.NOTSET)
    return scene_absurdity(scene)


def scene_absurdity(scene) -> str | None:
    """Why an accepted scene is physically absurd, or None.

    A body must start inside the world cube (its vertices under its initial
    pose and scale), and no body or particle may cross more than half the
    cube in one step (speed * h > half_size): the seed's wall test then
    sees nothing of the wall it passed.
    """
    import numpy as np

    half, h = scene.world.half_size, scene.integration.step
    with np.errstate(all="ignore"):
        for body in scene.bodies:
            vertices = scene.mesh(body).vertices * body.scale
            world = vertices @ np.array(body.orientation).T + np.array(body.position)
            if not (np.isfinite(world).all() and np.abs(world).max() <= half):
                return f"body {body.name!r} is not inside the world cube at the start"
            if math.hypot(*body.velocity) * h > half:
                return f"body {body.name!r} crosses more than half the cube in one step"
        if scene.particles is not None:
            if scene.particles.speed_max * scene.particles.step > half:
                return "particles cross more than half the cube in one step"
    return None


def _parse_facts(stdout: str) -> dict:
    facts = {}
    for line in stdout.splitlines():
        key, sep, value = line.partition("  ")
        if sep:
            facts[key.strip()] = value.strip()
    return facts


def execute(case: Case, runner, workdir: Path) -> Record:
    """Run ``case`` with ``runner`` in a fresh directory under ``workdir``."""
    root = Path(tempfile.mkdtemp(prefix="case-", dir=workdir))
    try:
        places = materialize(case, root)
        watched = {w: _kind(fill(w, places)) for w in case.watch}
        made = {os.path.relpath(fill(s.path, places), places["{out}"])
                for s in case.specials if s.path.startswith("{out}")}
        command = Command(
            argv=tuple(fill(a, places) for a in case.argv), cwd=Path(places["{out}"]),
            stdout=root / "stdout", stderr=root / "stderr", cpu_limit=case.cpu_limit,
            unprivileged=case.unprivileged, interrupt=case.interrupt)
        outcome = runner.run(command)
        output = fill(case.output, places) if case.output else None
        expected = set(made)
        if output is not None and outcome.returncode in (0, 3):
            expected.add(os.path.relpath(output, places["{out}"]))
        left = tuple(sorted(name for name, kind in _tree(places["{out}"]).items()
                            if name not in expected and kind != "directory"))
        replaced = tuple(f"{os.path.basename(fill(w, places))}: {before} -> {after}"
                         for w, before in watched.items()
                         if (after := _kind(fill(w, places))) != before)
        record = Record(case.id, outcome, places, left=left, replaced=replaced)
        if outcome.returncode == 0 and case.argv[:1] == ("run",) and output is not None:
            scene = fill(case.argv[1], places)
            record = Record(case.id, outcome, places, left=left, replaced=replaced,
                            output_problem=None if case.watch else check_output(output),
                            scene_problem=check_scene(scene) if case.files else None)
        elif outcome.returncode == 0 and case.argv[:1] == ("info",):
            record = Record(case.id, outcome, places, left=left, replaced=replaced,
                            facts=_parse_facts(outcome.stdout))
        return record
    finally:
        shutil.rmtree(root, ignore_errors=True)
