"""glint: a physically based CPU renderer, from Python.

Load a scene, render it to a numpy array, edit its parameters and render again, denoise::

    import glint
    scene = glint.load_file("scenes/cornell-box.json")
    result = glint.render(scene, spp=64)          # result.image: float32 (H, W, 3), linear
    params = glint.traverse(scene)
    params["shapes.5.emission"] *= 2              # brighter light; no BVH is rebuilt
    params.update()
    brighter = glint.render(scene, spp=64).image
    glint.write_image("cornell.exr", brighter)

The image of ``glint.render(scene, spp=N, seed=S)`` is bit-identical to that of
``glint render SCENE -o out.pfm --spp N --seed S``. Rendering releases the GIL, stops on
Ctrl-C (KeyboardInterrupt) and can be limited to ``threads`` worker threads.
"""

import json
import os
from collections.abc import MutableMapping
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Iterator, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _glint
from ._errors import SceneError
from ._glint import DEFAULT_PASS_SPP, Preview, Scene, Session
from ._denoise import denoise

__all__ = [
    "DEFAULT_PASS_SPP",
    "Preview",
    "RenderResult",
    "Scene",
    "SceneError",
    "SceneParameters",
    "Session",
    "denoise",
    "load_dict",
    "load_file",
    "read_image",
    "render",
    "render_gradient",
    "traverse",
    "write_image",
]

AOV_NAMES: Tuple[str, ...] = tuple(_glint.AOV_NAMES)
#: The integrators ``render(integrator=...)`` takes.
INTEGRATORS: Tuple[str, ...] = tuple(_glint.INTEGRATORS)


def _path(value: Any, arg: str) -> str:
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{arg} must be a path (str or os.PathLike), not {type(value).__name__}")
    return os.fspath(value)


def load_file(
    path: Union[str, os.PathLike], *, camera: Union[str, int, None] = None, **defines: Any
) -> Scene:
    """Reads a scene file of any format glint reads (.json, Mitsuba .xml, glTF .gltf and
    .glb, .obj, .ply).

    ``camera`` picks a glTF file's camera by index or name, as the command line's
    ``--camera`` does (default: the first camera node of the default scene). Other keyword
    arguments override the Mitsuba scene's ``<default>`` values, as the command line's
    ``-D name=value`` does (``spp=64``); they are an error for other formats.
    Raises SceneError (with ``.file``, ``.line``) for a scene that cannot be read.
    """
    path = _path(path, "path")

    def text(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (str, int, float)):
            return str(v)
        raise TypeError(f"define {v!r}: expected a str, int, float or bool")

    cam = None if camera is None else str(camera)
    return _glint.load_file(path, [(k, text(v)) for k, v in defines.items()], cam)


def _json_default(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"a {type(o).__name__} in the scene dict cannot be written as JSON")


def _mesh_arrays(index: int, shape: Mapping[str, Any]) -> Dict[str, Any]:
    """The arrays of an in-memory mesh shape, checked and converted for the Rust side."""

    def array(name: str, dtype: Any, cols: int, required: bool) -> Optional[np.ndarray]:
        v = shape.get(name)
        if v is None:
            if required:
                raise ValueError(f"shapes[{index}] (mesh): needs '{name}'")
            return None
        a = np.asarray(v)
        if a.ndim != 2 or a.shape[1] != cols:
            raise ValueError(f"shapes[{index}].{name}: expected shape (N, {cols}), got {a.shape}")
        if dtype == np.uint32:
            if not np.issubdtype(a.dtype, np.integer):
                raise TypeError(f"shapes[{index}].{name}: expected integers, got {a.dtype}")
            if a.size and (a.min() < 0 or a.max() > np.iinfo(np.uint32).max):
                raise ValueError(f"shapes[{index}].{name}: indices must be non-negative 32-bit")
        return np.ascontiguousarray(a, dtype=dtype)

    out = {
        "index": index,
        "positions": array("positions", np.float32, 3, True),
        "indices": array("indices", np.uint32, 3, True),
        "normals": array("normals", np.float32, 3, False),
        "uvs": array("uvs", np.float32, 2, False),
    }
    if out["normals"] is not None and len(out["normals"]) != len(out["positions"]):
        raise ValueError(f"shapes[{index}].normals: one per position expected")
    if out["uvs"] is not None and len(out["uvs"]) != len(out["positions"]):
        raise ValueError(f"shapes[{index}].uvs: one per position expected")
    return out


def load_dict(d: Mapping[str, Any], base_dir: Union[str, os.PathLike] = ".") -> Scene:
    """Makes a scene from a dict with the schema of glint's JSON scenes (docs/scene-format.md).

    Relative file names resolve against ``base_dir``. numpy arrays may stand for lists.
    A shape may also be an in-memory mesh: ``{"type": "mesh", "positions": (N, 3) floats,
    "indices": (M, 3) ints, "normals": (N, 3) (optional), "uvs": (N, 2) (optional)}`` with
    the other shape keys (material, transform, emission, ...) as usual.
    """
    if not isinstance(d, Mapping):
        raise TypeError(f"d must be a dict, not {type(d).__name__}")
    base = _path(base_dir, "base_dir")
    d = dict(d)
    meshes = []
    shapes = d.get("shapes")
    if isinstance(shapes, (list, tuple)):
        replaced = []
        for i, s in enumerate(shapes):
            if isinstance(s, Mapping) and s.get("type") == "mesh":
                meshes.append(_mesh_arrays(i, s))
                # The JSON reader sees a placeholder with the shape's other keys; its
                # geometry is then replaced by the arrays.
                rest = {k: v for k, v in s.items() if k not in ("positions", "indices", "normals", "uvs")}
                rest["type"] = "rectangle"
                replaced.append(rest)
            else:
                replaced.append(s)
        d["shapes"] = replaced
    text = json.dumps(d, default=_json_default)
    return _glint.load_json(text, os.path.join(base, "<dict>.json"), meshes)


@dataclass
class RenderResult:
    """What ``render`` returns.

    ``image``: float32 (height, width, 3), linear RGB. ``aovs``: layer name -> float32
    (height, width, channels). ``spp``: samples per pixel rendered (fewer than asked if
    the time limit was reached). ``stats``: rays, seconds and the scene's build counters
    (``mesh_bvh_builds``, ``top_level_builds``: BVHs built for this scene so far).
    """

    image: np.ndarray
    aovs: Dict[str, np.ndarray] = field(default_factory=dict)
    spp: int = 0
    stats: Dict[str, Any] = field(default_factory=dict)


def _check_scene(scene: Any) -> Scene:
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a glint.Scene (from load_file or load_dict), not {type(scene).__name__}")
    return scene


def _check_int(value: Any, arg: str, minimum: int) -> Optional[int]:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{arg} must be an int, not {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{arg} must be at least {minimum}, got {value}")
    return int(value)


def render(
    scene: Scene,
    spp: Optional[int] = None,
    seed: int = 0,
    time_limit: Optional[float] = None,
    aovs: Sequence[str] = (),
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    preview: Union[bool, str] = False,
    denoise: bool = False,
    **overrides: Any,
) -> RenderResult:
    """Renders the scene and returns a RenderResult.

    ``spp``: samples per pixel (default: the scene's). ``seed``: the random seed.
    ``time_limit``: seconds after which no pass starts. ``aovs``: extra layers (albedo,
    normal, depth, position, variance, spp, bvh-cost); layers the scene asks for follow them. ``threads``: worker threads
    (default: all cores). ``progress(done_spp, total_spp)``: called at most four times a
    second and once at the end. Ctrl-C raises KeyboardInterrupt. ``preview``: True (or an
    address, "HOST:PORT") serves a live view of the render in the browser, shown inline in
    Jupyter and its address printed elsewhere (``Session.preview``); its Stop button ends
    the render after the current pass, and the result holds the passes done. ``denoise``: the
    image denoised by Open Image Denoise (as ``glint render --denoise``: the albedo and normal
    layers guide it, and the image as rendered is the layer ``noisy``).

    Keyword overrides of the scene's settings, as the command line's flags (the scene is
    not changed for later renders): ``integrator`` (one of ``INTEGRATORS``), ``max_depth``
    (path tracers: segments, -1 unbounded; whitted: recursion depth), ``strategy`` (mis,
    light, bsdf), ``light_selection`` (power, tree, auto, uniform, area), ``sampler`` (sobol,
    independent), ``width``, ``height``.
    """
    s = make_session(scene, spp=spp, seed=seed, aovs=aovs, threads=threads, denoise=denoise, **overrides)
    if preview is not False and preview is not None:
        if not isinstance(preview, (bool, str)):
            raise TypeError(f"preview must be True or an address, not {type(preview).__name__}")
        show_preview(s.preview(None if preview is True else preview))
    if time_limit is not None and not isinstance(time_limit, (int, float)):
        raise TypeError(f"time_limit must be a number of seconds, not {type(time_limit).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable")
    s.render_passes(None, time_limit, progress)
    image, layers = s.outputs(denoise)
    return RenderResult(image=image, aovs=dict(layers), spp=s.spp, stats=dict(s.stats))


def render_gradient(
    scene: Scene,
    params: Sequence[str],
    grad_image: Any,
    spp: Optional[int] = None,
    seed: int = 0,
    threads: Optional[int] = None,
) -> Dict[str, np.ndarray]:
    """The gradient of a loss on the image with respect to scene parameters.

    Given ``grad_image``, the loss's derivative with respect to each pixel and channel of
    the image (float, shape (H, W, 3)), returns for each name in ``params`` (names as
    ``traverse`` gives them) the gradient of ``sum(grad_image * image)``, a float64 array
    shaped like the parameter: () for a number, (3,) for a colour. ``image`` is what
    ``render(scene, spp=spp, seed=seed)`` makes with the scene's path integrator and a box
    filter. So for any loss computed in numpy, PyTorch or JAX, pass its gradient with
    respect to the image, and get its gradient with respect to the parameters (chain rule).

    Path replay backpropagation (Mitsuba's ``prb``): memory does not grow with path length,
    and the result is the same bits for any ``threads`` (fixed-point sums). Gradients flow
    through materials and lights, not through geometry or the camera: asking for those, or
    for a parameter of a material that only has delta lobes, raises ``SceneError``. See
    docs/differentiable.md. Releases the GIL; Ctrl-C raises KeyboardInterrupt.
    """
    scene = _check_scene(scene)
    if isinstance(params, str):
        params = (params,)
    names = [str(p) for p in params]
    g = np.ascontiguousarray(np.asarray(grad_image, dtype=np.float32))
    if g.ndim != 3:
        raise ValueError(f"grad_image: expected shape (H, W, 3), got {g.shape}")
    n = _check_int(spp, "spp", 1)
    if n is None:
        n = scene.spp
    threads = _check_int(threads, "threads", 1)
    if not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed: {seed!r} is not a non-negative integer")
    return dict(_glint.render_gradient(scene, names, g, n, seed, threads))


#: Render overrides ``render`` and ``make_session`` take, and the type of each.
_OVERRIDES = {
    "integrator": str,
    "max_depth": int,
    "strategy": str,
    "light_selection": str,
    "sampler": str,
    "width": int,
    "height": int,
}


def _check_overrides(overrides: Mapping[str, Any]) -> Dict[str, Any]:
    checked = {}
    for name, value in overrides.items():
        kind = _OVERRIDES.get(name)
        if kind is None:
            raise TypeError(f"unexpected keyword argument {name!r}")
        if value is None:
            continue
        if kind is int:
            value = _check_int(value, name, -(2**63))
        elif not isinstance(value, str):
            raise TypeError(f"{name} must be a str, not {type(value).__name__}")
        checked[name] = value
    return checked


def show_preview(p: Preview) -> None:
    """Shows a preview inline in Jupyter (IPython), or prints its address on stderr."""
    import sys

    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    if shell is not None and getattr(shell, "kernel", None) is not None:
        from IPython.display import display

        display(p)
    else:
        print(f"glint: preview at {p.url}", file=sys.stderr, flush=True)


def make_session(
    scene: Scene,
    spp: Optional[int] = None,
    seed: int = 0,
    aovs: Sequence[str] = (),
    threads: Optional[int] = None,
    denoise: bool = False,
    **overrides: Any,
) -> Session:
    """``Session(...)`` with its arguments checked (TypeError naming the argument);
    ``denoise`` and ``overrides`` as ``render`` takes them."""
    _check_scene(scene)
    spp = _check_int(spp, "spp", 1)
    seed = _check_int(seed, "seed", 0)
    threads = _check_int(threads, "threads", 1)
    if isinstance(aovs, str) or not all(isinstance(a, str) for a in aovs):
        raise TypeError("aovs must be a sequence of layer names (str)")
    if not isinstance(denoise, bool):
        raise TypeError(f"denoise must be a bool, not {type(denoise).__name__}")
    if denoise:
        _glint.find_denoiser()  # before any sample: a missing one is an ImportError now
    return Session(scene, spp, seed, list(aovs), threads, None, _check_overrides(overrides), denoise)


def read_image(path: Union[str, os.PathLike]) -> np.ndarray:
    """Reads a PNG (decoded from sRGB), EXR or PFM file: float32 (height, width, 3), linear."""
    return _glint.read_image(_path(path, "path"))


def write_image(
    path: Union[str, os.PathLike], image: np.ndarray, aovs: Optional[Mapping[str, np.ndarray]] = None
) -> None:
    """Writes a (height, width, 3) linear RGB image as PNG (sRGB, 8 bit), EXR or PFM,
    chosen by extension, and ``aovs`` (name -> (height, width, channels)) as the command
    line writes a render's layers: in an EXR file as channels beside the image
    (``albedo.R``, ``normal.X``, ...); for PNG and PFM each as its own PNG, ``OUT.NAME.png``,
    mapped to a visible range."""
    path = _path(path, "path")
    if not isinstance(image, np.ndarray):
        raise TypeError(f"image must be a numpy array, not {type(image).__name__}")
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"image: expected shape (height, width, 3), got {image.shape}")
    layers = []
    for name, a in (aovs or {}).items():
        a = np.asarray(a, dtype=np.float32)
        if a.ndim == 2:
            a = a[:, :, None]
        layers.append((name, np.ascontiguousarray(a)))
    _glint.write_image(path, np.ascontiguousarray(image, dtype=np.float32), layers)


#: The value of an image parameter whose texels are not read yet.
_UNREAD = object()


class SceneParameters(MutableMapping):
    """The editable parameters of a scene, by name (see ``traverse``).

    Values are floats, colours (numpy arrays of 3) or 4x4 matrices (numpy arrays).
    Assigning stores the value; ``update()`` applies every stored change at once and
    rebuilds as little as it can: material, emission, light and camera edits rebuild no
    BVH; a shape's ``to_world`` rebuilds only the top-level BVH.
    """

    def __init__(self, scene: Scene):
        self._scene = _check_scene(scene)
        self._values: Dict[str, Any] = {}
        self._kinds: Dict[str, str] = {}
        self._pending: Dict[str, Any] = {}
        self._reload()

    def _reload(self) -> None:
        self._values.clear()
        for name, v in self._scene._params():
            if isinstance(v, tuple):
                kind, data = v
                self._kinds[name] = kind
                # An image's texels are read from its file only when asked for.
                self._values[name] = _UNREAD if data is None else np.array(data, dtype=np.float64)
            else:
                self._kinds[name] = "float"
                self._values[name] = float(v)

    def _name(self, key: str) -> str:
        """The name ``traverse`` lists for ``key``: that name or an alias of it (Mitsuba's
        key, such as ``ball.to_world``). KeyError for an unknown or ambiguous one."""
        if key in self._values:
            return key
        if not isinstance(key, str):
            raise KeyError(key)
        name = self._scene._param_name(key)
        if name not in self._values:
            # An unset camera transform has a name but no value to edit.
            raise KeyError(f"no parameter called {key!r}")
        return name

    def __getitem__(self, key: str) -> Any:
        key = self._name(key)
        if key in self._pending:
            v = self._pending[key]
        else:
            v = self._values[key]
            if v is _UNREAD:
                _, data = self._scene._param(key)
                v = self._values[key] = np.array(data, dtype=np.float32)
        return v.copy() if isinstance(v, np.ndarray) else v

    def __setitem__(self, key: str, value: Any) -> None:
        key = self._name(key)
        kind = self._kinds[key]
        if kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
                raise TypeError(f"{key} takes a number, not {type(value).__name__}")
            self._pending[key] = float(value)
            return
        if kind == "image":
            try:
                a = np.array(value, dtype=np.float32)
            except (TypeError, ValueError):
                raise TypeError(f"{key} takes an image (height, width, 3), not {type(value).__name__}") from None
            if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] == 0 or a.shape[1] == 0:
                raise TypeError(f"{key} takes an image of shape (height, width, 3), not {a.shape}")
            self._pending[key] = a
            return
        try:
            a = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"{key} takes {'3 numbers' if kind == 'color' else 'a 4x4 matrix'}, not {value!r}") from None
        if kind == "color" and a.ndim == 0:
            a = np.full(3, float(a))
        expected = (3,) if kind == "color" else (4, 4)
        if a.shape != expected:
            raise TypeError(f"{key} takes an array of shape {expected}, not {a.shape}")
        self._pending[key] = a

    def __contains__(self, key: object) -> bool:
        # Without reading the value (an image's texels come from its file).
        try:
            self._name(key)  # type: ignore[arg-type]
        except KeyError:
            return False
        return True

    def __delitem__(self, key: str) -> None:
        raise TypeError("scene parameters cannot be removed")

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        lines = [f"  {k!r}: {self[k]!r}," for k in self]
        return "SceneParameters({\n" + "\n".join(lines) + "\n})"

    def update(self, other: Any = (), **kwargs: Any) -> None:  # type: ignore[override]
        """Stores the given values (as ``dict.update``), then applies every stored change
        to the scene. Raises SceneError (nothing changed) for values the scene cannot take."""
        for k, v in dict(other, **kwargs).items():
            self[k] = v
        edits, images = [], []
        for k, v in self._pending.items():
            kind = self._kinds[k]
            if kind == "image":
                images.append((k, np.ascontiguousarray(v, dtype=np.float32)))
                continue
            values = [v] if kind == "float" else [float(x) for x in np.ravel(v)]
            edits.append((k, kind, values))
        if edits or images:
            self._scene._set_params(edits, images)
        self._pending.clear()
        self._reload()


def traverse(scene: Scene) -> SceneParameters:
    """The scene's editable parameters, a dict-like SceneParameters.

    Names: ``materials.NAME.reflectance`` (and ``kd``, ``diffuse`` when constant, ``ks``,
    ``exponent``, ``eta``, ``k``, ``specular``, ``reflect``, ``transmit``, ``alpha``),
    ``lights.ID.radiance`` / ``intensity`` / ``irradiance`` / ``scale``,
    ``shapes.ID.emission``, ``shapes.ID.to_world``, ``camera.fov``, ``camera.to_world``.
    A shape or light is named by its id in the file (Mitsuba's ``id``) where no other
    shares it, else by its index (``shapes.0.to_world``).
    Mitsuba's keys are accepted as aliases when reading and assigning:
    ``ball.to_world``, ``ball.emitter.radiance.value``, ``paint.reflectance.value``,
    ``plastic.diffuse_reflectance.value``, ``sun.intensity.value``,
    ``PerspectiveCamera.to_world``, ``PerspectiveCamera.x_fov`` and so on.
    Assign, then call ``update()``.
    """
    return SceneParameters(scene)
