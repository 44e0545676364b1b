"""``refsim info`` and ``refsim run``: facts about model files, and a
scene simulated with its frames written as they are computed."""

from __future__ import annotations

import contextlib
import json
import sys
from dataclasses import asdict
from pathlib import Path

from refsim.cli.common import max_steps_option, output_file, with_duration, write_output
from refsim.errors import DivergenceError, RefsimError, SceneError
from refsim.kernels import notices_on


def info_command(args) -> int:
    from refsim.errors import OptionError
    from refsim.models.facts import describe, format_facts
    from refsim.models.loading import load_model

    if args.bundled:
        if args.models:
            raise OptionError("--bundled lists the bundled models and scenes; give it "
                              "without MODEL files")
        from refsim.bundled import bundled_models, bundled_scenes

        for path in (*bundled_models(), *bundled_scenes()):
            print(path.name)
        return 0
    if not args.models:
        raise OptionError("give one or more MODEL files, or --bundled to list the bundled "
                          "models and scenes (see refsim info --help)")
    for i, path in enumerate(args.models):
        if i:
            print()
        print(format_facts(describe(load_model(path), name=str(path))))
    return 0


def _settings(scene, every: int) -> dict:
    """The scene's settings as written into the .npz (entry ``scene``, JSON)."""
    from refsim import __version__

    return {
        "scene": None if scene.path is None else str(scene.path),
        "world": asdict(scene.world),
        "integration": asdict(scene.integration),
        "particles": asdict(scene.particles),
        "every": every,
        "refsim": __version__,
    }


def run_command(args) -> int:
    from refsim.scenes.loader import load_scene_text

    if args.output:
        output_file(args.output, (".npz",), "run")
    max_steps = max_steps_option(args)
    scene, text = load_scene_text(args.scene, max_steps=max_steps)
    if args.duration is not None:
        scene = with_duration(scene, args.duration, max_steps)
    if scene.bodies and scene.particles is not None:
        raise SceneError("refsim run simulates either rigid bodies or particles; this scene "
                         "has both (split it in two)", scene.path, "particles")
    if args.every is not None and args.every < 1:
        raise RefsimError(f"--every must be at least 1, got {args.every}")
    out = Path(args.output) if args.output else Path(Path(args.scene).stem + ".npz")
    if not out.parent.is_dir():
        raise RefsimError(f"{out}: cannot write: no directory {out.parent}")
    if scene.bodies:
        return _run_bodies(scene, text, out, args.every)
    return _run_particles(scene, out, args.every)


#: ``refsim run`` shows its progress line only once it has run this long (s):
#: a short run prints its one closing line and nothing else.
RUN_PROGRESS_DELAY = 2.0


@contextlib.contextmanager
def _frame_progress(n_steps: int, every: int, sink):
    """``sink`` wrapped so that a long run shows its frames so far on stderr
    (redrawn on a terminal after ``RUN_PROGRESS_DELAY``; elsewhere a line
    every ten seconds once it has run that long: never silent)."""
    from refsim.storage.frames import CountedSink, frame_count
    from refsim.sweep.progress import Progress

    progress = Progress(frame_count(n_steps, every), label="refsim run", unit="frames",
                        delay=RUN_PROGRESS_DELAY)
    try:
        yield CountedSink(sink, progress)
    finally:
        progress.close()


def _run_bodies(scene, text: str, out: Path, every: int | None) -> int:
    """Rigid bodies: ``refsim.simulate`` with the frames spilled beside
    ``out`` as they are computed (:class:`refsim.storage.frames.SpillSink`: memory
    does not grow with the steps), then written as a Trajectory (.npz) whose
    settings record the scene: its file and its ``text``, from which
    ``refsim replay`` rebuilds the meshes."""
    from refsim.dynamics.simulate import default_every, simulate
    from refsim.dynamics.start import start_kernel
    from refsim.storage.frames import SpillSink, check_disk_space
    from refsim.storage.writing import output_target
    from refsim.viewer.replay import recorded_scene_settings

    output_target(out)                  # a FIFO, device or directory: refused before running
    B = len(scene.bodies)
    n_steps = scene.integration.n_steps
    # t, then position, velocity, angular_velocity (B, 3) and orientation (B, 3, 3)
    check_disk_space(out, [8, 24 * B, 24 * B, 24 * B, 72 * B], n_steps,
                     default_every(n_steps) if every is None else every, compressed=True,
                     frames_of=f"{B} {'body' if B == 1 else 'bodies'}",
                     size_hint=f"{scene.path}: fewer [[body]] tables")
    kernel = start_kernel(scene, n_steps)
    if kernel is not None and notices_on():
        print("refsim: numba has not compiled the simulation loop on this machine yet; "
              "this run takes less on the readable kernels than the compile would "
              "(the same results, bit for bit)", file=sys.stderr, flush=True)
    every = default_every(n_steps) if every is None else every
    with SpillSink(out) as spill, _frame_progress(n_steps, every, spill) as sink:
        try:
            trajectory = simulate(scene, every=every, sink=sink, kernel=kernel)
        except DivergenceError as exc:
            partial = exc.partial
            partial.settings.update(recorded_scene_settings(scene.path, text))
            write_output(out, partial.save)
            raise DivergenceError(
                f"{exc.message}; wrote the {partial.n_frames} frames before "
                f"it (t = 0 to {partial.t[-1]:.6g}) to {out}", step=exc.step, time=exc.time,
                body=exc.body) from None
        trajectory.settings.update(recorded_scene_settings(scene.path, text))
        write_output(out, trajectory.save)
        n_frames, t_end = trajectory.n_frames, float(trajectory.t[-1])
    ran = ", ".join(trajectory.stages)
    print(f"wrote {out}: {n_frames} frames of {B} {'body' if B == 1 else 'bodies'}, "
          f"t = 0 to {t_end:.6g} ({scene.integration.solver}, "
          f"h = {scene.integration.step:g}); stages: {ran}")
    return 0


def _run_particles(scene, out: Path, every: int | None) -> int:
    """Particles: :func:`refsim.particles.run.run_particles` with the frames
    spilled beside ``out`` as they are computed, then written as .npz
    (uncompressed: random floats do not compress, and it is faster)."""
    import numpy as np

    from refsim.particles.run import FRAME_BYTES_PER_PARTICLE, frame_stride, run_particles
    from refsim.storage.frames import SpillSink, check_disk_space
    from refsim.storage.writing import output_target, write_npz_atomic

    output_target(out)                  # a FIFO, device or directory: refused before running
    config = scene.particles
    n_steps, every = frame_stride(scene, every)
    N = config.count
    # t, step, then position and velocity (N, 3)
    check_disk_space(out, [8, 8, FRAME_BYTES_PER_PARTICLE // 2 * N,
                           FRAME_BYTES_PER_PARTICLE // 2 * N], n_steps, every,
                     compressed=False, frames_of=f"{N} particles",
                     size_hint=f"{scene.path}: particles.count")

    def save(frames, status: str):
        arrays = {"t": frames.t, "step": frames.step, "position": frames.position,
                  "velocity": frames.velocity,
                  "scene": np.array(json.dumps(_settings(scene, every), sort_keys=True)),
                  "status": np.array(status)}
        write_output(out, lambda path: write_npz_atomic(path, arrays))

    with SpillSink(out) as spill, _frame_progress(n_steps, every, spill) as sink:
        try:
            frames = run_particles(config, n_steps, every, sink=sink)
        except DivergenceError as exc:
            partial = exc.partial
            assert partial is not None, "run_particles keeps the frames before a divergence"
            save(partial, f"diverged at step {exc.step}, t = {exc.time:.6g}")
            raise DivergenceError(
                f"particle state is not finite; wrote the {len(partial.t)} frames before it "
                f"(t = 0 to {partial.t[-1]:.6g}) to {out}", step=exc.step,
                time=exc.time) from None
        save(frames, "complete")
        n_frames, t_end = len(frames.t), float(frames.t[-1])
    print(f"wrote {out}: {n_frames} frames of {config.count} particles, "
          f"t = 0 to {t_end:.6g} ({config.solver}, h = {config.step:g}, "
          f"every {every} steps)")
    return 0
