"""Rendering: arrays, bit-identity with the CLI, passes, threads, progress, images on disk."""

import json
import subprocess

import numpy as np
import pytest

import glint
from conftest import SCENES, cornell, cornell_dict


def test_image_and_aov_arrays():
    r = glint.render(cornell(32), spp=2, aovs=["albedo", "normal", "depth"])
    assert r.image.shape == (32, 32, 3) and r.image.dtype == np.float32
    assert r.aovs["albedo"].shape == (32, 32, 3)
    assert r.aovs["normal"].shape == (32, 32, 3)
    assert r.aovs["depth"].shape == (32, 32, 1)
    assert all(a.dtype == np.float32 for a in r.aovs.values())
    assert r.spp == 2
    assert r.stats["rays"] > 0 and r.stats["seconds"] > 0
    assert r.stats["mesh_bvh_builds"] == 6 and r.stats["top_level_builds"] == 1


def cli_image(cli, scene_path, out, *args):
    subprocess.run([str(cli), "render", str(scene_path), "-o", str(out), "--quiet", *args], check=True)
    return glint.read_image(out)


@pytest.mark.parametrize("spp,seed", [(3, 0), (2, 7)])
def test_file_bit_identical_to_cli(cli, tmp_path, spp, seed):
    # A small copy of the Cornell box, its mesh paths made absolute.
    d = cornell_dict(40)
    for shape in d["shapes"]:
        shape["file"] = str(SCENES / shape["file"])
    path = tmp_path / "small.json"
    path.write_text(json.dumps(d))
    ref = cli_image(cli, path, tmp_path / "cli.pfm", "--spp", str(spp), "--seed", str(seed))
    img = glint.render(glint.load_file(path), spp=spp, seed=seed).image
    assert img.shape == ref.shape == (40, 40, 3)
    np.testing.assert_array_equal(img, ref)


def test_dict_bit_identical_to_cli_overrides(cli, tmp_path):
    ref = cli_image(cli, SCENES / "cornell-box.json", tmp_path / "cli.pfm", "--width", "48", "--height", "40")
    d = cornell_dict(48)
    d["film"]["height"] = 40
    img = glint.render(glint.load_dict(d, base_dir=SCENES)).image
    np.testing.assert_array_equal(img, ref)


def test_passes_add_up_to_one_render():
    s = cornell(24)
    whole = glint.render(s, spp=6, seed=1).image
    session = glint.Session(s, spp=6, seed=1)
    assert session.render_passes(2) == 2 and session.spp == 2
    session.render_passes(1)
    session.render_passes()
    assert session.spp == 6 == session.target_spp
    np.testing.assert_array_equal(session.image(), whole)
    assert session.render_passes() == 0


def test_thread_count_does_not_change_the_image():
    s = cornell(24)
    np.testing.assert_array_equal(glint.render(s, spp=2, threads=1).image, glint.render(s, spp=2).image)


def test_progress_is_called_with_samples_done():
    calls = []
    glint.render(cornell(24), spp=4, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (4, 4)
    assert all(total == 4 and 0 <= done <= 4 for done, total in calls)


def test_progress_exception_stops_the_render():
    def boom(done, total):
        raise RuntimeError("stop")

    session = glint.Session(cornell(64), spp=4096)
    with pytest.raises(RuntimeError, match="stop"):
        session.render_passes(None, None, boom)
    assert session.spp < 4096


@pytest.mark.parametrize("ext", ["exr", "pfm"])
def test_write_and_read_image_round_trip(tmp_path, ext):
    img = np.random.default_rng(1).random((7, 5, 3), dtype=np.float32) * 4
    path = tmp_path / f"x.{ext}"
    glint.write_image(path, img)
    np.testing.assert_array_equal(glint.read_image(path), img)


def test_png_round_trip_is_8_bit_srgb(tmp_path):
    img = np.random.default_rng(2).random((6, 4, 3), dtype=np.float32)
    glint.write_image(tmp_path / "x.png", img)
    back = glint.read_image(tmp_path / "x.png")
    # 8-bit sRGB: rounding moves a value by half a step (0.5/255) in sRGB, which is at
    # most 2.4 times that in linear below 1 (the curve's steepest slope there).
    np.testing.assert_allclose(back, img, atol=2.4 * 0.5 / 255 + 1e-6)


def test_exr_with_layers(tmp_path):
    r = glint.render(cornell(16), spp=1, aovs=["albedo", "depth"])
    glint.write_image(tmp_path / "x.exr", r.image, r.aovs)
    np.testing.assert_array_equal(glint.read_image(tmp_path / "x.exr"), r.image)
    header = (tmp_path / "x.exr").read_bytes()[:4096]
    for channel in (b"albedo.B\0", b"depth.Z\0"):
        assert channel in header, channel
    # Beside a PFM (or PNG) image each layer is a PNG of its own, as the command line writes.
    glint.write_image(tmp_path / "y.pfm", r.image, r.aovs)
    assert sorted(p.name for p in tmp_path.glob("y.*")) == ["y.albedo.png", "y.depth.png", "y.pfm"]
    np.testing.assert_array_equal(glint.read_image(tmp_path / "y.pfm"), r.image)
    # A layer no PNG can show: refused before anything is written.
    with pytest.raises(ValueError, match="mask: 2 channels"):
        glint.write_image(tmp_path / "z.png", r.image, {"mask": np.zeros((16, 16, 2), np.float32)})
    assert not list(tmp_path.glob("z.*"))
