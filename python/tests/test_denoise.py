"""The Open Image Denoise front end, on the Cornell box."""

import numpy as np
import pytest

import glint
from conftest import cornell

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


def test_missing_pyoidn_says_how_to_install(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "pyoidn", None)
    with pytest.raises(ImportError, match="pip install pyoidn"):
        glint.denoise(np.zeros((4, 4, 3), np.float32))
