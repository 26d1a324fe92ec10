"""The live preview in a real browser: Debian's Chromium, headless, driven by chromedriver
over the W3C WebDriver protocol (plain HTTP, urllib). It loads the page of a `glint render
--preview` in progress, sees the image change between passes, reads a pixel through the
inspector, switches to a layer, presses Stop, and the render exits as after Ctrl-C (130,
the image written). Screenshots go to out/test-preview-browser/ for a person to look at.

scripts/test-python installs chromium and chromium-driver where apt can; where neither is
there and apt could not install them, the test is skipped with a message (CI installs them)."""

import base64
import json
import os
import pathlib
import shutil
import socket
import subprocess
import time
import urllib.request

import pytest

from conftest import ROOT, SCENES

SHOTS = ROOT / "out" / "test-preview-browser"


def _browser():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not (chromium and driver):
        pytest.skip("chromium and chromedriver are not installed (scripts/test-python installs them with apt)")
    return chromium, driver


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class WebDriver:
    """The few WebDriver commands the test needs."""

    def __init__(self, url: str):
        self.url = url
        self.session = None

    def call(self, method: str, path: str, body=None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.url + path, data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=60) as r:
            return json.loads(r.read())["value"]

    def start(self, chromium: str) -> None:
        args = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1000,860", "--no-first-run", "--no-default-browser-check"]
        caps = {"capabilities": {"alwaysMatch": {"browserName": "chrome", "goog:chromeOptions": {
            "binary": chromium, "args": args}}}}
        self.session = self.call("POST", "/session", caps)["sessionId"]

    def cmd(self, method: str, path: str, body=None):
        return self.call(method, f"/session/{self.session}{path}", body)

    def js(self, script: str, *args):
        return self.cmd("POST", "/execute/sync", {"script": script, "args": list(args)})

    def element(self, css: str) -> str:
        e = self.cmd("POST", "/element", {"using": "css selector", "value": css})
        return next(iter(e.values()))

    def click(self, css: str) -> None:
        self.cmd("POST", f"/element/{self.element(css)}/click", {})

    def hover(self, css: str, dx: int, dy: int) -> None:
        origin = {"element-6066-11e4-a52e-4f735466cecf": self.element(css)}
        moves = [{"type": "pointerMove", "duration": 0, "origin": origin, "x": dx + k, "y": dy} for k in (0, 1)]
        self.cmd("POST", "/actions", {"actions": [{"type": "pointer", "id": "mouse", "actions": moves}]})

    def screenshot(self, path: pathlib.Path) -> None:
        path.write_bytes(base64.b64decode(self.cmd("GET", "/screenshot")))

    def wait(self, what: str, script: str, timeout: float = 60.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            v = self.js(script)
            if v:
                return v
            time.sleep(0.05)
        raise AssertionError(f"timed out waiting for {what}")

    def quit(self) -> None:
        if self.session:
            try:
                self.cmd("DELETE", "")
            except OSError:
                pass


# A sum of the pixels of the image on the page, drawn into a canvas: changes when the image does.
CHECKSUM = """
const img = document.getElementById('image');
if (!img.complete || !img.naturalWidth) return null;
const c = document.createElement('canvas');
c.width = img.naturalWidth; c.height = img.naturalHeight;
const ctx = c.getContext('2d'); ctx.drawImage(img, 0, 0);
const d = ctx.getImageData(0, 0, c.width, c.height).data;
let s = 0; for (let i = 0; i < d.length; i++) s = (s * 31 + d[i]) % 1000000007;
return [Number(document.body.dataset.frame), s];
"""


@pytest.mark.timeout(240)
def test_the_preview_page_watches_inspects_switches_layers_and_stops_the_render(cli, tmp_path):
    chromium, chromedriver = _browser()
    SHOTS.mkdir(parents=True, exist_ok=True)
    out = tmp_path / "cornell.png"
    # A render that would take minutes, so that only Stop ends it.
    render = subprocess.Popen(
        [str(cli), "render", str(SCENES / "cornell-box.json"), "-o", str(out), "--width", "200", "--height", "200",
         "--spp", "100000", "--aov", "albedo,depth", "--preview"],
        stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True)
    port = _free_port()
    driver = subprocess.Popen([chromedriver, f"--port={port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wd = WebDriver(f"http://127.0.0.1:{port}")
    try:
        line = render.stderr.readline()
        assert line.startswith("glint: preview at http://127.0.0.1:"), line
        url = line.split(" at ", 1)[1].strip()
        for _ in range(100):
            try:
                wd.start(chromium)
                break
            except OSError:
                time.sleep(0.1)
        wd.cmd("POST", "/url", {"url": url})

        # The image arrives, then changes as passes land.
        first = wd.wait("the first frame", CHECKSUM)
        wd.screenshot(SHOTS / "1-first-frame.png")
        later = wd.wait("a later frame that differs",
                        f"const v = (function() {{ {CHECKSUM} }})(); return v && v[0] > {first[0]} && v[1] != {first[1]} ? v : null;")
        assert later[0] > first[0]
        spp = int(wd.js("return document.getElementById('spp').textContent").split("/")[0])
        assert spp > 0

        # The inspector reads a pixel: coordinates, linear RGB, samples, relative error.
        wd.click("#fit")
        wd.hover("#image", 5, 10)
        text = wd.wait("the inspector", "const t = document.getElementById('inspector').textContent;"
                                        "return t.includes('RGB') ? t : null;")
        assert "spp" in text and "rel. error" in text, text
        x, y = (int(v) for v in text.split(")")[0].strip("( ").split(","))
        assert 0 <= x < 200 and 0 <= y < 200
        rgb = [float(v) for v in text.split("RGB")[1].split("spp")[0].split()]
        assert len(rgb) == 3 and all(v >= 0 for v in rgb), text
        wd.screenshot(SHOTS / "2-inspector.png")

        # Switch to the depth layer (false colour).
        wd.click("#layer option[value='depth']")
        wd.wait("the depth layer", "return document.body.dataset.layer === 'depth';")
        assert wd.js("return document.getElementById('view').value") == "false"
        wd.screenshot(SHOTS / "3-depth-layer.png")
        wd.click("#layer option[value='beauty']")
        wd.wait("the beauty again", "return document.body.dataset.layer === 'beauty';")

        # Stop: the render ends as after Ctrl-C, the image written.
        wd.click("#stop")
        assert render.wait(timeout=60) == 130
        err = render.stderr.read()
        assert "stopped from the preview at" in err and str(out) in err, err
        assert out.stat().st_size > 0
        wd.screenshot(SHOTS / "4-stopped.png")
    finally:
        wd.quit()
        driver.kill()
        driver.wait()
        if render.poll() is None:
            render.kill()
            render.wait()
    print(f"screenshots in {SHOTS}")
