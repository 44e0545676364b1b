"""How long ``refsim view SCENE`` takes to show its first frame in a browser.

From the start of the command to the first canvas that is not one uniform
colour in headless Chromium (SwiftShader WebGL, as in the tests), with the
browser already open on a blank page; also when the address is printed, when
the page has loaded, and when the first run's status appears in the panel
(the scene simulated and ready to play). Each repeat starts a new
``refsim view`` process (a cold Python: imports, numba's cached kernels,
viser), then stops it with Ctrl-C (SIGINT) and checks the exit status 130.

    .venv/bin/python docs/decisions/viewer_first_frame.py [SCENE] [--repeat N]

Needs Debian's chromium and chromium-driver, and the viewer extra.
"""

from __future__ import annotations

import argparse
import base64
import io
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CANVAS_PNG = """
const c = Array.from(document.querySelectorAll('canvas'))
  .sort((a, b) => b.width * b.height - a.width * a.height)[0];
return c ? c.toDataURL('image/png') : null;
"""

STATUS = """
return Array.from(document.querySelectorAll('p, div'))
  .some(e => /^run 1: /.test(e.innerText || ''));
"""

TIMEOUT = 120.0


def browser():
    os.environ.setdefault("SE_OFFLINE", "true")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium")
    for flag in ("--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader",
                 "--disable-background-networking", "--disable-component-update",
                 "--no-first-run", "--disable-sync", f"--user-data-dir={tempfile.mkdtemp()}",
                 "--window-size=1280,800"):
        options.add_argument(flag)
    return webdriver.Chrome(options=options, service=Service(shutil.which("chromedriver")))


def blank(driver) -> bool:
    import numpy as np
    from PIL import Image

    url = driver.execute_script(CANVAS_PNG)
    if not url:
        return True
    pixels = np.asarray(Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))))
    return bool((pixels == pixels[0, 0]).all())


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def once(driver, scene: str) -> dict:
    refsim = str(Path(sys.executable).with_name("refsim"))
    driver.get("about:blank")
    start = time.perf_counter()
    proc = subprocess.Popen([refsim, "view", scene, "--port", str(free_port())],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        printed = time.perf_counter() - start
        url = line.split()[2]
        driver.get(url)
        loaded = time.perf_counter() - start
        while blank(driver):
            if time.perf_counter() - start > TIMEOUT:
                raise TimeoutError("no frame drawn")
            time.sleep(0.05)
        drawn = time.perf_counter() - start
        while not driver.execute_script(STATUS):
            if time.perf_counter() - start > TIMEOUT:
                raise TimeoutError("no run finished")
            time.sleep(0.05)
        ran = time.perf_counter() - start
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    return {"address printed": printed, "page loaded": loaded, "first frame": drawn,
            "first run shown": ran, "exit": proc.returncode, "stderr": err.strip()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="scenes/spinning-cube.toml")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    driver = browser()
    try:
        for i in range(args.repeat):
            r = once(driver, args.scene)
            print(f"run {i + 1}: address {r['address printed']:.2f} s, page loaded "
                  f"{r['page loaded']:.2f} s, first frame {r['first frame']:.2f} s, first run "
                  f"shown {r['first run shown']:.2f} s; exit {r['exit']} ({r['stderr']})")
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
