"""Loading scenes from files and dicts, in-memory meshes, and errors."""

import json

import numpy as np
import pytest

import glint
from conftest import SCENES, cornell, cornell_dict


def test_load_file_json():
    s = glint.load_file(SCENES / "cornell-box.json")
    assert (s.width, s.height, s.spp) == (784, 784, 64)


def test_load_dict_matches_file():
    d = cornell_dict(784)
    from_dict = glint.load_dict(d, base_dir=SCENES)
    from_file = glint.load_file(SCENES / "cornell-box.json")
    a = glint.render(from_dict, spp=1).image[::8, ::8]
    b = glint.render(from_file, spp=1).image[::8, ::8]
    np.testing.assert_array_equal(a, b)


def test_layers_the_scene_asks_for_follow_the_requested_ones():
    d = cornell_dict(16)
    d["film"]["aovs"] = ["depth", "albedo"]
    r = glint.render(glint.load_dict(d, base_dir=SCENES), spp=1, aovs=["albedo", "normal"])
    assert list(r.aovs) == ["albedo", "normal", "depth"]
    assert r.aovs["depth"].shape == (16, 16, 1)


def test_numpy_values_in_dict():
    d = cornell_dict(16)
    d["materials"]["red"]["reflectance"] = np.array([0.63, 0.065, 0.05])
    d["sampler"]["spp"] = np.int64(2)
    assert glint.load_dict(d, base_dir=SCENES).spp == 2


def test_defines_on_json_is_an_error():
    with pytest.raises(glint.SceneError, match="Mitsuba"):
        glint.load_file(SCENES / "cornell-box.json", spp=4)


def test_mitsuba_defines(tmp_path):
    xml = """<scene version="3.0.0">
  <default name="res" value="8"/>
  <sensor type="perspective">
    <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
  </sensor>
  <shape type="sphere"/>
  <emitter type="constant"/>
</scene>
"""
    path = tmp_path / "s.xml"
    path.write_text(xml)
    assert glint.load_file(path).width == 8
    assert glint.load_file(path, res=12).width == 12


def test_scene_error_carries_file_and_line(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40},\n  "film": {"width": 8, "height": 8},\n  "shapes": [ {"type": "teapot"} ]\n}\n')
    with pytest.raises(glint.SceneError) as e:
        glint.load_file(path)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.file is not None and err.file.endswith("bad.json")
    assert err.line == 3
    assert "teapot" in err.message
    assert str(err).startswith(err.file)


def test_missing_mesh_file_is_a_scene_error_at_render(tmp_path):
    d = cornell_dict(8)
    d["shapes"][0]["file"] = "no/such.obj"
    s = glint.load_dict(d, base_dir=SCENES)
    with pytest.raises(glint.SceneError, match="such.obj"):
        glint.render(s, spp=1)


def test_type_errors_name_the_argument():
    s = cornell(8)
    with pytest.raises(TypeError, match="path"):
        glint.load_file(42)
    with pytest.raises(TypeError, match="spp"):
        glint.render(s, spp="4")
    with pytest.raises(TypeError, match="scene"):
        glint.render("scenes/cornell-box.json")
    with pytest.raises(TypeError, match="threads"):
        glint.render(s, spp=1, threads=1.5)
    with pytest.raises(ValueError, match="aovs"):
        glint.render(s, spp=1, aovs=["nonsense"])


def quad_scene(shape: dict) -> dict:
    """A white square facing a camera, under a uniform sky."""
    return {
        "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
        "film": {"width": 48, "height": 48},
        "materials": {"white": {"type": "diffuse", "reflectance": 0.5}},
        "shapes": [dict(shape, material="white")],
        "lights": [{"type": "constant", "radiance": 1.0}],
    }


def test_in_memory_mesh_covers_what_the_primitive_covers():
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    indices = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    mesh = glint.load_dict(quad_scene({"type": "mesh", "positions": positions, "indices": indices}))
    rect = glint.load_dict(quad_scene({"type": "rectangle"}))
    a = glint.render(mesh, spp=4, aovs=["albedo"]).aovs["albedo"]
    b = glint.render(rect, spp=4, aovs=["albedo"]).aovs["albedo"]
    covered = a[..., 0] > 0.25
    assert 100 < covered.sum() < 48 * 48 - 100
    # Same square: the masks differ at most along its edges (4 sides of the square).
    side = int(np.sqrt(covered.sum()))
    assert (covered != (b[..., 0] > 0.25)).sum() <= 4 * side
    np.testing.assert_allclose(a[covered, :], 0.5, rtol=1e-5)


def test_in_memory_mesh_with_normals_and_uvs_and_bad_shapes():
    positions = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], dtype=np.float32)
    ok = {
        "type": "mesh",
        "positions": positions,
        "indices": [[0, 1, 2]],
        "normals": np.tile([0.0, 0.0, 1.0], (3, 1)),
        "uvs": np.zeros((3, 2)),
    }
    img = glint.render(glint.load_dict(quad_scene(ok)), spp=1).image
    assert np.isfinite(img).all() and img.max() > 0
    with pytest.raises(ValueError, match="positions"):
        glint.load_dict(quad_scene(dict(ok, positions=np.zeros((3, 2)))))
    with pytest.raises(TypeError, match="indices"):
        glint.load_dict(quad_scene(dict(ok, indices=[[0.0, 1.0, 2.0]])))
    bad_index = glint.load_dict(quad_scene(dict(ok, indices=[[0, 1, 7]])))
    with pytest.raises(glint.SceneError):
        glint.render(bad_index, spp=1)
