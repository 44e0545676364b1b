"""The live viewer: a scene in the browser, re-run from its controls (S12).

``refsim view SCENE.toml`` (and :func:`view`, for notebooks) serves one page
with viser (:mod:`refsim.viewer`): the world cube and the scene's bodies in
3D, y up; a playback panel (play/pause, step, a frame slider to scrub,
speed); the scene's options as controls (solver, step size, collision level,
box update, rotation model, body response) whose change re-runs the
simulation; overlays (the bodies' boxes, the world cube, the contacting
triangle pairs at the frame shown, wall-hit normals and impulses) and an
energy chart. A ``[particles]`` table is drawn as a point cloud.

Threads. viser serves the page and calls the controls' callbacks from its
own threads. A run happens in a worker thread (:mod:`refsim.viewer.runs`),
chunk by chunk, reporting progress to a bar; a newer request cancels it, so
the page never waits for a simulation. A player thread advances the frame
while playing. The state they share (the current run, the frame, the
playback clock) is guarded by one lock; drawing happens outside it.

What is shown per frame (:meth:`Viewer.show_frame`) is computed from the
recorded run by :mod:`refsim.viewer.overlays`: boxes and energy for every
frame when a run finishes; contacting triangles lazily, for the frame shown
(and cached); wall hits for the frames within ``HIT_SECONDS`` after each.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np

from refsim.dynamics.trajectory import Trajectory
from refsim.errors import DivergenceError, RefsimError, SceneError
from refsim.scenes.schema import Scene
from refsim.viewer import draw
from refsim.viewer.overlays import (
    OPTIONS,
    Energy,
    WallHit,
    body_boxes,
    body_meshes,
    contacting_triangles,
    energy_per_frame,
    scene_with,
    wall_hits,
)
from refsim.viewer.runs import Cancelled, ParticleRun, run_bodies, run_particles
from refsim.viewer.server import LOCAL_HOST, start_server, stop_server, url

#: The player's tick: frames are drawn at most this often (s), about 30 per second.
TICK = 1.0 / 30.0

#: A wall hit's normal and impulse stay drawn this long after it (s of simulated time).
HIT_SECONDS = 0.25

#: Playback speeds offered (simulated seconds per wall-clock second).
SPEEDS = ("0.1x", "0.25x", "0.5x", "1x", "2x", "4x")

#: Progress is sent to the page at most this often (s).
PROGRESS_INTERVAL = 0.1

#: How long :meth:`Viewer.close` waits for its threads (s): a chunk of
#: steps of the slowest bundled scene, and the overlays of a finished run.
CLOSE_SECONDS = 5.0

#: Particles drawn as points of this size, in metres.
PARTICLE_SIZE = 0.03

#: The controls of the simulation panel: option -> label.
CONTROL_LABELS = {"solver": "Solver", "step": "Step h (s)", "level": "Collision level",
                  "aabb": "Box update", "rotation": "Rotation", "body_response": "Body response"}


def scene_options(scene) -> dict:
    """The current value of each option the controls change."""
    return {"solver": scene.integration.solver, "step": scene.integration.step,
            "level": scene.collision.level, "aabb": scene.collision.aabb,
            "rotation": scene.dynamics.rotation,
            "body_response": scene.dynamics.body_response}


@dataclass
class Run:
    """A finished run and what the overlays need of it, for every frame."""

    scene: Scene
    generation: int
    t: np.ndarray                            # (F,)
    # The bodies' frames and their overlays: all four or none (no bodies).
    trajectory: Trajectory | None = None
    boxes: np.ndarray | None = None          # (F, B, 2, 3)
    energy: Energy | None = None
    hits: list[WallHit] | None = None
    particles: ParticleRun | None = None
    note: str = ""                    # e.g. "diverged at step 812"
    seconds: float = 0.0              # wall time of the simulation

    @property
    def n_frames(self) -> int:
        return len(self.t)


class Viewer:
    """A scene served to the browser, with its simulation re-run on demand.

    Parameters
    ----------
    scene : refsim.Scene or path
        A scene (``refsim.load_scene``) or a scene file.
    host : str
        Address to bind (default 127.0.0.1: this machine only).
    port : int
        0 (default) for any free port; a port in use raises RefsimError.
    every : int, optional
        Keep a frame every ``every`` steps (default: about 1000 frames).
    play : bool
        Start playing when the first run is done.

    Attributes
    ----------
    server : viser.ViserServer
    url : str
    scene : refsim.Scene
        The scene of the run shown (the options of the last finished run).
    run : Run or None
        The run shown.
    frame : int
        The frame shown.
    """

    def __init__(self, scene, *, host: str = LOCAL_HOST, port: int = 0,
                 every: int | None = None, play: bool = True):
        from refsim.scenes.loader import load_scene

        if not isinstance(scene, Scene):
            scene = load_scene(scene)
        if not scene.bodies and scene.particles is None:
            # the loader refuses such a scene; one built in Python is checked here
            # (a run has a trajectory or particles: Run, _every)
            raise SceneError("a scene needs at least one [[body]] or a [particles] table",
                             scene.path, "body")
        self.scene = scene
        self.every = every
        self.meshes = body_meshes(scene)
        self.masses = np.array([b.mass for b in scene.bodies])
        self.run: Run | None = None
        self.frame = 0
        self.playing = play
        self.speed = 1.0
        self.error = ""
        self._clock = 0.0                     # simulated time of the player
        self._lock = threading.RLock()
        self._finished = threading.Condition(self._lock)
        self._draw_lock = threading.Lock()    # one drawer at a time (player, callbacks)
        self._generation = 0                  # the latest requested run
        self._finished_generation = 0         # the latest run shown
        self._contacts: dict[int, list] = {}  # frame -> contacting triangles (this run)
        self._hit_key: tuple = ()
        self._contact_key: tuple[int, int] | None = None   # (run, frame) of the contacts drawn
        self._stop = threading.Event()
        self._workers: list[threading.Thread] = []
        name = scene.path.name if scene.path is not None else "scene"
        self.server = start_server(host, port, label=f"refsim: {name}")
        self.url = url(self.server)
        try:
            self._build_scene()
            self._build_gui()
            self._player = threading.Thread(target=self._play_loop, name="refsim-player",
                                            daemon=True)
            self._player.start()
            self.rerun()
        except BaseException:
            self.close()
            raise

    # -- the scene ------------------------------------------------------------------

    def _build_scene(self) -> None:
        s = self.server.scene
        H = self.scene.world.half_size
        draw.place_camera(self.server.initial_camera, 2.0 * H, 2.0 * H, pan=draw.PANEL_PAN)
        self.cube = draw.add_cube(s, "/world/cube", H)
        self.bodies = []
        for b, (cfg, mesh) in enumerate(zip(self.scene.bodies, self.meshes, strict=True)):
            handle = draw.add_body(s, f"/bodies/{cfg.name}", mesh, draw.color(b))
            draw.set_pose(handle, np.array(cfg.orientation), np.array(cfg.position))
            self.bodies.append(handle)
        self.boxes = None
        self.contact_node = None
        self.normal_node = self.impulse_node = None
        self.points = None
        if self.scene.particles is not None:
            x, _ = self.scene.particles.initial_state()
            self.points = s.add_point_cloud("/particles", x.astype(np.float32), draw.color(0),
                                            point_size=PARTICLE_SIZE, point_shape="circle")

    # -- the controls ---------------------------------------------------------------

    def _build_gui(self) -> None:
        gui = self.server.gui
        bodies = bool(self.scene.bodies)
        with gui.add_folder("Playback"):
            self.play_button = gui.add_button("Pause" if self.playing else "Play")
            self.step_buttons = gui.add_button_group("Step", ("Back", "Forward"))
            self.frame_slider = gui.add_slider("Frame", 0, 1, 1, 0)
            self.speed_menu = gui.add_dropdown("Speed", SPEEDS, initial_value="1x")
            self.readout = gui.add_markdown("t = 0 s")
        with gui.add_folder("Simulation"):
            options = scene_options(self.scene)
            self.controls = {}
            for name, label in CONTROL_LABELS.items():
                only_bodies = name not in ("solver", "step")
                if name == "step":
                    handle = gui.add_number(label, options[name], min=1e-6, step=1e-5)
                else:
                    handle = gui.add_dropdown(label, OPTIONS[name], initial_value=options[name],
                                              disabled=only_bodies and not bodies)
                handle.on_update(self._control_changed(name))
                self.controls[name] = handle
            self.rerun_button = gui.add_button("Re-run")
            self.progress = gui.add_progress_bar(0.0)
            self.status = gui.add_markdown("starting")
        with gui.add_folder("Overlays"):
            self.show_cube = gui.add_checkbox("World cube", True)
            self.show_boxes = gui.add_checkbox("Boxes (AABB)", False, disabled=not bodies)
            self.show_contacts = gui.add_checkbox("Contacting triangles", bodies,
                                                  disabled=not bodies)
            self.show_hits = gui.add_checkbox("Wall hits: normal, impulse", bodies,
                                              disabled=not bodies)
            self.show_energy = gui.add_checkbox("Energy chart", bodies, disabled=not bodies)
        # particles have no energy chart: no folder for it either (an empty box)
        self.energy_folder = gui.add_folder("Energy (J)", visible=bodies)
        with self.energy_folder:
            self.chart = gui.add_uplot(
                (np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2)),
                ({"label": "t (s)"},
                 {"label": "kinetic", "stroke": "#0072b2", "width": 1.5},
                 {"label": "potential", "stroke": "#009e73", "width": 1.5},
                 {"label": "rotational", "stroke": "#d55e00", "width": 1.5},
                 {"label": "total", "stroke": "#333333", "width": 2.0}),
                scales={"x": {"time": False}}, aspect=1.6, visible=bodies)

        self.play_button.on_click(lambda _: self.pause() if self.playing else self.play())
        self.step_buttons.on_click(
            lambda event: self.step(-1 if event.target.value == "Back" else 1))
        self.frame_slider.on_update(self._slider_moved)
        self.speed_menu.on_update(
            lambda event: setattr(self, "speed", float(event.target.value.rstrip("x"))))
        self.rerun_button.on_click(lambda _: self._request({}))
        self.show_cube.on_update(lambda event: setattr(self.cube, "visible",
                                                       event.target.value))
        for box in (self.show_boxes, self.show_contacts, self.show_hits):
            box.on_update(lambda _: self.show_frame(self.frame))
        self.show_energy.on_update(lambda event: setattr(self.energy_folder, "visible",
                                                         event.target.value))

    def _control_changed(self, name: str):
        def changed(event) -> None:
            if event.client is None:            # set from Python (a run finishing): no re-run
                return
            self._request({name: event.target.value})
        return changed

    def _slider_moved(self, event) -> None:
        if event.client is None:                # the player moved it
            return
        self.pause()
        self.show_frame(int(event.target.value))

    def _request(self, change: dict) -> None:
        """A control asked for a run: start it, or say why not on the page."""
        options = {name: handle.value for name, handle in self.controls.items()}
        options.update(change)
        try:
            self.rerun(**options)
        except RefsimError as exc:
            self.error = str(exc)
            self.status.content = f"**not run**: {exc}"

    # -- runs -----------------------------------------------------------------------

    def rerun(self, **options) -> int:
        """Start a run of the scene with ``options`` changed (solver, step,
        level, aabb, rotation, body_response; see
        :func:`refsim.viewer.overlays.scene_with`); the current run goes on
        playing until it finishes. Returns the run's number, for
        :meth:`wait`. Raises SceneError or OptionError for a bad option."""
        scene = scene_with(self.scene, **options)
        with self._lock:
            self._generation += 1
            generation = self._generation
        self.error = ""
        self.status.content = "running..."
        self.progress.value = 0.0
        self.progress.animated = True
        worker = threading.Thread(target=self._work, args=(generation, scene),
                                  name=f"refsim-run-{generation}", daemon=True)
        self._workers = [w for w in self._workers if w.is_alive()] + [worker]
        worker.start()
        return generation

    def wait(self, generation: int | None = None, timeout: float = 60.0) -> Run:
        """Block until run ``generation`` (default: the latest requested) is
        shown; TimeoutError after ``timeout`` seconds, RefsimError when the
        viewer is closed before it is shown."""
        with self._finished:
            target = self._generation if generation is None else generation
            if not self._finished.wait_for(
                    lambda: self._finished_generation >= target or self._stop.is_set(),
                    timeout):
                raise TimeoutError(f"run {target} not finished after {timeout} s")
            if self._finished_generation < target or self.run is None:
                raise RefsimError(f"the viewer was closed before run {target} was shown")
            return self.run

    def _work(self, generation: int, scene) -> None:
        try:
            self._run_and_show(generation, scene)
        except Exception:
            if self._stop.is_set():        # closed mid-run: the page is gone, nothing to say
                return
            raise

    def _run_and_show(self, generation: int, scene) -> None:
        def cancelled() -> bool:
            return self._generation != generation or self._stop.is_set()

        last = [0.0]

        def progress(fraction: float) -> None:
            now = time.perf_counter()
            if now - last[0] >= PROGRESS_INTERVAL and not cancelled():
                last[0] = now
                self.progress.value = round(100.0 * fraction, 1)

        start = time.perf_counter()
        try:
            run = self._simulate(generation, scene, progress, cancelled)
        except Cancelled:
            return
        except RefsimError as exc:
            if not cancelled():
                self.error = str(exc)
                self.status.content = f"**failed**: {exc}"
                self.progress.animated = False
            return
        run.seconds = time.perf_counter() - start
        with self._lock:
            if cancelled():
                return
            self.scene = scene
            self.run = run
            self._contacts = {}
            self._clock = 0.0
            self.frame = 0
            self._finished_generation = generation
        self._show_run(run)
        with self._finished:
            self._finished.notify_all()

    def _simulate(self, generation: int, scene, progress, cancelled) -> Run:
        """The run of ``scene`` with everything its overlays need."""
        run = Run(scene=scene, generation=generation, t=np.zeros(1))
        if scene.bodies:
            try:
                traj = run_bodies(scene, every=self.every, progress=progress,
                                  cancelled=cancelled)
            except DivergenceError as exc:
                traj = exc.partial
                run.note = f"diverged at step {exc.step} (t = {exc.time:.6g} s)"
            run.trajectory = traj
            run.t = traj.t
            run.boxes = body_boxes(self.meshes, traj)
            run.energy = energy_per_frame(scene, traj)
            run.hits = wall_hits(self.meshes, traj, self.masses, scene.world.gravity,
                                 scene.world.half_size)
        if scene.particles is not None:
            try:
                run.particles = run_particles(scene, every=self.every, progress=progress,
                                              cancelled=cancelled)
            except DivergenceError as exc:
                raise RefsimError(f"the particles diverged at step {exc.step} "
                                  f"(t = {exc.time:.6g} s)") from None
            if not scene.bodies:
                run.t = run.particles.t
        return run

    def _show_run(self, run: Run) -> None:
        """A finished run on the page: controls, slider, chart, status."""
        for name, value in scene_options(run.scene).items():
            self.controls[name].value = value
        self.frame_slider.max = max(run.n_frames - 1, 1)
        self.progress.value = 100.0
        self.progress.animated = False
        if run.energy is not None:
            e = run.energy
            self.chart.data = (e.t, e.kinetic, e.potential, e.rotational, e.total)
        s = run.scene
        what = (f"{s.integration.solver}, h = {s.integration.step:g} s, {run.n_frames} frames"
                f" (every {self._every(run)} steps), {run.seconds:.2f} s to run")
        self.status.content = (f"run {run.generation}: {what}"
                               + (f"  \n**{run.note}**" if run.note else ""))
        self.show_frame(0)

    @staticmethod
    def _every(run: Run) -> int:
        if run.trajectory is not None:
            return int(run.trajectory.settings.get("every", 1))
        assert run.particles is not None, "a scene has bodies or particles (Viewer checks)"
        return run.particles.every

    # -- playback -------------------------------------------------------------------

    def play(self) -> None:
        with self._lock:
            self.playing = True
        self.play_button.label = "Pause"

    def pause(self) -> None:
        with self._lock:
            self.playing = False
        self.play_button.label = "Play"

    def step(self, frames: int = 1) -> None:
        """Pause and move ``frames`` frames (negative: back)."""
        self.pause()
        self.show_frame(self.frame + frames)

    def show_frame(self, k: int) -> int:
        """Draw frame ``k`` (clipped to the run) and return it."""
        with self._lock:
            run = self.run
            if run is None:
                return 0
            k = int(min(max(k, 0), run.n_frames - 1))
            self.frame = k
            self._clock = float(run.t[k])
        with self._draw_lock, self.server.atomic():
            self._draw(run, k)
        return k

    def _draw(self, run: Run, k: int) -> None:
        traj = run.trajectory
        if traj is not None:
            assert run.boxes is not None and run.hits is not None, \
                "set with the trajectory (_simulate)"
            R, x = traj.orientation[k], traj.position[k]
            for b, handle in enumerate(self.bodies):
                draw.set_pose(handle, R[b], x[b])
            self._draw_boxes(run.boxes[k])
            self._draw_contacts(run.generation, traj, k)
            self._draw_hits(run, run.hits, k)
        if run.particles is not None:
            f = min(int(np.searchsorted(run.particles.t, run.t[k] - 1e-12)),
                    len(run.particles.t) - 1)
            assert self.points is not None, "made by _build_scene for a scene with particles"
            self.points.points = run.particles.position[f]
        self.frame_slider.value = k
        text = f"t = {run.t[k]:.4g} s, frame {k} of {run.n_frames - 1}"
        if run.energy is not None:
            text += f"  \nE = {run.energy.total[k]:.6g} J"
        self.readout.content = text

    def _draw_boxes(self, boxes: np.ndarray) -> None:
        """The bodies' boxes of one frame, (B, 2, 3)."""
        if not self.show_boxes.value:
            if self.boxes is not None:
                self.boxes.visible = False
            return
        if self.boxes is None:
            self.boxes = draw.add_boxes(self.server.scene, "/overlays/boxes", boxes)
        else:
            self.boxes.points = draw.boxes_segments(boxes).astype(np.float32)
            self.boxes.visible = True

    def contacts(self, k: int) -> list:
        """The contacting triangle pairs at frame ``k`` of the run shown
        (computed on first use, then cached for the run)."""
        with self._lock:
            run = self.run
            cached = self._contacts.get(k)
        if cached is not None or run is None or run.trajectory is None:
            return cached or []
        assert run.boxes is not None, "set with the trajectory (_simulate)"
        found = contacting_triangles(self.meshes, run.trajectory, k, run.boxes[k])
        with self._lock:
            if self.run is run:
                self._contacts[k] = found
        return found

    def _draw_contacts(self, generation: int, traj: Trajectory, k: int) -> None:
        found = self.contacts(k) if self.show_contacts.value else []
        key = (generation, k) if found else None
        if key == self._contact_key:
            return
        self._contact_key = key
        if self.contact_node is not None:
            self.contact_node.remove()
            self.contact_node = None
        if found:
            vertices, faces = draw.contact_mesh(self.meshes, traj.orientation[k],
                                                traj.position[k], found)
            self.contact_node = self.server.scene.add_mesh_simple(
                "/overlays/contacts", vertices, faces, color=draw.CONTACT_COLOR,
                side="double", flat_shading=True)

    def _draw_hits(self, run: Run, run_hits: list[WallHit], k: int) -> None:
        t = run.t[k]
        hits = [h for h in run_hits if h.time <= t + 1e-12 and t - h.time <= HIT_SECONDS] \
            if self.show_hits.value else []
        key = (run.generation, tuple((h.frame, h.body, h.wall) for h in hits))
        if key == self._hit_key:
            return
        self._hit_key = key
        for node in (self.normal_node, self.impulse_node):
            if node is not None:
                node.remove()
        self.normal_node = self.impulse_node = None
        if hits:
            H = run.scene.world.half_size
            normals, impulses = draw.hit_arrows(hits, self.masses, H)
            self.normal_node = draw.add_arrows(self.server.scene, "/overlays/wall-normals",
                                               normals, draw.NORMAL_COLOR)
            self.impulse_node = draw.add_arrows(self.server.scene, "/overlays/wall-impulses",
                                                impulses, draw.IMPULSE_COLOR)

    def _play_loop(self) -> None:
        last = time.perf_counter()
        while not self._stop.wait(TICK):
            now = time.perf_counter()
            elapsed, last = now - last, now
            with self._lock:
                run = self.run
                if not self.playing or run is None or run.n_frames < 2:
                    continue
                self._clock += elapsed * self.speed
                if self._clock > run.t[-1]:
                    self._clock = 0.0                      # loop
                k = int(np.searchsorted(run.t, self._clock, side="right")) - 1
                clock = self._clock
            if k != self.frame:
                self.show_frame(k)
                with self._lock:
                    self._clock = clock      # show_frame snaps the clock to the frame
            # (a frame drawn more slowly than TICK makes playback slower, never jumpy)

    # -- lifetime -------------------------------------------------------------------

    def close(self) -> None:
        """Stop the player, any run and the server.

        A run stops at its next chunk of steps; the threads are given
        ``CLOSE_SECONDS`` to finish before the server stops, so that none
        of them sends to a closed page (they are daemons: a straggler never
        keeps the process alive)."""
        self._stop.set()
        with self._finished:
            self._finished.notify_all()
        deadline = time.monotonic() + CLOSE_SECONDS
        for thread in [getattr(self, "_player", None), *self._workers]:
            if thread is not None and thread is not threading.current_thread():
                thread.join(max(0.0, deadline - time.monotonic()))
        stop_server(self.server)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _repr_html_(self) -> str:
        return (f'<iframe src="{self.url}" width="100%" height="600" '
                f'style="border: 0"></iframe>')


def view(scene, *, host: str = LOCAL_HOST, port: int = 0, every: int | None = None,
         play: bool = True) -> Viewer:
    """Serve ``scene`` (a refsim.Scene or a scene file) in the browser and
    return the :class:`Viewer` at once (it runs in background threads; in a
    notebook it displays as the page itself). Prints the address.
    ``viewer.close()`` stops it."""
    viewer = Viewer(scene, host=host, port=port, every=every, play=play)
    print(f"refsim view: {viewer.url}")
    return viewer


def serve(scene, *, host: str = LOCAL_HOST, port: int = 8080, every: int | None = None) -> None:
    """``refsim view``: serve until interrupted (KeyboardInterrupt propagates,
    after the server is stopped)."""
    import logging

    # A connection that is not a browser's (a port probe, a client gone mid
    # handshake) is the client's business: the websockets library would log
    # it with a traceback on the command line's stderr.
    logging.getLogger("websockets.server").setLevel(logging.CRITICAL)
    viewer = Viewer(scene, host=host, port=port, every=every)
    try:
        print(f"refsim view: {viewer.url} (Ctrl-C stops)", flush=True)
        while True:
            time.sleep(3600)
    finally:
        viewer.close()
