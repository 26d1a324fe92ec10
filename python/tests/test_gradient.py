"""glint.render_gradient from Python: its arguments, its names (canonical and Mitsuba's),
determinism across threads, Ctrl-C and the GIL. Agreement with finite differences is tested
in Rust (crates/glint/tests/gradient.rs), with Mitsuba in test_gradient_mitsuba.py."""

import _thread
import pathlib
import signal
import threading

import numpy as np
import pytest

import glint
from conftest import cornell, counting_thread

RED = "materials.red.reflectance"


def ones(scene):
    return np.ones((scene.height, scene.width, 3), np.float32)


def test_shapes_and_bit_identity_across_threads():
    s = cornell(16)
    names = (RED, "shapes.5.emission")
    one = glint.render_gradient(s, names, ones(s), spp=4, seed=3, threads=1)
    two = glint.render_gradient(s, names, ones(s), spp=4, seed=3, threads=2)
    for n in names:
        assert one[n].shape == (3,) and one[n].dtype == np.float64
        assert one[n].tobytes() == two[n].tobytes(), n
    assert (one[RED] != glint.render_gradient(s, names, ones(s), spp=4, seed=4)[RED]).any()
    # A brighter red wall brightens the image: positive, and most of all in red.
    assert (one[RED] > 0).all() and one[RED][0] > one[RED][1]


def test_an_adjoint_image_scales_the_gradient():
    s = cornell(16)
    g = glint.render_gradient(s, (RED,), ones(s), spp=4, seed=1)[RED]
    half = glint.render_gradient(s, (RED,), 0.5 * ones(s), spp=4, seed=1)[RED]
    np.testing.assert_allclose(half, 0.5 * g, rtol=1e-6)


def test_mitsuba_keys_name_parameters_too(tmp_path):
    scene = tmp_path / "s.xml"
    scene.write_text(
        """<scene version="3.0.0">
        <sensor type="perspective"><transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
          <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film></sensor>
        <bsdf type="diffuse" id="paint"><rgb name="reflectance" value="0.5, 0.4, 0.3"/></bsdf>
        <shape type="sphere" id="ball"><ref id="paint"/></shape>
        <emitter type="constant" id="sky"><rgb name="radiance" value="1, 1, 1"/></emitter>
        </scene>"""
    )
    s = glint.load_file(scene)
    by_alias = glint.render_gradient(s, ("paint.reflectance.value", "sky.radiance.value"), ones(s), spp=4)
    canonical = glint.render_gradient(s, ("materials.paint.reflectance", "lights.sky.radiance"), ones(s), spp=4)
    assert by_alias["paint.reflectance.value"].tobytes() == canonical["materials.paint.reflectance"].tobytes()
    assert by_alias["sky.radiance.value"].tobytes() == canonical["lights.sky.radiance"].tobytes()
    with pytest.raises(glint.SceneError, match="geometry"):
        glint.render_gradient(s, ("ball.to_world",), ones(s), spp=1)


def test_bad_arguments_are_refused():
    s = cornell(16)
    with pytest.raises(ValueError, match="grad_image"):
        glint.render_gradient(s, (RED,), np.ones((15, 16, 3), np.float32), spp=1)
    with pytest.raises(ValueError, match="not finite"):
        glint.render_gradient(s, (RED,), np.full((16, 16, 3), np.nan, np.float32), spp=1)
    with pytest.raises(ValueError, match="spp"):
        glint.render_gradient(s, (RED,), ones(s), spp=0)
    with pytest.raises(glint.SceneError, match="no parameter called"):
        glint.render_gradient(s, ("materials.nothing.reflectance",), ones(s), spp=1)
    with pytest.raises(glint.SceneError, match="twice"):
        glint.render_gradient(s, (RED, RED), ones(s), spp=1)
    with pytest.raises(glint.SceneError, match="not differentiable"):
        glint.render_gradient(s, ("camera.fov",), ones(s), spp=1)


def test_keyboard_interrupt_stops_a_gradient_and_other_threads_run():
    s = cornell(64)
    glint.render_gradient(s, (RED,), ones(s), spp=1)  # built first
    # As in test_threads: Python's own SIGINT handler, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    try:
        with counting_thread() as counter, pytest.raises(KeyboardInterrupt):
            glint.render_gradient(s, (RED,), ones(s), spp=1_000_000)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    # The GIL was free while the gradient ran; the scene still works.
    assert counter[0] > 10
    assert np.isfinite(glint.render_gradient(s, (RED,), ones(s), spp=1)[RED]).all()


def test_texels_are_edited_as_images(tmp_path):
    scene = glint.load_file(pathlib.Path(__file__).resolve().parents[2] / "tests" / "scenes" / "gradients" / "textured.xml")
    params = glint.traverse(scene)
    name = "materials.floor.reflectance"
    texels = params[name]
    assert texels.shape == (8, 8, 3) and texels.dtype == np.float32
    before = glint.render(scene, spp=4, seed=1).image
    params[name] = np.zeros((4, 2, 3), np.float32)  # any size
    params.update()
    assert glint.traverse(scene)[name].shape == (4, 2, 3)
    assert glint.render(scene, spp=4, seed=1).image.sum() < before.sum()
    with pytest.raises(TypeError, match="height, width, 3"):
        params[name] = np.zeros((4, 4), np.float32)
    with pytest.raises(glint.SceneError, match="not finite"):
        params.update({name: np.full((2, 2, 3), np.nan, np.float32)})
    # Nothing changed by the refused edit.
    assert glint.traverse(scene)[name].shape == (4, 2, 3)


def test_traverse_reads_an_image_only_when_asked(tmp_path):
    gradients = pathlib.Path(__file__).resolve().parents[2] / "tests" / "scenes" / "gradients"
    for f in ("textured.xml", "texture.exr"):
        (tmp_path / f).write_bytes((gradients / f).read_bytes())
    scene = glint.load_file(tmp_path / "textured.xml")
    (tmp_path / "texture.exr").unlink()
    params = glint.traverse(scene)  # lists the texture without reading its file
    assert "materials.floor.reflectance" in params
    assert params["shapes.light.emission"].shape == (3,)
    with pytest.raises(KeyError, match="cannot be read"):
        params["floor.reflectance.data"]
