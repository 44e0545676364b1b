"""The viewer and a replay in a real browser: Debian's headless Chromium
(chromium and chromium-driver; .ci/run installs them), WebGL by SwiftShader,
with the network closed (a proxy to nowhere, every host name unresolvable but
127.0.0.1, where the live viewer serves).

What a person would check: the page connects and draws the scene (the 3D
canvas is not one colour); two frames look different and going back to the
first gives the same pixels; choosing a control re-runs the simulation on
the server; the console has no SEVERE entry; the replay file draws from
``file://`` without a single network request.

The canvas is read with ``toDataURL`` (viser keeps its drawing buffer), so
the GUI panel over it never enters a comparison.
"""

from __future__ import annotations

import base64
import io
import os
import shutil
import time
from dataclasses import replace

import numpy as np
import pytest

import refsim

CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")

pytestmark = pytest.mark.skipif(
    not (CHROMIUM and CHROMEDRIVER),
    reason="Debian packages chromium and chromium-driver are not installed "
           "(.ci/run installs them: apt-get install chromium chromium-driver)")

#: Bound on every wait for the page (s): SwiftShader on a busy 2-core machine
#: takes a few seconds for the first frame.
WAIT = 30.0

#: Between two looks at the canvas (s).
POLL = 0.25

#: The largest canvas on the page (viser's 3D view; uPlot draws a smaller one).
CANVAS_PNG = """
const c = Array.from(document.querySelectorAll('canvas'))
  .sort((a, b) => b.width * b.height - a.width * a.height)[0];
return c ? c.toDataURL('image/png') : null;
"""


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    os.environ.setdefault("SE_OFFLINE", "true")      # never let selenium fetch a driver
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader",
                 "--disable-background-networking", "--disable-component-update",
                 "--no-first-run", "--disable-sync",
                 f"--user-data-dir={tmp_path_factory.mktemp('chromium-profile')}",
                 "--window-size=1280,800",
                 # the network closed: a proxy that refuses, and no name resolves
                 "--proxy-server=127.0.0.1:9",
                 "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    driver.set_page_load_timeout(WAIT)
    driver.set_script_timeout(WAIT)
    driver.console = []                               # every console entry seen so far
    yield driver
    driver.quit()


def _console(driver) -> list[dict]:
    driver.console.extend(driver.get_log("browser"))
    return driver.console


def _canvas(driver) -> np.ndarray | None:
    """The 3D canvas's pixels (h, w, 4), or None before it exists."""
    from PIL import Image

    url = driver.execute_script(CANVAS_PNG)
    if not url:
        return None
    png = base64.b64decode(url.split(",", 1)[1])
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))


def _is_blank(pixels) -> bool:
    return pixels is None or pixels.size == 0 or bool((pixels == pixels[0, 0]).all())


def _wait_for(driver, test, what: str, *, settled: bool = True) -> np.ndarray:
    """Poll the canvas until ``test(pixels)`` holds, for two looks in a row
    when ``settled`` (the drawing has settled; a replay that plays never
    settles); AssertionError naming ``what`` after WAIT."""
    deadline = time.monotonic() + WAIT
    last = None
    while time.monotonic() < deadline:
        pixels = _canvas(driver)
        if pixels is not None and test(pixels):
            if not settled or (last is not None and np.array_equal(pixels, last)):
                return pixels
            last = pixels
        else:
            last = None
        time.sleep(POLL)
    raise AssertionError(f"the canvas did not show {what} within {WAIT} s")


# -- the live viewer ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def viewer():
    from refsim.viewer.live import Viewer

    scene = refsim.load_scene("spinning-cube.toml")
    scene = replace(scene, integration=replace(scene.integration, duration=1.2))
    with Viewer(scene, play=False) as v:
        v.wait(timeout=WAIT)
        yield v


@pytest.fixture
def page(browser, viewer):
    """The browser on the viewer's page, the scene drawn."""
    if not browser.current_url.startswith(viewer.url):
        browser.get(viewer.url)
    _wait_for(browser, lambda p: not _is_blank(p), "the scene")
    return browser


def test_live_page_connects_and_draws(page, viewer):
    pixels = _canvas(page)
    assert not _is_blank(pixels)
    assert pixels.shape[0] > 300 and pixels.shape[1] > 300
    assert len(viewer.server.get_clients()) >= 1           # the page's websocket connected


def test_two_frames_differ_and_going_back_gives_the_same_pixels(page, viewer):
    k, k2 = 0, viewer.run.n_frames // 2
    viewer.show_frame(k)
    first = _wait_for(page, lambda p: not _is_blank(p), f"frame {k}")
    viewer.show_frame(k2)
    second = _wait_for(page, lambda p: not np.array_equal(p, first), f"frame {k2}")
    assert not np.array_equal(first, second)
    viewer.show_frame(k)
    again = _wait_for(page, lambda p: np.array_equal(p, first), f"frame {k} again")
    assert np.array_equal(again, first)


def test_choosing_a_control_reruns_the_simulation(page, viewer):
    from selenium.webdriver.common.by import By

    generation = viewer._generation
    runs_before = viewer.run
    rotation = "seed" if viewer.scene.dynamics.rotation == "impulse" else "impulse"
    label = page.find_element(By.XPATH, "//label[normalize-space(text())='Rotation']")
    page.find_element(By.ID, label.get_attribute("for")).click()
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        options = [o for o in page.find_elements(By.XPATH, "//*[@role='option']")
                   if o.text == rotation]
        if options:
            options[0].click()
            break
        time.sleep(POLL)
    else:
        raise AssertionError("the Rotation menu did not open")
    run = viewer.wait(generation + 1, timeout=WAIT)     # the callback started a run
    assert viewer._generation == generation + 1
    assert run is not runs_before and run.generation == generation + 1
    assert run.trajectory.settings["rotation"] == rotation == viewer.scene.dynamics.rotation
    assert viewer.controls["rotation"].value == rotation


def test_no_severe_console_entry(page, viewer):
    viewer.show_frame(viewer.run.n_frames - 1)
    _wait_for(page, lambda p: not _is_blank(p), "the last frame")
    severe = [e for e in _console(page) if e["level"] == "SEVERE"]
    assert severe == []


# -- a replay file -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def replay_file(tmp_path_factory):
    from refsim.viewer.replay import run_from_scene, write_replay

    runs = []
    for model in ("seed", "impulse"):
        scene = refsim.load_scene("spinning-cube.toml")
        scene = replace(scene, integration=replace(scene.integration, duration=0.6),
                        dynamics=replace(scene.dynamics, rotation=model))
        runs.append(run_from_scene(model, scene, refsim.simulate(scene)))
    return write_replay(runs, tmp_path_factory.mktemp("replay") / "replay.html").path


def test_replay_draws_from_file_without_the_network(browser, replay_file):
    browser.get(replay_file.as_uri())
    _wait_for(browser, lambda p: not _is_blank(p), "the replay", settled=False)
    resources = browser.execute_script(
        "return performance.getEntriesByType('resource').map(e => e.name);")
    assert [r for r in resources if not r.startswith(("data:", "blob:"))] == []
    assert browser.execute_script("return performance.getEntriesByType('navigation')"
                                  ".map(e => e.name);") == [replay_file.as_uri()]
    panel = browser.execute_script(
        "return document.getElementById('refsim-replay').innerText;")
    assert "impulse" in panel and "rk4" in panel
    severe = [e for e in _console(browser) if e["level"] == "SEVERE"]
    assert severe == []


#: The size of the iframe the report embeds a replay in (CSS pixels).
IFRAME_SIZE = (900, 600)

#: The size (CSS pixels) and the URL of the largest canvas of the page.
CANVAS_BOX = """
const c = Array.from(document.querySelectorAll('canvas'))
  .sort((a, b) => b.width * b.height - a.width * a.height)[0];
const r = c.getBoundingClientRect();
return [r.width, r.height, document.location.href];
"""


def test_replay_plays_inside_an_iframe(browser, replay_file, tmp_path):
    """As the report shows it: in an iframe the replay fills the frame,
    draws, plays (the canvas changes by itself) and shows its panel."""
    width, height = IFRAME_SIZE
    host = tmp_path / "host.html"
    host.write_text(f'<!doctype html><html><body style="margin:0">'
                    f'<iframe id="r" src="{replay_file.as_uri()}" width="{width}" '
                    f'height="{height}"></iframe></body></html>')
    browser.get(host.as_uri())
    frame = browser.find_element("id", "r")
    assert browser.execute_script("return [arguments[0].clientWidth, arguments[0].clientHeight];",
                                  frame) == [width, height]             # inside its border
    browser.switch_to.frame(frame)
    try:
        first = _wait_for(browser, lambda p: not _is_blank(p), "the replay in an iframe",
                          settled=False)
        w, h, url = browser.execute_script(CANVAS_BOX)
        assert url == replay_file.as_uri()
        assert 0.5 * width <= w <= width and 0.5 * height <= h <= height
        later = _wait_for(browser, lambda p: not _is_blank(p) and not np.array_equal(p, first),
                          "the replay playing on", settled=False)
        assert not np.array_equal(later, first)
        panel = browser.execute_script(
            "return document.getElementById('refsim-replay').innerText;")
        assert "refsim replay" in panel and "2 runs side by side" in panel
        assert "seed" in panel and "impulse" in panel
    finally:
        browser.switch_to.default_content()
    severe = [e for e in _console(browser) if e["level"] == "SEVERE"]
    assert severe == []
