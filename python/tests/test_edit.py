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


MITSUBA = """<scene version="3.0.0">
    <sensor type="perspective" id="cam">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
    </sensor>
    <bsdf type="diffuse" id="paint"><rgb name="reflectance" value="0.5, 0.5, 0.5"/></bsdf>
    <shape type="sphere" id="ball"><ref id="paint"/></shape>
    <shape type="rectangle">
        <transform name="to_world"><translate z="-2"/><scale value="3"/></transform>
    </shape>
    <emitter type="constant" id="sky"><rgb name="radiance" value="0.8, 0.8, 0.8"/></emitter>
</scene>
"""


def mitsuba_scene(tmp_path):
    path = tmp_path / "ball.xml"
    path.write_text(MITSUBA)
    return glint.load_file(path)


def test_shapes_and_lights_are_named_by_their_ids(tmp_path):
    params = glint.traverse(mitsuba_scene(tmp_path))
    names = set(params)
    assert {"shapes.ball.to_world", "shapes.1.to_world", "materials.paint.reflectance", "lights.sky.radiance"} <= names
    assert "shapes.0.to_world" not in names
    # Mitsuba's keys read the same values as the names traverse lists.
    np.testing.assert_array_equal(params["ball.to_world"], params["shapes.ball.to_world"])
    np.testing.assert_array_equal(params["paint.reflectance.value"], [0.5, 0.5, 0.5])
    np.testing.assert_array_equal(params["cam.to_world"], params["camera.to_world"])


def test_mitsuba_keys_edit_what_the_canonical_names_edit(tmp_path):
    by_alias, by_name = mitsuba_scene(tmp_path), mitsuba_scene(tmp_path)
    before = glint.render(by_alias, spp=2).image
    moved = np.array(glint.traverse(by_alias)["shapes.ball.to_world"])
    moved[0, 3] += 0.7
    glint.traverse(by_alias).update({"ball.to_world": moved, "paint.reflectance.value": [0.9, 0.1, 0.1]})
    glint.traverse(by_name).update({"shapes.ball.to_world": moved, "materials.paint.reflectance": [0.9, 0.1, 0.1]})
    after = glint.render(by_alias, spp=2).image
    np.testing.assert_array_equal(after, glint.render(by_name, spp=2).image)
    assert not np.array_equal(after, before)
    params = glint.traverse(by_alias)
    np.testing.assert_array_equal(params["shapes.ball.to_world"], moved)
    np.testing.assert_allclose(params["materials.paint.reflectance"], [0.9, 0.1, 0.1], rtol=1e-6)
    # The red ball is redder than it was.
    assert after[..., 0].sum() > before[..., 0].sum() and after[..., 2].sum() < before[..., 2].sum()


def test_unknown_names_suggest_the_nearest(tmp_path):
    params = glint.traverse(mitsuba_scene(tmp_path))
    with pytest.raises(KeyError, match="did you mean 'shapes.ball.to_world'"):
        params["shapes.bal.to_world"] = np.eye(4)
    with pytest.raises(KeyError, match="no parameter called 'ball.radius'"):
        params["ball.radius"] = 2.0
