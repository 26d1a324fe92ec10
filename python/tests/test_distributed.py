"""Distributed rendering on a local Ray cluster of two worker processes (loopback only; the
module starts and stops its own): bit-identical to local renders and to the CLI, with a
worker process killed mid-render, interrupted and resumed, for edited scenes and
animations; packs that need none of the driver's files; bad input refused on the driver
with the CLI's message before any task is submitted."""

import json
import os
import pathlib
import shutil
import signal
import struct
import subprocess
import sys
import threading
import time
import zlib

import numpy as np
import pytest

import glint
from conftest import ROOT, SCENES, cornell, cornell_dict

# No usage report to Ray's servers from the test clusters (the machine has no network).
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
ray = pytest.importorskip("ray")
import glint.distributed as gd  # noqa: E402
from glint.distributed import _pack, _plan  # noqa: E402


@pytest.fixture(scope="module")
def cluster():
    """A local Ray instance with two CPUs: two worker processes render at once. Always a new
    one ("local"): plain ray.init() would join a cluster that `ray start` left running."""
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def small_scene(folder: pathlib.Path, size: int = 32) -> pathlib.Path:
    """The Cornell box at size x size in ``folder``, with its meshes copied beside it and
    one more mesh whose material comes from an .mtl file in a sibling folder."""
    d = cornell_dict(size)
    shutil.copytree(SCENES / "assets" / "cornell-box", folder / "assets" / "cornell-box")
    (folder / "models").mkdir()
    (folder / "materials").mkdir()
    (folder / "materials" / "orange.mtl").write_text("newmtl orange\nKd 0.9 0.4 0.1\n")
    (folder / "models" / "panel.obj").write_text(
        "mtllib ../materials/orange.mtl\nv 150 100 100\nv 300 100 100\nv 300 250 150\nv 150 250 150\n"
        "usemtl orange\nf 1 2 3 4\n"
    )
    d["shapes"].append({"type": "obj", "file": "models/panel.obj"})
    path = folder / "small.json"
    path.write_text(json.dumps(d))
    return path


def same_bits(a: np.ndarray, b: np.ndarray) -> None:
    assert a.shape == b.shape and a.dtype == b.dtype
    assert np.array_equal(a, b)
    assert a.tobytes() == b.tobytes()


def test_distributed_is_bit_identical_to_local_and_to_the_cli(cluster, cli, tmp_path):
    scene = small_scene(tmp_path)
    local = glint.render(glint.load_file(scene), spp=5, seed=7)
    out = tmp_path / "dist.pfm"
    r = gd.render(scene, spp=5, seed=7, out=out, tile=12, passes_per_task=2)
    same_bits(r.image, local.image)
    assert r.spp == 5
    # 3x3 tiles times 3 pass ranges, each world built once per worker process.
    assert r.stats["tasks"] == 27
    assert 1 <= r.stats["world_builds"] <= r.stats["workers"] <= 2
    assert r.stats["rays"] == local.stats["rays"] and r.stats["camera_rays"] == 32 * 32 * 5
    subprocess.run([str(cli), "render", str(scene), "-o", str(tmp_path / "cli.pfm"), "--spp", "5", "--seed", "7",
                    "--quiet"], check=True)
    assert out.read_bytes() == (tmp_path / "cli.pfm").read_bytes()


def test_a_splatting_filter_stays_bit_identical_across_tiles(cluster, cli, tmp_path):
    # A gaussian splats samples across tile edges: the tiles' films carry the margins, and
    # the merge adds them, so the image is still the local one, bit for bit.
    scene = small_scene(tmp_path)
    d = json.loads(scene.read_text())
    d["film"]["filter"] = "gaussian"
    scene.write_text(json.dumps(d))
    local = glint.render(glint.load_file(scene), spp=4, seed=3)
    out = tmp_path / "dist.pfm"
    r = gd.render(scene, spp=4, seed=3, out=out, tile=12, passes_per_task=2)
    same_bits(r.image, local.image)
    subprocess.run([str(cli), "render", str(scene), "-o", str(tmp_path / "cli.pfm"), "--spp", "4", "--seed", "3",
                    "--quiet"], check=True)
    assert out.read_bytes() == (tmp_path / "cli.pfm").read_bytes()
    d["film"]["filter"] = "box"
    scene.write_text(json.dumps(d))
    assert not np.array_equal(local.image, glint.render(glint.load_file(scene), spp=4, seed=3).image)


def test_defaults_match_local_defaults_with_aovs(cluster):
    local = glint.render(cornell(40), aovs=["albedo", "depth"])
    r = gd.render(cornell(40), aovs=["albedo", "depth"])
    same_bits(r.image, local.image)
    assert r.aovs.keys() == local.aovs.keys()
    for k in local.aovs:
        same_bits(r.aovs[k], local.aovs[k])
    assert r.spp == local.spp == cornell(40).spp


def test_animation_frames_share_the_workers(cluster, tmp_path):
    frames = [cornell(24), cornell(24)]
    glint.traverse(frames[1]).update({"camera.fov": 30.0})
    r = gd.render(frames, spp=3, out=str(tmp_path / "f{frame}.exr"), tile=8)
    assert len(r) == 2
    for frame, result in zip([cornell(24), frames[1]], r):
        same_bits(result.image, glint.render(frame, spp=3).image)
    same_bits(glint.read_image(tmp_path / "f1.exr"), r[1].image)
    assert not np.array_equal(r[0].image, r[1].image)


def test_an_edited_transform_renders_as_locally(cluster):
    # A transform edited in place is traced through it, not baked: workers must do the same.
    s = cornell(24)
    params = glint.traverse(s)
    m = params["shapes.1.to_world"]
    m[0, 3] += 20.0
    params.update({"shapes.1.to_world": m})
    same_bits(gd.render(s, spp=2, tile=8).image, glint.render(s, spp=2).image)


def stalled_task(flags: pathlib.Path, region, passes):
    """A stand-in for the worker's task (``_worker.render_block``, which it runs), except
    that the first attempt of the task (``region``, ``passes``) writes its process id to
    ``flags/attempt-PID`` and then waits to be killed: a worker is then certainly mid-task
    when the test kills it. A second attempt (Ray's retry) renders as usual."""

    def task(key, pack_box, spp, seed, aovs, threads, r, p):
        from glint.distributed import _worker

        if tuple(r) == region and tuple(p) == passes:
            first = not any(flags.glob("attempt-*"))
            (flags / f"attempt-{os.getpid()}").touch()
            deadline = time.monotonic() + 120
            while first and time.monotonic() < deadline:
                time.sleep(0.05)
        return _worker.render_block(key, pack_box, spp, seed, aovs, threads, r, p)

    return task


def kill_when_started(flags: pathlib.Path, killed: list) -> threading.Thread:
    """Kills the process whose first attempt of the stalled task announces itself."""

    def run():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            marks = list(flags.glob("attempt-*"))
            if marks:
                pid = int(marks[0].name.split("-")[1])
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                return
            time.sleep(0.01)

    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t


def test_a_worker_killed_mid_render_changes_nothing(cluster, tmp_path, monkeypatch):
    # Deterministic: the worker killed is one that is running a task of this render (not
    # found by process title, which matched any Ray cluster's workers on the machine and
    # raced with the task's end), and Ray's retry of that task is seen to run.
    from glint.distributed import _worker

    local = glint.render(cornell(64), spp=128, seed=2)
    monkeypatch.setattr(_worker, "render_block", stalled_task(tmp_path, (0, 0, 32, 32), (0, 16)))
    killed: list = []
    killer = kill_when_started(tmp_path, killed)
    r = gd.render(cornell(64), spp=128, seed=2, tile=32, passes_per_task=16)
    killer.join()
    attempts = sorted(int(m.name.split("-")[1]) for m in tmp_path.glob("attempt-*"))
    assert len(killed) == 1 and killed[0] in attempts and len(attempts) == 2  # killed, then retried
    same_bits(r.image, local.image)
    assert r.stats["tasks"] == 4 * 8


def test_interrupted_then_resumed_by_the_cli_and_by_the_call(cluster, cli, tmp_path):
    scene = small_scene(tmp_path, size=24)
    ck, out = tmp_path / "render.film", tmp_path / "dist.pfm"
    blocks = []

    def stop_after_five(p):
        blocks.append(p)
        if len(blocks) == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        gd.render(scene, spp=6, out=out, checkpoint=ck, tile=8, passes_per_task=2, report=stop_after_five)
    assert ck.exists() and out.exists()  # the image so far and the film
    local = tmp_path / "local.pfm"
    subprocess.run([str(cli), "render", str(scene), "-o", str(local), "--spp", "6", "--quiet"], check=True)
    # glint resume fills in what the scattered blocks lack (in a copy: it checkpoints into
    # the film it resumes).
    shutil.copy(ck, tmp_path / "copy.film")
    subprocess.run([str(cli), "resume", str(tmp_path / "copy.film"), "-o", str(tmp_path / "resumed.pfm"), "--quiet"],
                   check=True)
    assert (tmp_path / "resumed.pfm").read_bytes() == local.read_bytes()
    # The same call given the checkpoint renders only the rest; its output is the default.
    out.unlink()
    r = gd.render(scene, spp=6, tile=8, passes_per_task=2, resume=ck)
    assert 0 < r.stats["tasks"] <= 27 - 5
    assert out.read_bytes() == local.read_bytes()


def test_a_pack_needs_none_of_the_drivers_files(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    scene = glint.load_file(small_scene(src))
    before = glint.render(scene, spp=2).image
    p = _pack.pack(scene)
    assert sorted(os.path.basename(k) for k in p.files) == sorted(
        ["floor.obj", "shortbox.obj", "tallbox.obj", "left.obj", "right.obj", "light.obj", "panel.obj", "orange.mtl"]
    )
    shutil.rmtree(src)
    (tmp_path / "copy").mkdir()
    again = _pack.unpack(p, str(tmp_path / "copy"))
    same_bits(glint.render(again, spp=2).image, before)


def png_rgb(width, height, rgb):
    """A PNG of one colour, written without an imaging library."""
    raw = b"".join(b"\0" + bytes(rgb) * width for _ in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def test_a_pack_ships_a_gltf_files_buffers_and_images(tmp_path):
    src = tmp_path / "src"
    (src / "buffers").mkdir(parents=True)
    (src / "textures").mkdir()
    positions = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    uvs = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    (src / "buffers" / "quad.bin").write_bytes(positions + uvs)
    (src / "textures" / "paint.png").write_bytes(png_rgb(2, 2, (200, 90, 30)))
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}],
        "materials": [{"emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1]}],
        "textures": [{"source": 0}],
        "images": [{"uri": "textures/paint.png"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "mode": 6, "material": 0}]}],
        "buffers": [{"byteLength": 80, "uri": "buffers/quad.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
        ],
    }
    (src / "quad.gltf").write_text(json.dumps(doc))
    scene = glint.load_file(src / "quad.gltf")
    before = glint.render(scene, spp=2, width=16, height=16).image
    assert before.max() > 0
    p = _pack.pack(scene)
    assert sorted(os.path.basename(k) for k in p.files) == ["paint.png", "quad.bin", "quad.gltf"]
    shutil.rmtree(src)
    (tmp_path / "copy").mkdir()
    again = _pack.unpack(p, str(tmp_path / "copy"))
    same_bits(glint.render(again, spp=2, width=16, height=16).image, before)


def test_plan_skips_work_the_film_holds_and_refuses_misaligned_blocks():
    done = [((0, 0, 16, 8), (0, 3)), ((0, 8, 8, 16), (1, 2))]
    tasks = _plan.plan(0, 16, 16, 4, 8, 2, done)
    got = {(t.region, t.passes) for t in tasks}
    assert got == {
        ((0, 0, 8, 8), (3, 4)), ((8, 0, 16, 8), (3, 4)),
        ((0, 8, 8, 16), (0, 1)), ((0, 8, 8, 16), (2, 4)),
        ((8, 8, 16, 16), (0, 2)), ((8, 8, 16, 16), (2, 4)),
    }
    ranges = [t.passes[0] // 2 for t in tasks]
    assert ranges == sorted(ranges)  # the early pass ranges of every tile first
    with pytest.raises(ValueError, match="whole tiles"):
        _plan.plan(0, 16, 16, 4, 8, 2, [((0, 0, 12, 8), (0, 1))])
    assert _plan.auto_passes_per_task(256, 16, 2) == 86


def bad_scenes(tmp_path):
    d = cornell_dict(16)
    d["shapes"][0]["file"] = str(tmp_path / "no-such-mesh.obj")
    (tmp_path / "missing.json").write_text(json.dumps(d))
    (tmp_path / "syntax.json").write_text('{"film": {"width": 16,,}}\n')
    (tmp_path / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")
    d = cornell_dict(16)
    d["shapes"][0]["file"] = str(tmp_path / "broken.obj")
    (tmp_path / "bad-mesh.json").write_text(json.dumps(d))
    return [tmp_path / n for n in ("missing.json", "syntax.json", "bad-mesh.json")]


def test_bad_input_fails_on_the_driver_with_the_cli_message(cli, tmp_path, monkeypatch):
    def no_cluster(*args, **kwargs):
        raise AssertionError("Ray was reached before the input was checked")

    for scene in bad_scenes(tmp_path):
        c = subprocess.run([str(cli), "render", str(scene), "-o", str(tmp_path / "x.png")], capture_output=True,
                           text=True)
        assert c.returncode != 0 and c.stderr.startswith("glint: error: ")
        message = c.stderr.strip()[len("glint: error: "):]
        with monkeypatch.context() as m:
            m.setattr(ray, "init", no_cluster)
            m.setattr(ray, "put", no_cluster)
            with pytest.raises(glint.SceneError) as e:
                gd.render(str(scene), out=str(tmp_path / "x.png"))
        assert str(e.value) == message
        # The command line front end prints the same one line, and no traceback.
        p = subprocess.run([sys.executable, "-m", "glint.distributed", str(scene), "-o", str(tmp_path / "x.png")],
                           capture_output=True, text=True, cwd=ROOT)
        assert p.returncode == 1
        assert p.stderr == c.stderr
    assert not (tmp_path / "x.png").exists()


def test_every_output_file_is_checked_before_ray(tmp_path, monkeypatch):
    def no_cluster(*args, **kwargs):
        raise AssertionError("Ray was reached before the output was checked")

    d = cornell_dict(16)
    d["film"]["aovs"] = ["depth"]
    scene = glint.load_dict(d, base_dir=SCENES)
    monkeypatch.setattr(ray, "init", no_cluster)
    with pytest.raises(glint.SceneError, match="missing.* does not exist"):
        gd.render(scene, out=str(tmp_path / "missing" / "x.png"))
    with pytest.raises(ValueError, match="unknown image format"):
        gd.render(scene, out=str(tmp_path / "x.bmp"))
    # The depth layer's PNG would overwrite a file the scene reads.
    mesh = tmp_path / "x.depth.png"
    mesh.write_bytes((SCENES / "assets" / "cornell-box" / "floor.obj").read_bytes())
    d["shapes"][0]["file"] = str(mesh)
    with pytest.raises(glint.SceneError, match="overwrite the scene's input file"):
        gd.render(glint.load_dict(d, base_dir=SCENES), out=str(tmp_path / "x.png"))
    assert not (tmp_path / "x.png").exists()


def test_command_line_front_end_renders_what_glint_render_does(cli, tmp_path):
    scene = small_scene(tmp_path, size=16)
    subprocess.run([str(cli), "render", str(scene), "-o", str(tmp_path / "cli.pfm"), "--spp", "3", "--quiet"],
                   check=True)
    p = subprocess.run([sys.executable, "-m", "glint.distributed", str(scene), "-o", str(tmp_path / "dist.pfm"),
                        "--spp", "3"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "dist.pfm").read_bytes() == (tmp_path / "cli.pfm").read_bytes()
    summary = [line for line in p.stderr.splitlines() if line.startswith("glint: ")]
    assert len(summary) == 1 and " 16x16 @ 3 spp in " in summary[0] and summary[0].endswith("dist.pfm")


def test_a_checkpoint_that_cannot_be_written_warns_and_the_render_goes_on(cluster, tmp_path):
    # The checkpoint's folder vanishes mid-render (as on a full disk, the write fails): one
    # warning, the render goes on to the same bits, and its image is written.
    scene = small_scene(tmp_path, size=16)
    folder = tmp_path / "checkpoints"
    folder.mkdir()
    ck, out = folder / "render.film", tmp_path / "dist.pfm"
    blocks = []

    def remove_after_two(p):
        blocks.append(p)
        if len(blocks) == 2:
            assert ck.exists()  # written after the first block
            shutil.rmtree(folder)

    with pytest.warns(RuntimeWarning) as caught:
        r = gd.render(scene, spp=4, seed=1, out=out, tile=8, passes_per_task=1, checkpoint=ck,
                      checkpoint_every=1e-6, report=remove_after_two)
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len([m for m in messages if "next try in" in m]) == 1, messages  # once, not per block
    assert any("the image is written" in m for m in messages), messages
    assert all(str(ck) in m and "No such file or directory" in m for m in messages), messages
    same_bits(r.image, glint.render(glint.load_file(scene), spp=4, seed=1).image)
    assert out.exists() and not folder.exists()


def test_the_preview_shows_the_merged_film_and_the_workers_and_its_stop_acts_as_ctrl_c(cluster, tmp_path):
    import re
    import socket
    import urllib.request

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    url = f"http://127.0.0.1:{port}/"
    seen = []

    def report(_progress):
        seen.append(json.loads(urllib.request.urlopen(url + "state", timeout=30).read()))
        if len(seen) == 4:
            page = urllib.request.urlopen(url, timeout=30).read().decode()
            token = re.search(r'const TOKEN = "([0-9a-f]+)"', page).group(1)
            urllib.request.urlopen(url + f"stop?token={token}", timeout=30).read()

    out = tmp_path / "stopped.pfm"
    with pytest.raises(KeyboardInterrupt):
        gd.render(cornell(32), spp=40, out=out, tile=16, passes_per_task=2, report=report,
                  preview=f"127.0.0.1:{port}")
    assert out.exists(), "the image so far is written, as after Ctrl-C"
    shown = [s for s in seen if s["frame"] > 0]
    assert shown and shown[-1]["width"] == 32 and shown[-1]["progress"]["spp"] < 40
    workers = shown[-1]["workers"]
    assert 1 <= len(workers) <= 2 and all(w["name"].startswith("pid ") and w["total"] == 80 for w in workers)
