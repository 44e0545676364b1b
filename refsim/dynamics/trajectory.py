"""What a simulation returns: per-frame arrays for every body, and events.

The same type comes back from refsim's own loop (``refsim.simulate``) and from
the pybullet oracle, so that the two can be compared array for array.

Shapes, for F frames and B bodies:

- ``t`` (F,): time of each frame, seconds;
- ``position``, ``velocity``, ``angular_velocity`` (F, B, 3): the body's
  reference point (its mesh's origin), its velocity, and its angular velocity
  in radians per second, world frame (refsim's loop reports the velocity of
  the body's centroid, the seed's Vel; for a mesh whose centroid is its
  origin, as for every bundled model but the l-beam and the star, the two
  coincide);
- ``orientation`` (F, B, 3, 3): columns are the body's axes in world space.

``events`` lists wall hits and body contacts. ``stages`` names the stages of
the loop that ran; ``stage_seconds`` the wall time spent in each.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from refsim.io import write_npz_atomic


@dataclass(frozen=True)
class Event:
    """A wall hit (``kind="wall"``, ``other`` is the wall, e.g. "y-") or a
    body contact (``kind="body"``, ``other`` is the other body's name)."""

    kind: str
    step: int
    time: float
    body: str
    other: str


@dataclass
class Trajectory:
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
        """Write the trajectory as .npz, atomically (never half a file)."""
        events = json.dumps([e.__dict__ for e in self.events])
        return write_npz_atomic(path, dict(
            t=self.t, position=self.position, velocity=self.velocity,
            angular_velocity=self.angular_velocity, orientation=self.orientation,
            names=np.array(self.names), events=np.array(events),
            stages=np.array(self.stages),
            stage_seconds=np.array(json.dumps(self.stage_seconds)),
            settings=np.array(json.dumps(self.settings, default=str))), compressed=True)

    @classmethod
    def load(cls, path) -> Trajectory:
        with np.load(path) as data:
            return cls(
                t=data["t"], position=data["position"], velocity=data["velocity"],
                angular_velocity=data["angular_velocity"], orientation=data["orientation"],
                names=tuple(str(n) for n in data["names"]),
                events=[Event(**e) for e in json.loads(str(data["events"]))],
                stages=tuple(str(s) for s in data["stages"]),
                stage_seconds=json.loads(str(data["stage_seconds"])),
                settings=json.loads(str(data["settings"])))
