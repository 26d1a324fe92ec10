"""glTF 2.0 through the Python package: a .glb loads, ``camera=`` picks its cameras by name
and index, and ``traverse`` names its materials and lights by their glTF names."""

import json
import struct

import numpy as np
import pytest

import glint


def write_glb(path, light_intensity=2000.0):
    """A white quad (material "paint") at z = 0 lit by a point light "bulb" at z = 1, seen
    by camera "front" (node "eye", 3 units away on +z) and camera "side" (looking along -x
    from x = 3, so the quad is seen edge-on)."""
    positions = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    binary = positions + indices + b"\0\0"
    # The side camera: rotated 90 degrees about +y, so its -z looks along -x.
    s = 0.5 ** 0.5
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "name": "bulb", "intensity": light_intensity}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"mesh": 0},
            {"name": "eye", "camera": 0, "translation": [0, 0, 3]},
            {"camera": 1, "translation": [3, 0, 0], "rotation": [0, s, 0, s]},
            {"translation": [0, 0, 1], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "cameras": [
            {"name": "front", "type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}},
            {"name": "side", "type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}},
        ],
        "materials": [
            {"name": "paint", "doubleSided": True, "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    return path


def image(scene):
    return glint.render(scene, spp=4, width=24, height=24).image


def test_a_glb_loads_and_camera_picks_by_name_or_index(tmp_path):
    glb = write_glb(tmp_path / "quad.glb")
    front = image(glint.load_file(glb))
    assert np.isfinite(front).all() and front.max() > 0
    np.testing.assert_array_equal(image(glint.load_file(glb, camera="front")), front)
    np.testing.assert_array_equal(image(glint.load_file(glb, camera=0)), front)
    np.testing.assert_array_equal(image(glint.load_file(glb, camera="eye")), front)
    side = image(glint.load_file(glb, camera="side"))
    np.testing.assert_array_equal(image(glint.load_file(glb, camera=1)), side)
    # Seen edge-on, the quad covers almost nothing of the side view.
    assert (front.max(axis=2) > 0).sum() > 4 * (side.max(axis=2) > 0).sum()
    with pytest.raises(glint.SceneError, match="nope"):
        glint.load_file(glb, camera="nope")
    with pytest.raises(glint.SceneError, match="camera 5: no camera"):
        glint.load_file(glb, camera=5)


def test_traverse_names_materials_and_lights_by_their_gltf_names(tmp_path):
    scene = glint.load_file(write_glb(tmp_path / "quad.glb"))
    params = glint.traverse(scene)
    assert {"materials.paint.base_color", "materials.paint.roughness", "lights.bulb.intensity"} <= set(params)
    # 2000 cd at 683 lm/W.
    np.testing.assert_allclose(params["lights.bulb.intensity"], [2000 / 683] * 3, rtol=1e-6)
    before = image(scene)
    params["lights.bulb.intensity"] = params["lights.bulb.intensity"] * 2
    params.update()
    np.testing.assert_allclose(image(scene), 2 * before, rtol=1e-6, atol=1e-9)
    params["materials.paint.base_color"] = [0.0, 0.0, 0.0]
    params.update()
    # A black dielectric keeps its specular layer only: far darker than white.
    assert image(scene).sum() < 0.5 * 2 * before.sum()
