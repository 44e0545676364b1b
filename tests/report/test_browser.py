"""The report in a real browser: headless Chromium (Debian's chromium and
chromium-driver; .ci/run installs them) opens the page, and we check what a
reader would see: no console errors, no broken images, every chart drawn
with a non-zero size. A full-page screenshot is saved for a person to read.
"""

from __future__ import annotations

import os
import shutil

import pytest

CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")

pytestmark = pytest.mark.skipif(
    not (CHROMIUM and CHROMEDRIVER),
    reason="Debian packages chromium and chromium-driver are not installed "
           "(.ci/run installs them: apt-get install chromium chromium-driver)")

#: Width of the browser window: a laptop screen.
WINDOW_WIDTH = 1280


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    os.environ.setdefault("SE_OFFLINE", "true")      # never let selenium fetch a driver
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # The flags this machine needs: no sandbox as root, and no background
    # networking (the network is closed; Chromium would retry for ever).
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={tmp_path_factory.mktemp('chromium-profile')}",
                 f"--window-size={WINDOW_WIDTH},900"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    yield driver
    driver.quit()


@pytest.fixture(scope="module")
def opened(browser, quick_report):
    out, _, results = quick_report
    browser.get((out / "index.html").as_uri())
    return browser, out, results


def test_no_console_errors(opened):
    browser, _, _ = opened
    severe = [entry for entry in browser.get_log("browser") if entry["level"] == "SEVERE"]
    assert severe == []


BROKEN_IMAGES = ("return Array.from(document.images)"
                 ".filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src);")


def test_no_broken_images(opened):
    browser, _, _ = opened
    # The page's charts are inline SVG, so it has no <img> today; the check
    # guards against one being added. First prove it catches a broken one.
    browser.execute_async_script(
        "const done = arguments[0]; const img = document.createElement('img');"
        "img.id = 'probe'; img.onerror = () => done(); img.onload = () => done();"
        "img.src = 'no-such-image.png'; document.body.appendChild(img);")
    assert [src.rsplit("/", 1)[-1] for src in browser.execute_script(BROKEN_IMAGES)] == \
        ["no-such-image.png"]
    browser.execute_script("document.getElementById('probe').remove();")
    assert browser.execute_script(BROKEN_IMAGES) == []


def test_every_chart_is_drawn_with_a_size(opened):
    browser, _, _ = opened
    sizes = browser.execute_script(
        "return Array.from(document.querySelectorAll('figure:not(.replay)')).map(f => {"
        "  const s = f.querySelector('svg');"
        "  const r = s ? s.getBoundingClientRect() : {width: 0, height: 0};"
        "  return [f.id, r.width, r.height]; });")
    assert sizes, "the page has no charts"
    for figure_id, width, height in sizes:
        assert width > 100 and height > 50, figure_id
    # every chart fits the window: nothing forces a sideways scroll
    page_width = browser.execute_script("return document.documentElement.scrollWidth;")
    assert page_width <= WINDOW_WIDTH


def test_every_replay_has_a_frame_with_a_size(opened):
    """The replays (iframes of pages beside the report) are laid out where
    they are shown, each frame at least a readable size."""
    browser, _, results = opened
    written = [r for r in results["sections"]["dynamics"]["results"]["replays"]
               if r["status"] == "written"]
    sizes = browser.execute_script(
        "return Array.from(document.querySelectorAll('figure.replay iframe')).map(f => {"
        "  const r = f.getBoundingClientRect();"
        "  return [f.getAttribute('src'), r.width, r.height]; });")
    assert sorted(src for src, _, _ in sizes) == sorted(r["file"] for r in written)
    for src, width, height in sizes:
        assert width > 400 and height > 300, src


def test_every_section_is_visible(opened):
    browser, _, results = opened
    for key in results["sections"]:
        height = browser.execute_script(
            f"return document.getElementById('{key}').getBoundingClientRect().height;")
        assert height > 0, key


def test_screenshot(opened, tmp_path_factory):
    browser, out, _ = opened
    height = browser.execute_script("return document.documentElement.scrollHeight;")
    browser.set_window_size(WINDOW_WIDTH, min(height, 16000))
    shot = out / "screenshot.png"
    assert browser.save_screenshot(str(shot))
    assert shot.stat().st_size > 10_000
    with open(shot, "rb") as handle:
        assert handle.read(8) == b"\x89PNG\r\n\x1a\n"
