"""Denoising with Intel Open Image Denoise (the ``pyoidn`` wheel bundles the library)."""

from typing import Any, Optional

import numpy as np

_INSTALL = "glint.denoise needs Intel Open Image Denoise: pip install pyoidn"


def _pyoidn() -> Any:
    try:
        import pyoidn
    except ImportError as e:
        raise ImportError(_INSTALL) from e
    return pyoidn


def _image(a: Any, name: str, shape: Optional[tuple] = None) -> np.ndarray:
    if not isinstance(a, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not {type(a).__name__}")
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"{name}: expected shape (height, width, 3), got {a.shape}")
    if shape is not None and a.shape != shape:
        raise ValueError(f"{name}: shape {a.shape} differs from the image's {shape}")
    return np.ascontiguousarray(a, dtype=np.float32)


def _run_filter(pyoidn: Any, device: Any, inputs: dict, output: np.ndarray, **options: bool) -> None:
    flt = pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT)
    try:
        for name, image in inputs.items():
            flt.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3)
        flt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, output, pyoidn.OIDN_FORMAT_FLOAT3)
        for k, v in options.items():
            flt.set_bool(k, v)
        flt.set_quality(pyoidn.OIDN_QUALITY_HIGH)
        flt.commit()
        flt.execute()
        err = device.get_error()
        if err:
            raise RuntimeError(f"Open Image Denoise: {err}")
    finally:
        flt.release()


def denoise(image: np.ndarray, albedo: Optional[np.ndarray] = None, normal: Optional[np.ndarray] = None) -> np.ndarray:
    """Denoises a linear HDR image (height, width, 3) with Open Image Denoise.

    ``albedo`` and ``normal`` (the ``albedo`` and ``normal`` AOVs of the same render) guide
    it; they are denoised first and the result is then filtered with ``cleanAux``, as
    Blender Cycles' "accurate" prefilter does, so that their own noise is not copied into
    the image. A normal needs an albedo. Returns a new float32 array.
    """
    pyoidn = _pyoidn()
    color = _image(image, "image")
    aux = {}
    if normal is not None and albedo is None:
        raise ValueError("normal: needs an albedo too")
    device = pyoidn.Device()
    try:
        device.commit()
        err = device.get_error()
        if err:
            raise RuntimeError(f"Open Image Denoise: {err}")
        if albedo is not None:
            a = _image(albedo, "albedo", color.shape)
            clean = np.empty_like(a)
            _run_filter(pyoidn, device, {pyoidn.OIDN_IMAGE_ALBEDO: a}, clean)
            aux[pyoidn.OIDN_IMAGE_ALBEDO] = clean
        if normal is not None:
            n = _image(normal, "normal", color.shape)
            clean = np.empty_like(n)
            _run_filter(pyoidn, device, {pyoidn.OIDN_IMAGE_NORMAL: n}, clean)
            aux[pyoidn.OIDN_IMAGE_NORMAL] = clean
        out = np.empty_like(color)
        _run_filter(pyoidn, device, {pyoidn.OIDN_IMAGE_COLOR: color, **aux}, out, hdr=True, cleanAux=bool(aux))
    finally:
        device.release()
    return out
