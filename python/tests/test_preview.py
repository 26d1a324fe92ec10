"""The live preview from Python: glint.render(preview=True), Session.preview() (inline in
Jupyter through _repr_html_), the Stop button, and a render unchanged by watching it."""

import json
import re
import threading
import time
import urllib.request

import numpy as np

import glint
from conftest import cornell


def _get(url: str) -> str:
    with urllib.request.urlopen(url, timeout=30) as r:
        return r.read().decode()


def _state(p: glint.Preview) -> dict:
    return json.loads(_get(p.url + "state"))


def test_render_with_a_preview_prints_its_address_and_gives_the_same_image(capsys):
    scene = cornell(24)
    plain = glint.render(scene, spp=8, aovs=("albedo",))
    watched = glint.render(scene, spp=8, aovs=("albedo",), preview=True)
    err = capsys.readouterr().err
    assert re.search(r"glint: preview at http://127\.0\.0\.1:\d+/", err), err
    assert np.array_equal(plain.image, watched.image)
    assert np.array_equal(plain.aovs["albedo"], watched.aovs["albedo"])


def test_session_preview_serves_the_film_and_shows_inline():
    s = glint.make_session(cornell(16), spp=4, aovs=("depth",))
    p = s.preview()
    assert p.url.startswith("http://127.0.0.1:")
    assert f'<iframe src="{p.url}"' in p._repr_html_()
    assert s.preview().url == p.url, "one preview per session"
    s.render_passes()
    state = _state(p)
    assert state["progress"]["spp"] == 4 and state["progress"]["state"] == "done"
    assert [l["name"] for l in state["layers"]] == ["beauty", "depth"]
    pixel = json.loads(_get(p.url + "pixel?x=3&y=9"))
    assert np.float32(pixel["layers"]["beauty"][1]) == s.image()[9, 3, 1]
    assert np.float32(pixel["layers"]["depth"][0]) == s.aovs()["depth"][9, 3, 0]


def test_the_stop_button_ends_a_python_render_keeping_the_passes_done():
    s = glint.make_session(cornell(24), spp=100000)
    p = s.preview()
    token = re.search(r'const TOKEN = "([0-9a-f]+)"', _get(p.url)).group(1)
    done = []
    t = threading.Thread(target=lambda: done.append(s.render_passes()))
    t.start()
    while _state(p)["progress"]["passes_done"] < 2:
        time.sleep(0.01)
    assert "stopping" in _get(p.url + f"stop?token={token}")
    t.join(60)
    assert not t.is_alive()
    assert 2 <= done[0] < 100000 and s.spp == done[0]
    assert _state(p)["progress"]["state"] == "stopped"


def test_a_preview_without_a_session_shows_what_it_is_given():
    s = glint.make_session(cornell(8), spp=2)
    s.render_passes()
    p = glint.Preview(title="farm")
    assert "<title>glint: farm</title>" in _get(p.url)
    p.set_workers([("pid 1", 3, 4, "busy")])
    p.publish(s, elapsed=2.0, mrays=1.5, state="done")
    state = _state(p)
    assert state["workers"] == [{"name": "pid 1", "done": 3, "total": 4, "status": "busy"}]
    assert state["progress"]["mrays_per_second"] == 1.5 and state["frame"] == 1
