"""One request, three front ends: ``glint render``, ``glint.render`` + ``glint.write_image``
and the distributed driver write the same files, byte for byte, for layers beside a PNG
image, for render overrides and for a denoised render (the rules are the library's)."""

import os
import pathlib
import signal
import subprocess
import sys

import numpy as np
import pytest

import glint
from conftest import SCENES

os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
ray = pytest.importorskip("ray")
import glint.distributed as gd  # noqa: E402
from glint.distributed.__main__ import main as distributed_main  # noqa: E402

SCENE = SCENES / "cornell-box.json"


@pytest.fixture(scope="module")
def cluster():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def cli_render(cli, out, *args, env=None):
    subprocess.run([str(cli), "render", str(SCENE), "-o", str(out), "--quiet", *args], check=True, env=env)


def same_files(*paths):
    first = pathlib.Path(paths[0]).read_bytes()
    for p in paths[1:]:
        assert pathlib.Path(p).read_bytes() == first, f"{p} differs from {paths[0]}"


def test_layers_beside_a_png_image_are_one_png_each(cli, cluster, tmp_path):
    size = dict(width=20, height=16)
    cli_render(cli, tmp_path / "cli.png", "--spp", "2", "--width", "20", "--height", "16", "--aov", "albedo,depth")
    r = glint.render(glint.load_file(SCENE), spp=2, aovs=["albedo", "depth"], **size)
    glint.write_image(tmp_path / "py.png", r.image, r.aovs)
    gd.render(str(SCENE), spp=2, aovs=["albedo", "depth"], out=str(tmp_path / "ray.png"), tile=8, **size)
    for suffix in ("png", "albedo.png", "depth.png"):
        same_files(*(tmp_path / f"{who}.{suffix}" for who in ("cli", "py", "ray")))
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == sorted(f"{who}.{s}" for who in ("cli", "py", "ray") for s in ("png", "albedo.png", "depth.png"))
    # The depth layer is scaled to its largest value: that pixel is white, nearer ones grey.
    depth = glint.read_image(tmp_path / "py.depth.png")
    assert depth.max() == 1.0 and 0 < depth[depth > 0].min() < 1


def test_overrides_are_the_same_flags_and_keywords_everywhere(cli, cluster, tmp_path):
    flags = ["--integrator", "whitted", "--max-depth", "2", "--light-selection", "uniform",
             "--sampler", "independent", "--width", "18", "--height", "14", "--spp", "3", "--seed", "5"]
    keywords = dict(integrator="whitted", max_depth=2, light_selection="uniform", sampler="independent",
                    width=18, height=14)
    cli_render(cli, tmp_path / "cli.pfm", *flags)
    scene = glint.load_file(SCENE)
    r = glint.render(scene, spp=3, seed=5, **keywords)
    glint.write_image(tmp_path / "py.pfm", r.image)
    # The command-line driver takes the command line's flags (run here, on the test's Ray;
    # its SIGTERM handler is put back afterwards).
    term = signal.getsignal(signal.SIGTERM)
    try:
        assert distributed_main([str(SCENE), "-o", str(tmp_path / "ray.pfm"), "--quiet", "--tile", "8", *flags]) == 0
    finally:
        signal.signal(signal.SIGTERM, term)
    same_files(tmp_path / "cli.pfm", tmp_path / "py.pfm", tmp_path / "ray.pfm")
    # The overrides held for that render only: a session without them has the scene's
    # size. And the whitted image is not the path tracer's.
    assert glint.make_session(scene, spp=1).width == scene.width == 784
    path_traced = glint.render(scene, spp=3, seed=5, sampler="independent", width=18, height=14)
    assert not np.array_equal(path_traced.image, r.image)
    # A bad override: the same message from the command line and from Python.
    c = subprocess.run([str(cli), "render", str(SCENE), "-o", str(tmp_path / "x.pfm"), "--integrator", "direct",
                        "--max-depth", "3"], capture_output=True, text=True)
    with pytest.raises(ValueError) as e:
        glint.render(scene, spp=1, integrator="direct", max_depth=3)
    assert c.returncode == 1 and c.stderr.strip() == f"glint: error: {e.value}"


def test_a_denoised_render_is_the_same_everywhere(cli, cluster, tmp_path):
    try:
        glint._glint.find_denoiser()
    except ImportError as e:
        pytest.skip(f"no Open Image Denoise library: {e}")
    # The command line looks for pyoidn through this environment's python (on PATH first).
    env = dict(os.environ, PATH=f"{pathlib.Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    cli_render(cli, tmp_path / "cli.exr", "--spp", "4", "--width", "24", "--height", "24", "--denoise", env=env)
    cli_render(cli, tmp_path / "cli.png", "--spp", "4", "--width", "24", "--height", "24", "--denoise", env=env)
    r = glint.render(glint.load_file(SCENE), spp=4, width=24, height=24, denoise=True)
    assert list(r.aovs) == ["noisy", "albedo", "normal"]
    assert not np.array_equal(r.image, r.aovs["noisy"])
    glint.write_image(tmp_path / "py.exr", r.image, r.aovs)
    glint.write_image(tmp_path / "py.png", r.image, r.aovs)
    d = gd.render(str(SCENE), spp=4, width=24, height=24, denoise=True, out=str(tmp_path / "ray.exr"), tile=8)
    np.testing.assert_array_equal(d.image, r.image)
    same_files(tmp_path / "cli.exr", tmp_path / "py.exr", tmp_path / "ray.exr")
    for suffix in ("png", "noisy.png", "albedo.png", "normal.png"):
        same_files(tmp_path / f"cli.{suffix}", tmp_path / f"py.{suffix}")
    # glint.denoise on the layers is the same denoiser.
    np.testing.assert_array_equal(glint.denoise(r.aovs["noisy"], r.aovs["albedo"], r.aovs["normal"]), r.image)
