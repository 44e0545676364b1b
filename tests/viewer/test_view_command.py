"""``refsim view`` as a person meets it: one line with the address, one line
for a mistake (exit 2), a clean stop on Ctrl-C (exit 130), and the viewer's
server side: runs in a worker thread, frames, controls."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from dataclasses import replace

import numpy as np
import pytest

import refsim
from refsim.cli import main
from refsim.viewer.live import Viewer

#: Bound on waiting for the command to print its address or to stop (s):
#: start-up imports numpy, scipy, numba and viser on a busy 2-core machine.
START_TIMEOUT = 60.0


def _short(name: str, duration: float):
    scene = refsim.load_scene(name)
    return replace(scene, integration=replace(scene.integration, duration=duration))


def _one_line_error(capsys, argv, expected: str) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"refsim: error: {expected}\n" or (err.count("\n") == 1 and expected in err)
    assert "Traceback" not in err


def test_view_without_viser_says_what_to_install(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "viser", None)       # import viser -> ImportError
    _one_line_error(capsys, ["view", "bounce.toml"], "pip install 'refsim[viewer]'")


def test_view_refuses_a_port_in_use(capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        _one_line_error(capsys, ["view", "bounce.toml", "--port", str(port)],
                        f"port {port} is in use")


@pytest.mark.parametrize("argv, expected", [
    (["view", "no-such-scene.toml"], "no-such-scene.toml"),
    (["view", "bounce.toml", "--port", "70000"], "port must be a whole number from 0 to 65535"),
])
def test_view_mistakes_are_one_line(argv, expected, capsys):
    _one_line_error(capsys, argv, expected)


@pytest.mark.parametrize("scene, wait", [
    ("bounce.toml", 0.5),               # after its first run (0.4 s of simulation)
    ("spinning-cube.toml", 0.0),        # in the middle of its first run
])
def test_view_prints_its_address_and_stops_on_ctrl_c(scene, wait):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-m", "refsim.cli", "view", scene, "--port", "0"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = _read_line(proc, START_TIMEOUT)
        assert line.startswith("refsim view: http://127.0.0.1:"), line
        port = int(line.split(":")[3].split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10) as page:
            assert b"<html" in page.read(2000)                 # it serves the page
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass                          # a connection that never speaks HTTP: no traceback
        time.sleep(wait)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=START_TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130
    assert out == ""                                       # the address was the only line
    assert err == "refsim: interrupted\n"
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=2).close()   # stopped


def _read_line(proc, timeout: float) -> str:
    import selectors

    with selectors.DefaultSelector() as sel:
        sel.register(proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            raise AssertionError(f"no output from refsim view after {timeout} s")
    return proc.stdout.readline()


# -- the server side -------------------------------------------------------------------


@pytest.fixture(scope="module")
def viewer():
    # 1.2 s: the first wall hit (t = 1.048 s) and 1200 steps, a frame every 2
    with Viewer(_short("spinning-cube.toml", 1.2), play=False) as v:
        v.wait(timeout=START_TIMEOUT)
        yield v


def test_viewer_binds_to_this_machine(viewer):
    assert viewer.url.startswith("http://127.0.0.1:")
    assert viewer.server.get_host() == "127.0.0.1"


def test_first_run_fills_the_controls_and_overlays(viewer):
    run = viewer.run
    assert run.n_frames == 601 and run.trajectory.settings["rotation"] == "seed"
    assert run.boxes.shape == (601, 1, 2, 3)
    assert run.energy.total[0] == refsim.Simulation(viewer.scene).energy().sum()
    assert run.hits and run.hits[0].wall == "y-"
    assert viewer.frame_slider.max == 600
    assert viewer.controls["rotation"].value == "seed"
    assert "601 frames" in viewer.status.content


def test_show_frame_poses_the_bodies(viewer):
    k = viewer.show_frame(500)
    traj = viewer.run.trajectory
    assert k == viewer.frame == 500 and viewer.frame_slider.value == 500
    assert np.allclose(viewer.bodies[0].position, traj.position[500, 0])
    assert viewer.show_frame(5000) == 600 and viewer.show_frame(-3) == 0
    viewer.step(2)
    assert viewer.frame == 2 and not viewer.playing


def test_a_rerun_does_not_block_and_replaces_the_run(viewer):
    before = viewer.run
    generation = viewer.rerun(rotation="impulse", step=0.002)
    assert viewer.run is before                           # returned at once: a worker runs it
    run = viewer.wait(generation, timeout=START_TIMEOUT)
    assert run is not before and run.generation == generation
    assert run.trajectory.settings["rotation"] == "impulse"
    assert run.trajectory.settings["step"] == 0.002 and run.n_frames == 601
    assert viewer.controls["rotation"].value == "impulse"
    assert viewer.controls["step"].value == 0.002


def test_a_newer_request_cancels_the_older(viewer):
    first = viewer.rerun(rotation="seed", step=0.001)
    second = viewer.rerun(rotation="seed", step=0.0005)
    run = viewer.wait(second, timeout=START_TIMEOUT)
    assert run.generation == second > first
    assert run.trajectory.settings["step"] == 0.0005


def test_playing_advances_the_frames(viewer):
    viewer.show_frame(0)
    viewer.speed = 1.0
    viewer.play()
    try:
        time.sleep(0.6)
    finally:
        viewer.pause()
    t = viewer.run.t[viewer.frame]
    assert 0.1 < t < 1.2                  # about 0.6 s of simulated time at 1x
    assert viewer.play_button.label == "Play"


def test_the_page_stays_responsive_during_a_run(monkeypatch):
    # 6000 readable steps with the corrected rotation (the compiled loop
    # would finish them between two polls), so that the bar is seen moving
    from dataclasses import replace

    monkeypatch.setenv("REFSIM_KERNELS", "readable")

    scene = refsim.load_scene("spinning-cube.toml")
    scene = replace(scene, dynamics=replace(scene.dynamics, rotation="impulse"))
    with Viewer(scene, play=False) as v:
        progress = []
        while v._finished_generation < 1:
            v.frame_slider.value = 0                  # what a callback from the page does
            progress.append(v.progress.value)
            time.sleep(0.05)
        # this thread went on while the worker ran, and saw the bar move
        assert progress == sorted(progress)
        assert any(0.0 < p < 100.0 for p in progress)


def test_waiting_on_a_closed_viewer_says_so():
    # the run is cancelled by close(): wait() has no run to give (it gave None)
    with Viewer(refsim.load_scene("spinning-cube.toml"), play=False) as v:   # 6000 steps
        pass
    with pytest.raises(refsim.RefsimError, match="closed before run 1 was shown"):
        v.wait(timeout=START_TIMEOUT)


def test_a_scene_with_nothing_to_show_is_refused():
    # the loader refuses it; built in Python it got a server whose run failed
    # in its thread, and wait() then timed out
    with pytest.raises(refsim.SceneError, match=r"at least one \[\[body\]\]"):
        Viewer(refsim.Scene(path=None), play=False)


def test_a_bad_option_is_refused_before_running(viewer):
    with pytest.raises(refsim.RefsimError, match="integration.step"):
        viewer.rerun(step=0.0007)                         # 1.2 s is not whole steps of it


def test_particles_are_a_point_cloud():
    scene = refsim.load_scene("particles.toml")
    scene = replace(scene, integration=replace(scene.integration, duration=0.2),
                    particles=replace(scene.particles, count=200))
    with Viewer(scene, play=False) as v:
        run = v.wait(timeout=START_TIMEOUT)
        assert run.trajectory is None and run.particles.position.shape[1:] == (200, 3)
        v.show_frame(run.n_frames - 1)
        assert np.allclose(v.points.points, run.particles.position[-1], atol=1e-2)
        assert v.controls["rotation"].disabled and not v.controls["solver"].disabled
        # no energy for particles: neither the chart nor an empty box for it
        assert not v.energy_folder.visible and v.show_energy.disabled


def test_bodies_have_their_energy_chart_and_its_checkbox_hides_it(viewer):
    assert viewer.energy_folder.visible and viewer.show_energy.value
    viewer.show_energy.value = False
    try:
        assert not viewer.energy_folder.visible
    finally:
        viewer.show_energy.value = True
    assert viewer.energy_folder.visible


def test_overlays_at_a_contact_and_at_a_wall_hit():
    from refsim.studies.dynamics import c11_scene

    with Viewer(c11_scene("stack", "seed", duration=1.2), play=False, every=10) as v:
        run = v.wait(timeout=START_TIMEOUT)
        v.show_boxes.value = True
        sunk = [k for k in range(run.n_frames) if v.contacts(k)]
        assert sunk                                        # C11: the top body sinks in
        v.show_frame(sunk[len(sunk) // 2])
        found = v.contacts(v.frame)
        faces = sum(len(np.unique(f.pairs[:, 0])) + len(np.unique(f.pairs[:, 1]))
                    for f in found)
        assert v.contact_node is not None and len(v.contact_node.faces) == faces
        assert len(v.boxes.points) == 2 * 12               # two boxes, twelve edges each
        v.show_frame(0)
        assert v.contact_node is None                      # apart at the start
        hit = run.hits[0]                                  # the first wall hit
        v.show_frame(hit.frame)
        assert v.normal_node is not None and v.impulse_node is not None
        v.show_hits.value = False
        assert v.normal_node is None
