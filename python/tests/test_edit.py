"""Editing through traverse: values, what is rebuilt, errors."""

import numpy as np
import pytest

import glint
from conftest import cornell

LIGHT = "shapes.5.emission"


def test_parameters_and_values():
    params = glint.traverse(cornell(16))
    assert {"materials.white.reflectance", LIGHT, "camera.fov", "camera.to_world", "shapes.0.to_world"} <= set(params)
    np.testing.assert_allclose(params["materials.white.reflectance"], [0.725, 0.71, 0.68], rtol=1e-6)
    assert params[LIGHT].shape == (3,)
    assert params["camera.to_world"].shape == (4, 4)
    assert params["camera.fov"] == pytest.approx(40)


def test_doubling_the_light_doubles_the_image_and_builds_no_bvh():
    s = cornell(32)
    before = glint.render(s, spp=4)
    params = glint.traverse(s)
    params[LIGHT] = params[LIGHT] * 2
    params.update()
    after = glint.render(s, spp=4)
    # Doubling is exact in binary floating point; the film's fixed-point sums round at
    # their last bit.
    np.testing.assert_allclose(after.image, 2 * before.image, rtol=1e-6, atol=1e-9)
    assert after.stats["mesh_bvh_builds"] == before.stats["mesh_bvh_builds"] == 6
    assert after.stats["top_level_builds"] == before.stats["top_level_builds"] == 1


def test_material_and_camera_edits_build_no_bvh():
    s = cornell(32)
    glint.render(s, spp=1)
    params = glint.traverse(s)
    params["materials.red.reflectance"] = [0.1, 0.2, 0.9]
    params["camera.fov"] = 30.0
    params.update()
    r = glint.render(s, spp=1)
    assert (r.stats["mesh_bvh_builds"], r.stats["top_level_builds"]) == (6, 1)
    # The edited scene loaded afresh renders the same image.
    from conftest import cornell_dict, SCENES

    d = cornell_dict(32)
    d["materials"]["red"]["reflectance"] = [0.1, 0.2, 0.9]
    d["camera"]["fov"] = 30
    fresh = glint.render(glint.load_dict(d, base_dir=SCENES), spp=1).image
    np.testing.assert_array_equal(r.image, fresh)


def test_transform_edit_rebuilds_only_the_top_level():
    s = cornell(32)
    before = glint.render(s, spp=1)
    params = glint.traverse(s)
    m = params["shapes.2.to_world"]
    m[0, 3] += 50.0
    params["shapes.2.to_world"] = m
    params.update()
    after = glint.render(s, spp=1)
    assert after.stats["mesh_bvh_builds"] == 6
    assert after.stats["top_level_builds"] == 2
    assert not np.array_equal(after.image, before.image)
    np.testing.assert_allclose(glint.traverse(s)["shapes.2.to_world"], m)


def test_bad_edits_change_nothing():
    s = cornell(16)
    params = glint.traverse(s)
    with pytest.raises(KeyError):
        params["materials.nope.reflectance"] = [1, 1, 1]
    with pytest.raises(TypeError, match="camera.fov"):
        params["camera.fov"] = [1, 2, 3]
    with pytest.raises(TypeError, match=LIGHT):
        params[LIGHT] = np.ones(4)
    before = glint.render(s, spp=1).image
    params["materials.white.reflectance"] = [0.2, 0.2, 0.2]
    params["camera.fov"] = -10.0
    with pytest.raises(glint.SceneError):
        params.update()
    assert glint.traverse(s)["camera.fov"] == pytest.approx(40)
    np.testing.assert_allclose(glint.traverse(s)["materials.white.reflectance"], [0.725, 0.71, 0.68], rtol=1e-6)
    np.testing.assert_array_equal(glint.render(s, spp=1).image, before)
