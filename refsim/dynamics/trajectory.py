"""What a simulation returns: per-frame arrays for every body, and events.

The same type comes back from refsim's own loop (``refsim.simulate``) and from
the pybullet oracle, so that the two can be compared array for array.

Shapes, for F frames and B bodies:

- ``t`` (F,): time of each frame, seconds;
- ``position`` (F, B, 3): the body's reference point, its mesh's origin,
  in the world frame (metres);
- ``velocity`` (F, B, 3): the velocity of the body's centre of mass (m/s),
  not of its reference point: the seed's Vel. The centre of mass is the
  uniform solid's in the corrected model and in the oracles, the vertex
  average in the seed model (a scene's ``[[body]] velocity`` means the
  same). For a mesh whose centre is its origin, as for every bundled model
  but the l-beam and the star, the two points move alike; for the others
  the origin moves at ``velocity + angular_velocity x (R c)``, ``c`` the
  centre in the mesh frame;
- ``angular_velocity`` (F, B, 3): radians per second, world frame;
- ``orientation`` (F, B, 3, 3): columns are the body's axes in world space.

``events`` lists wall hits and body contacts as they begin (:class:`Event`;
under the corrected responses each with the impulse it gave and where).
``stages`` names the stages of
the loop that ran; ``stage_seconds`` the wall time spent in each.

The frame arrays are numpy arrays, except in a trajectory whose frames were
spilled to disk as they were computed (``simulate(scene, sink=SpillSink(out))``,
what ``refsim run`` does): there they are :class:`refsim.storage.frames.SpilledArray`
views of the spill files, enough to :meth:`Trajectory.save` it in bounded
memory, and valid while the sink is open.

File format (:meth:`Trajectory.save`, :meth:`Trajectory.load`): an .npz,
compressed, with the entries ``t``, ``position``, ``velocity``,
``angular_velocity``, ``orientation`` (the frames), ``names``, ``events``
(JSON), ``stages``, ``stage_seconds`` (JSON) and ``settings`` (JSON).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from refsim.errors import NpzFileError
from refsim.storage.npz import read_npz
from refsim.storage.writing import write_npz_atomic

#: The .npz entries of a trajectory, in the order they are written.
FRAME_ENTRIES = ("t", "position", "velocity", "angular_velocity", "orientation")
ENTRIES = (*FRAME_ENTRIES, "names", "events", "stages", "stage_seconds", "settings")


class Contact(NamedTuple):
    """A contact found in a step: ``kind`` "wall" (``other`` names the wall,
    "x-" .. "z+") or "body" (``other`` is the other body's name). The step
    keeps the set of its contacts; an :class:`Event` marks the step one
    began in."""

    kind: str
    body: str
    other: str


@dataclass(frozen=True)
class Event:
    """A wall hit (``kind="wall"``, ``other`` is the wall, e.g. "y-") or a
    body contact (``kind="body"``, ``other`` is the other body's name): the
    step in which the contact began.

    With the corrected responses (impulses) the event also holds what the
    contact did in that step: ``impulse``, the contact impulses on ``body``
    summed (N s, world frame: normal and friction; ``other`` received its
    opposite), and ``point``, where they acted (m, world frame: the contact
    points weighted by their normal impulses). Both are None where no
    impulse acts: the seed's laws, which set velocities, and a contact
    whose impulses were all zero (a body already leaving)."""

    kind: str
    step: int
    time: float
    body: str
    other: str
    impulse: tuple[float, float, float] | None = None
    point: tuple[float, float, float] | None = None


@dataclass
class Trajectory:
    """A recorded run of F frames of B bodies (the module docstring lists the
    arrays and their shapes); :meth:`save` writes it as .npz and
    :meth:`load` reads it back, raising :class:`refsim.errors.NpzFileError`
    naming the file and entry for anything it cannot read."""

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    orientation: np.ndarray
    names: tuple[str, ...]
    events: list[Event] = field(default_factory=list)
    stages: tuple[str, ...] = ()
    stage_seconds: dict[str, float] = field(default_factory=dict)
    settings: dict = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        return len(self.t)

    def save(self, path) -> Path:
        """Write the trajectory as a compressed .npz, atomically (never half a
        file), in bounded memory (:func:`refsim.storage.writing.write_npz_atomic`).

        Raises
        ------
        OutputError
            ``path`` is a directory, device, FIFO or socket, or its directory
            is missing (a symlink is written through, see :mod:`refsim.storage.writing`).
        OSError
            As the file system reports it (e.g. a full disk); no file left.
        """
        events = json.dumps([_event_json(e) for e in self.events])
        return write_npz_atomic(path, dict(
            t=self.t, position=self.position, velocity=self.velocity,
            angular_velocity=self.angular_velocity, orientation=self.orientation,
            names=np.array(self.names), events=np.array(events),
            stages=np.array(self.stages),
            stage_seconds=np.array(json.dumps(self.stage_seconds)),
            settings=np.array(json.dumps(self.settings, default=str))), compressed=True)

    @classmethod
    def load(cls, path) -> Trajectory:
        """The trajectory saved at ``path``.

        Raises
        ------
        refsim.storage.npz.NpzFileError
            (a :class:`~refsim.errors.RefsimError` and ``ValueError``) naming
            ``path`` and the entry: no such file, not an .npz (another
            format, or truncated), an entry missing or corrupt, or content
            that is not a trajectory (shapes that disagree, bad JSON).
        """
        data = read_npz(path, ENTRIES)
        t = data["t"]
        if t.ndim != 1 or not np.issubdtype(t.dtype, np.floating):
            raise NpzFileError(f"expected a 1-d float array of times, got {t.dtype} "
                               f"{t.shape}", path, "t")
        names = data["names"]
        if names.ndim != 1 or (names.size and names.dtype.kind != "U"):
            raise NpzFileError(f"expected a 1-d array of body names, got {names.dtype} "
                               f"{names.shape}", path, "names")
        F, B = len(t), len(names)
        for name, shape in (("position", (F, B, 3)), ("velocity", (F, B, 3)),
                            ("angular_velocity", (F, B, 3)), ("orientation", (F, B, 3, 3))):
            a = data[name]
            if a.shape != shape or not np.issubdtype(a.dtype, np.floating):
                raise NpzFileError(f"expected float {shape} ({F} frames of {B} bodies), "
                                   f"got {a.dtype} {a.shape}", path, name)
        stages = data["stages"]
        if stages.ndim != 1 or (stages.size and stages.dtype.kind != "U"):
            raise NpzFileError(f"expected a 1-d array of stage names, got {stages.dtype} "
                               f"{stages.shape}", path, "stages")
        events = _json(data, "events", list, path)
        try:
            records: list[dict[str, Any]] = [
                {k: tuple(v) if isinstance(v, list) else v for k, v in e.items()}
                for e in events]
            events = [Event(**r) for r in records]
        except (TypeError, AttributeError) as exc:
            raise NpzFileError(f"not a list of events ({exc})", path, "events") from None
        return cls(
            t=t, position=data["position"], velocity=data["velocity"],
            angular_velocity=data["angular_velocity"], orientation=data["orientation"],
            names=tuple(str(n) for n in names), events=events,
            stages=tuple(str(s) for s in stages),
            stage_seconds=_json(data, "stage_seconds", dict, path),
            settings=_json(data, "settings", dict, path))


def _event_json(event: Event) -> dict:
    """An event as JSON data; an event without impulse leaves both keys out
    (as files written before they existed)."""
    data = dict(event.__dict__)
    for key in ("impulse", "point"):
        if data[key] is None:
            del data[key]
        else:
            data[key] = list(data[key])
    return data


def _json(data: dict, name: str, kind: type, path):
    """Entry ``name``: a 0-d string holding JSON of type ``kind``."""
    a = data[name]
    if a.ndim != 0 or a.dtype.kind != "U":
        raise NpzFileError(f"expected a JSON string, got {a.dtype} {a.shape}", path, name)
    try:
        value = json.loads(str(a))
    except ValueError as exc:
        raise NpzFileError(f"not valid JSON ({exc})", path, name) from None
    if not isinstance(value, kind):
        raise NpzFileError(f"expected a JSON {kind.__name__}, got "
                           f"{type(value).__name__}", path, name)
    return value
