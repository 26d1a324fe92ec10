"""The Open Image Denoise front end, on the Cornell box."""

import os
import pathlib

import numpy as np
import pytest

import glint
from conftest import SCENES, cornell

SIZE = 128
REF_SPP = 1024


@pytest.fixture(scope="module")
def reference(request):
    """A 1024-spp render, cached between test runs (it takes a while on two cores)."""
    path = request.config.cache.mkdir("glint") / f"cornell-{SIZE}-{REF_SPP}.pfm"
    if not path.exists():
        glint.write_image(path, glint.render(cornell(SIZE), spp=REF_SPP, seed=1).image)
    return glint.read_image(path)


def rel_mse(a, ref):
    return float(np.mean((a - ref) ** 2 / (ref**2 + 1e-2)))


def test_denoising_lowers_the_error_fourfold(reference):
    r = glint.render(cornell(SIZE), spp=16, seed=2, aovs=["albedo", "normal"])
    out = glint.denoise(r.image, albedo=r.aovs["albedo"], normal=r.aovs["normal"])
    assert out.shape == r.image.shape and out.dtype == np.float32
    assert np.isfinite(out).all()
    noisy, denoised = rel_mse(r.image, reference), rel_mse(out, reference)
    assert denoised * 4 <= noisy, (noisy, denoised)
    # A flat patch of the back wall (white in the albedo layer throughout): the denoiser
    # keeps its brightness. The reference's own noise over the patch's pixels at 1024 spp
    # is far below 2%.
    wall = (slice(30, 50), slice(50, 78))
    np.testing.assert_allclose(r.aovs["albedo"][wall], np.broadcast_to([0.725, 0.71, 0.68], (20, 28, 3)), rtol=1e-5)
    assert abs(out[wall].mean() / reference[wall].mean() - 1) < 0.02


def test_denoise_without_auxiliary_images_and_bad_arguments():
    img = glint.render(cornell(32), spp=4).image
    assert np.isfinite(glint.denoise(img)).all()
    with pytest.raises(TypeError, match="image"):
        glint.denoise(img.tolist())
    with pytest.raises(ValueError, match="albedo"):
        glint.denoise(img, albedo=img[:16])
    with pytest.raises(ValueError, match="normal"):
        glint.denoise(img, normal=img)


def test_a_missing_library_says_how_to_install_it(tmp_path):
    """The library is found once per process: a fresh one that finds none says so."""
    import subprocess
    import sys

    code = "import glint, numpy as np; glint.denoise(np.zeros((4, 4, 3), np.float32))"
    env = dict(os.environ, GLINT_OIDN_LIBRARY=str(tmp_path / "none.so"))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert p.returncode != 0
    assert "ImportError" in p.stderr and "pip install pyoidn" in p.stderr, p.stderr


def test_cli_denoise_lowers_the_error_fourfold_and_keeps_the_noisy_layer(cli, reference, tmp_path):
    """`glint render --denoise` (the CLI loads the library that pyoidn bundles at run time)."""
    import subprocess
    import sys

    scene = str(SCENES / "cornell-box.json")
    common = ["--spp", "16", "--seed", "2", "--width", str(SIZE), "--height", str(SIZE), "--quiet"]
    # The CLI looks for pyoidn through this environment's python (on PATH first).
    env = dict(os.environ, PATH=f"{pathlib.Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    out = tmp_path / "d.exr"
    subprocess.run([str(cli), "render", scene, "-o", str(out), "--denoise", *common], check=True, env=env)
    noisy_pfm = tmp_path / "n.pfm"
    subprocess.run([str(cli), "render", scene, "-o", str(noisy_pfm), *common], check=True)
    denoised, noisy = glint.read_image(out), glint.read_image(noisy_pfm)
    assert np.isfinite(denoised).all()
    assert rel_mse(denoised, reference) * 4 <= rel_mse(noisy, reference)
    header = out.read_bytes()[:4096]
    for channel in (b"noisy.R\0", b"albedo.G\0", b"normal.Z\0"):
        assert channel in header, channel
    # Without the library: one line saying how to install it, and no output.
    missing = tmp_path / "m.png"
    p = subprocess.run(
        [str(cli), "render", scene, "-o", str(missing), "--denoise", *common],
        capture_output=True,
        text=True,
        env=dict(env, GLINT_OIDN_LIBRARY=str(tmp_path / "none.so")),
    )
    assert p.returncode != 0 and "pip install pyoidn" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not missing.exists()
