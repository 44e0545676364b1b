"""Standalone replays: recorded runs as one HTML file that plays offline (S12).

``write_replay(runs, path)`` draws each run's bodies in the world cube, side
by side along x (labelled) or overlaid in one cube (each run in its own
colour), records one pose update per body per kept frame with viser's scene
serializer, and writes viser's client with the recording embedded: a page
with play/pause, a time slider to scrub, a speed menu and a scene tree, that
works from ``file://`` and inside an ``<iframe>``, with no network. A panel
on the page names each run and its settings (the trajectory's ``settings``)
and the frame stride. Playback runs in simulated time (1x: one simulated
second per second).

Size budget. The page is viser's client (about 0.8 MB), the meshes, and the
frames (compressed with zstd, then base64). ``max_bytes`` bounds the whole
file: the replay keeps every ``stride``-th frame of the common timeline
(always the first and the last), with the smallest stride that fits: it
measures the page with all frames, estimates the bytes per frame from that
and from the page with none, and widens the stride until the page fits.
The stride chosen is reported (:class:`ReplayInfo`) and shown on the page.

Meshes. A trajectory records its bodies' names and the run's settings, not
their meshes. :func:`load_run` takes the meshes from a scene: the one given
(``refsim replay --scene``), else the scene the run records in its settings:
``refsim run`` stores the scene file's text and path
(:func:`recorded_scene_settings`), read again as if from that path, so that
its models resolve as they did; a recording with the path alone names a
scene file that must still be there. The scene
must have the run's bodies, by name and in order, and a warning says when
the run's first frame is not the scene's initial state (the file changed
since the run, or the run was made from another scene). A body's mesh is
the scene's model at the body's scale, as the simulation used it.

Cost: O(frames x bodies) pose updates, one serialization per size trial
(at most a handful).
"""

from __future__ import annotations

import base64
import html
import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from refsim.errors import OutputError, RefsimError, check_count
from refsim.limits import MAX_STEPS
from refsim.viewer import REPLAY_MAX_BYTES as DEFAULT_MAX_BYTES

if TYPE_CHECKING:
    from refsim.dynamics.trajectory import Trajectory

#: Space between two runs side by side, as a fraction of the larger cube's size.
GAP = 0.25

#: A run's first frame farther than this (m, relative to the cube's half
#: size) from its scene's initial state is reported: the scene file is not
#: the one the run was made from. Rounding of a position written in TOML
#: and recorded as float64 is far below it.
START_RTOL = 1e-9

#: The replay's camera stands farther back than the live viewer's: less
#: perspective between runs side by side, and room for the settings panel.
REPLAY_CAMERA_MARGIN = 1.4

#: Where a run's label stands, in half sizes of its cube from its centre:
#: just below the middle of the front bottom edge (above the cube it sat on
#: the top edges, seen from above).
LABEL_AT = (0.0, -1.08, 1.0)

#: Opacity of the bodies when runs are overlaid, so that both show where
#: they coincide.
OVERLAY_OPACITY = 0.65

#: The settings a run records, as the page names them, in the page's order
#: (others follow, sorted, their underscores as spaces).
SETTING_NAMES = {"scene": "scene", "engine": "engine", "solver": "solver",
                 "step": "step h (s)", "rotation": "rotation",
                 "body_response": "body response", "collision_level": "collision level",
                 "aabb": "box update", "every": "stored every (steps)",
                 "steps": "steps", "wall_speed": "wall speed", "wall_response": "wall response",
                 "boxes": "boxes", "kernel": "kernels"}

#: The settings entry that holds the text of the run's scene file (beside
#: ``scene``, its path); not shown on the page.
SCENE_TEXT = "scene_toml"

#: Widening of the stride per retry when the estimate missed the budget.
STRIDE_GROWTH = 1.25


@dataclass
class ReplayRun:
    """One run to replay.

    Attributes
    ----------
    label : str
        Shown above the run (side by side) and in the page's panel.
    trajectory : refsim.Trajectory
    meshes : tuple of refsim.Mesh
        One per body, in ``trajectory.names`` order, scaled as simulated.
    half_size : float
        The world cube's half size (m).
    settings : dict
        Shown on the page (default: the trajectory's settings).
    """

    label: str
    trajectory: Trajectory
    meshes: tuple
    half_size: float
    settings: dict = field(default_factory=dict)

    def __post_init__(self):
        B = len(self.trajectory.names)
        if len(self.meshes) != B:
            raise RefsimError(f"run {self.label!r}: {len(self.meshes)} meshes for {B} "
                              f"bod{'y' if B == 1 else 'ies'}")
        if self.trajectory.n_frames == 0:
            raise RefsimError(f"run {self.label!r} has no frames")
        if not self.settings:
            self.settings = dict(self.trajectory.settings)


def run_from_scene(label: str, scene, trajectory, settings: dict | None = None) -> ReplayRun:
    """A :class:`ReplayRun` of ``trajectory`` with the meshes of ``scene``."""
    from refsim.viewer.overlays import body_meshes

    check_bodies(label, scene, trajectory)
    shown = dict(trajectory.settings if settings is None else settings)
    shown.pop(SCENE_TEXT, None)
    if scene.path is not None:
        shown.setdefault("scene", Path(scene.path).name)
    return ReplayRun(label=label, trajectory=trajectory, meshes=body_meshes(scene),
                     half_size=scene.world.half_size, settings=shown)


def check_bodies(label: str, scene, trajectory) -> None:
    """RefsimError unless ``scene`` has the bodies of ``trajectory`` (names,
    order); a warning when the first frame is not the scene's initial pose."""
    names = tuple(b.name for b in scene.bodies)
    if names != tuple(trajectory.names):
        raise RefsimError(f"{label}: the run's bodies ({', '.join(trajectory.names)}) are "
                          f"not those of scene {scene.path or '<scene>'} "
                          f"({', '.join(names) or 'none'})")
    start = np.array([b.position for b in scene.bodies], dtype=np.float64)
    R0 = np.array([b.orientation for b in scene.bodies], dtype=np.float64)
    off = max(float(np.abs(trajectory.position[0] - start).max()),
              float(np.abs(trajectory.orientation[0] - R0).max()) * scene.world.half_size)
    if off > START_RTOL * scene.world.half_size:
        warnings.warn(f"{label}: the run's first frame is {off:.3g} m from the initial state "
                      f"of {scene.path or 'its scene'}: was the run made from another "
                      f"version of the scene?", stacklevel=2)


def load_run(path, scene=None, *, label: str | None = None) -> ReplayRun:
    """A run recorded by ``refsim run`` (.npz), with the meshes of ``scene``
    (a Scene or a scene file), else of the scene file the run records."""
    from refsim.dynamics.trajectory import Trajectory
    from refsim.scenes.loader import load_scene
    from refsim.scenes.schema import Scene

    path = Path(path)
    label = label or path.stem
    traj = _load_trajectory(path)
    if scene is None and isinstance(traj.settings.get(SCENE_TEXT), str):
        scene = _recorded_scene(path, traj.settings)
    if scene is None:
        recorded = traj.settings.get("scene")
        if not recorded:
            raise RefsimError(f"{path}: the run does not record its scene file; name it "
                              f"with --scene SCENE.toml")
        if not Path(recorded).is_file():
            raise RefsimError(f"{path}: the run's scene file {recorded} is not there; name "
                              f"the scene with --scene SCENE.toml")
        scene = recorded
    if not isinstance(scene, Scene):
        scene = load_scene(scene, max_steps=MAX_STEPS)      # run already: any length
    assert isinstance(traj, Trajectory)
    return run_from_scene(label, scene, traj)


def recorded_scene_settings(scene_path, text: str) -> dict:
    """The settings entries that let :func:`load_run` rebuild a run's scene:
    its file's absolute path (``scene``) and text (:data:`SCENE_TEXT`)."""
    return {"scene": None if scene_path is None else str(Path(scene_path).absolute()),
            SCENE_TEXT: text}


def _recorded_scene(path: Path, settings: dict):
    """The scene whose text the run at ``path`` records, read as if from the
    scene file's path (its relative model paths resolve as they did)."""
    from refsim.errors import SceneError
    from refsim.scenes.loader import scene_from_text

    recorded = settings.get("scene")
    try:
        return scene_from_text(settings[SCENE_TEXT],
                               Path(recorded) if isinstance(recorded, str) else None,
                               max_steps=MAX_STEPS)
    except SceneError as exc:
        raise RefsimError(f"{path}: the scene the run records cannot be rebuilt ({exc}); "
                          f"name the scene with --scene SCENE.toml") from None


def _load_trajectory(path: Path):
    import zipfile

    from refsim.dynamics.trajectory import Trajectory

    if not path.exists():
        raise RefsimError(f"{path}: no such file")
    if not path.is_file():                   # a FIFO or a device is never opened
        raise RefsimError(f"{path}: not a regular file")
    try:
        with np.load(path) as data:
            keys = set(data.files)
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise RefsimError(f"{path}: not a .npz file ({exc})") from None
    if "orientation" not in keys:
        kind = "a particle run" if "status" in keys else "not a trajectory"
        raise RefsimError(f"{path}: {kind}; refsim replay shows rigid-body runs "
                          f"(refsim run of a scene with [[body]] tables)")
    try:
        return Trajectory.load(path)
    except RefsimError:
        raise                                # it names the file and the entry
    except (KeyError, ValueError, TypeError, json.JSONDecodeError) as exc:
        raise RefsimError(f"{path}: not a refsim trajectory ({exc})") from None


def load_runs(paths, scenes=()) -> list[ReplayRun]:
    """:func:`load_run` of each path; ``scenes`` is empty (each run's
    recorded scene), one scene for all runs, or one per run."""
    paths, scenes = list(paths), list(scenes)
    if len(scenes) not in (0, 1, len(paths)):
        raise RefsimError(f"give --scene once for all runs or once per run: {len(scenes)} "
                          f"scenes for {len(paths)} runs")
    if len(scenes) == 1 and len(paths) > 1:
        from refsim.scenes.loader import load_scene

        scenes = [load_scene(scenes[0], max_steps=MAX_STEPS)] * len(paths)
    labels = _labels(paths)
    return [load_run(p, scenes[i] if scenes else None, label=labels[i])
            for i, p in enumerate(paths)]


def _labels(paths) -> list[str]:
    """File stems, made unique with their folders where two are alike."""
    stems = [Path(p).stem for p in paths]
    return [str(Path(p).with_suffix("")) if stems.count(s) > 1 else s
            for p, s in zip(paths, stems, strict=True)]


# -- the timeline ------------------------------------------------------------------------


def timeline(runs) -> np.ndarray:
    """(T,) the times of every run's frames, merged (equal times once)."""
    return np.unique(np.concatenate([np.asarray(r.trajectory.t, dtype=np.float64)
                                     for r in runs]))


def frame_at(t: np.ndarray, times: np.ndarray) -> np.ndarray:
    """For each time, the run's last frame at or before it (its first before it starts)."""
    return np.clip(np.searchsorted(t, times + 1e-12 * np.maximum(1.0, np.abs(times)),
                                   side="right") - 1, 0, len(t) - 1)


def kept_frames(n: int, stride: int) -> np.ndarray:
    """Indices 0, stride, 2 stride, ... and always the last of n."""
    keep = np.arange(0, n, stride)
    return keep if keep[-1] == n - 1 else np.append(keep, n - 1)


# -- writing ----------------------------------------------------------------------------


@dataclass(frozen=True)
class ReplayInfo:
    """What :func:`write_replay` wrote."""

    path: Path
    bytes: int
    stride: int              # every stride-th frame of the timeline kept
    frames: int              # frames kept
    timeline_frames: int     # frames of the merged timeline
    runs: tuple[str, ...]
    overlay: bool
    max_bytes: int

    def summary(self) -> str:
        n = len(self.runs)
        layout = "" if n == 1 else " overlaid" if self.overlay else " side by side"
        return (f"wrote {self.path}: {n} run{'s' if n != 1 else ''}{layout}, "
                f"{self.frames} of {self.timeline_frames} frames (stride {self.stride}), "
                f"{self.bytes / 1e6:.2f} MB (budget {self.max_bytes / 1e6:g} MB)")


def write_replay(runs, path, *, overlay: bool = False, max_bytes: int = DEFAULT_MAX_BYTES,
                 boxes: bool = False, title: str | None = None,
                 stride: int | None = None) -> ReplayInfo:
    """Write ``runs`` (:class:`ReplayRun`) as one standalone replay page.

    Parameters
    ----------
    runs : sequence of ReplayRun
    path : output .html, written whole or not at all
    overlay : draw all runs in one cube (default: side by side along x)
    max_bytes : the page's size budget; frames are skipped to fit
    boxes : draw each body's box (AABB, the linear scan) too
    title : the page's heading (default: the runs' labels)
    stride : keep every stride-th frame (default: the smallest that fits)

    Raises
    ------
    RefsimError
        No runs, or the budget is smaller than the page without its frames.
    OutputError
        The file cannot be written.
    """
    from refsim.storage.writing import write_text_atomic

    runs = list(runs)
    if not runs:
        raise RefsimError("no runs to replay")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, int) or max_bytes < 1:
        raise RefsimError(f"max_bytes must be a positive whole number, got {max_bytes!r}")
    path = Path(path)
    if not path.parent.is_dir():
        raise OutputError(f"{path}: cannot write: no directory {path.parent}")
    times = timeline(runs)
    title = title or " | ".join(r.label for r in runs)
    page = _Page(runs, times, overlay=overlay, boxes=boxes, title=title)
    T = len(times)
    if stride is None:
        stride, text = page.fit(max_bytes)
    else:
        stride = check_count("stride", stride, minimum=1)
        text = page.render(stride)
    size = len(text.encode("utf-8"))
    if size > max_bytes:
        raise RefsimError(f"the replay takes {size / 1e6:.2f} MB at stride {stride}, over "
                          f"the budget of {max_bytes / 1e6:g} MB (--max-bytes)")
    try:
        write_text_atomic(path, text)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None
    return ReplayInfo(path=path, bytes=size, stride=stride, frames=len(kept_frames(T, stride)),
                      timeline_frames=T, runs=tuple(r.label for r in runs), overlay=overlay,
                      max_bytes=max_bytes)


class _Page:
    """The replay's scene, recorded at a given stride."""

    def __init__(self, runs, times, *, overlay: bool, boxes: bool, title: str):
        self.runs, self.times = runs, times
        self.overlay, self.boxes, self.title = overlay, boxes, title
        H = max(r.half_size for r in runs)
        self.H = H
        if overlay:
            self.offsets = [np.zeros(3) for _ in runs]
        else:
            pitch = 2.0 * H * (1.0 + GAP)
            first = -0.5 * pitch * (len(runs) - 1)
            self.offsets = [np.array([first + i * pitch, 0.0, 0.0]) for i in range(len(runs))]
        self.frames = [frame_at(r.trajectory.t, times) for r in runs]
        self.box_frames: list[np.ndarray] | None = None     # per run, (F, B, 2, 3)
        if boxes:
            from refsim.viewer.overlays import body_boxes

            self.box_frames = [body_boxes(r.meshes, r.trajectory) for r in runs]

    def fit(self, max_bytes: int) -> tuple[int, str]:
        """The smallest stride whose page fits ``max_bytes``, and the page."""
        T = len(self.times)
        text = self.render(1)
        if len(text.encode("utf-8")) <= max_bytes or T <= 2:
            return 1, text
        base = len(self.render(T).encode("utf-8"))      # first and last frame only
        if base > max_bytes:
            raise RefsimError(f"the replay needs {base / 1e6:.2f} MB without its frames "
                              f"(viser's client and the meshes), over the budget of "
                              f"{max_bytes / 1e6:g} MB (--max-bytes)")
        per_frame = (len(text.encode("utf-8")) - base) / max(T - 2, 1)
        stride = max(2, int(np.ceil(T * per_frame / max(max_bytes - base, 1))))
        while True:
            text = self.render(stride)
            if len(text.encode("utf-8")) <= max_bytes or stride >= T:
                return stride, text
            stride = min(T, max(stride + 1, int(np.ceil(stride * STRIDE_GROWTH))))

    def render(self, stride: int) -> str:
        from refsim.viewer import draw
        from refsim.viewer.server import start_server, stop_server

        server = start_server()
        try:
            n = 1 if self.overlay else len(self.runs)
            # the page's panel floats over the left of the window: the runs to its right
            draw.place_camera(server.initial_camera, 2.0 * self.H * (n + GAP * (n - 1)),
                              2.0 * self.H,
                              direction=draw.VIEW_DIRECTION if n == 1 else draw.FRONT_DIRECTION,
                              margin=REPLAY_CAMERA_MARGIN, pan=-draw.PANEL_PAN)
            s = server.scene
            serializer = server.get_scene_serializer()
            nodes = self._add_nodes(s, draw)
            keep = kept_frames(len(self.times), stride)
            shown: list[int | None] = [None] * len(self.runs)   # the frame posed, per run
            for j, i in enumerate(keep):
                if j:
                    serializer.insert_sleep(float(self.times[i] - self.times[keep[j - 1]]))
                for r, run in enumerate(self.runs):
                    f = int(self.frames[r][i])
                    if f == shown[r]:
                        continue
                    shown[r] = f
                    self._pose(run, r, f, nodes[r], draw)
            text = serializer.as_html()
        finally:
            stop_server(server)
        return _with_panel(text, self._panel(stride, len(keep)))

    def _add_nodes(self, s, draw) -> list[dict]:
        nodes = []
        cubes = set()
        for r, run in enumerate(self.runs):
            off = self.offsets[r]
            key = (tuple(off), run.half_size)
            if key not in cubes:
                cubes.add(key)
                draw.add_cube(s, f"/run{r}/world-cube", run.half_size, off)
            if not self.overlay:
                # below the cube's front bottom edge, where no edge or body is drawn
                s.add_label(f"/run{r}/label", run.label,
                            position=off + run.half_size * np.array(LABEL_AT),
                            anchor="top-center", font_screen_scale=1.2)
            bodies = []
            for b, mesh in enumerate(run.meshes):
                rgb = draw.color(r if self.overlay else b)
                handle = draw.add_body(s, f"/run{r}/bodies/{run.trajectory.names[b]}", mesh, rgb,
                                       opacity=OVERLAY_OPACITY if self.overlay else None)
                bodies.append(handle)
            box = None
            if self.box_frames is not None:
                box = draw.add_boxes(s, f"/run{r}/boxes", self.box_frames[r][0], off)
            nodes.append({"bodies": bodies, "boxes": box})
        return nodes

    def _pose(self, run: ReplayRun, r: int, f: int, node: dict, draw) -> None:
        traj = run.trajectory
        for b, handle in enumerate(node["bodies"]):
            draw.set_pose(handle, traj.orientation[f, b], traj.position[f, b], self.offsets[r])
        if node["boxes"] is not None:
            assert self.box_frames is not None, "a box node is made only with box_frames"
            node["boxes"].points = draw.boxes_segments(self.box_frames[r][f],
                                                       self.offsets[r]).astype(np.float32)

    def _panel(self, stride: int, kept: int) -> str:
        from refsim.viewer import draw

        rows = []
        for r, run in enumerate(self.runs):
            swatches = "".join(
                f'<span class="sw" style="background:rgb{draw.color(r if self.overlay else b)}">'
                f'</span>' for b in range(1 if self.overlay else len(run.meshes)))
            traj = run.trajectory
            B = len(traj.names)
            facts = [f"{B} bod{'y' if B == 1 else 'ies'}: {', '.join(traj.names)}",
                     f"{traj.n_frames} frames, t = {traj.t[0]:g} to {traj.t[-1]:g} s"]
            settings = "".join(f"<tr><td>{html.escape(str(k))}</td>"
                               f"<td>{html.escape(_value(v))}</td></tr>"
                               for k, v in named_settings(run.settings))
            rows.append(f"<details open><summary>{swatches}<b>{html.escape(run.label)}</b>"
                        f"</summary><div>{html.escape('; '.join(facts))}</div>"
                        f"<table>{settings}</table></details>")
        layout = ("" if len(self.runs) == 1 else " overlaid" if self.overlay
                  else " side by side (along x)")
        every = "every frame" if stride == 1 else f"stride {stride}: one frame in {stride}"
        return (f'<div id="refsim-replay"><details open><summary><b>refsim replay</b>: '
                f'{html.escape(self.title)}</summary>'
                f'<div>{len(self.runs)} run{"s" if len(self.runs) != 1 else ""}{layout}; '
                f'{kept} of {len(self.times)} frames kept ({every}); 1x plays one '
                f'simulated second per second.</div>{"".join(rows)}</details></div>')


def named_settings(settings: dict) -> list[tuple[str, object]]:
    """A run's settings as the page lists them: (name in words, value), the
    :data:`SETTING_NAMES` first in their order, then the others sorted; the
    scene file's text is left out (its path is shown)."""
    first = [(SETTING_NAMES[k], settings[k]) for k in SETTING_NAMES if k in settings]
    rest = sorted((k.replace("_", " "), v) for k, v in settings.items()
                  if k not in SETTING_NAMES and k != SCENE_TEXT)
    return first + rest


def _value(v) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, dict | list):
        return json.dumps(v, default=str)
    return str(v)


PANEL_STYLE = """<style>
#refsim-replay { position: fixed; top: 8px; left: 8px; z-index: 1000; max-width: 25em;
  max-height: 70vh; overflow: auto; font: 12px/1.35 system-ui, sans-serif; color: #222;
  background: rgba(255, 255, 255, 0.92); border: 1px solid #ccc; border-radius: 6px;
  padding: 6px 8px; }
#refsim-replay details details { margin-top: 6px; }
#refsim-replay summary { cursor: pointer; }
#refsim-replay table { border-collapse: collapse; margin-top: 2px; }
#refsim-replay td { padding: 0 6px 0 0; vertical-align: top; }
#refsim-replay td:first-child { color: #666; white-space: nowrap; }
#refsim-replay td + td { overflow-wrap: break-word; }
#refsim-replay .sw { display: inline-block; width: 10px; height: 10px; margin-right: 3px;
  border-radius: 2px; vertical-align: baseline; }
</style>"""


def _with_panel(page: str, panel: str) -> str:
    """viser's page with the replay's panel (inline HTML and CSS, no script)."""
    head = page.index("</head>")
    page = page[:head] + PANEL_STYLE + page[head:]
    body = page.rindex("</body>")
    return page[:body] + panel + page[body:]


def read_recording(page: str) -> dict:
    """The recording a replay page carries, decoded: viser's serialized scene
    (``durationSeconds``, ``messages``, ``viserVersion``, ...), for checks
    that a page is whole. Raises ValueError when the page carries none.

    The layout (viser's ``StateSerializer.serialize``): 8 bytes of the
    uncompressed size, then zstd of [8 bytes of the msgpack length, the
    msgpack header, the binary buffers].
    """
    import msgspec
    import zstandard

    marker = 'window.__VISER_EMBED_DATA__="'
    if marker not in page:
        raise ValueError("the page carries no viser recording")
    start = page.index(marker) + len(marker)
    data = base64.b64decode(page[start:page.index('"', start)], validate=True)
    size = int.from_bytes(data[:8], "little")
    inner = zstandard.ZstdDecompressor().decompress(data[8:], max_output_size=size)
    if len(inner) != size:
        raise ValueError(f"the recording is {len(inner)} bytes, its header says {size}")
    header = int.from_bytes(inner[:8], "little")
    return msgspec.msgpack.decode(inner[8:8 + header])
