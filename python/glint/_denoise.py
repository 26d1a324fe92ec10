"""Denoising with Intel Open Image Denoise: the library's denoiser (the one ``glint render
--denoise`` uses), which loads the copy the ``pyoidn`` wheel bundles."""

from typing import Any, Optional

import numpy as np

from . import _glint


def _image(a: Any, name: str, shape: Optional[tuple] = None) -> np.ndarray:
    if not isinstance(a, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not {type(a).__name__}")
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"{name}: expected shape (height, width, 3), got {a.shape}")
    if shape is not None and a.shape != shape:
        raise ValueError(f"{name}: shape {a.shape} differs from the image's {shape}")
    return np.ascontiguousarray(a, dtype=np.float32)


def denoise(image: np.ndarray, albedo: Optional[np.ndarray] = None, normal: Optional[np.ndarray] = None) -> np.ndarray:
    """Denoises a linear HDR image (height, width, 3) with Open Image Denoise.

    ``albedo`` and ``normal`` (the ``albedo`` and ``normal`` AOVs of the same render) guide
    it; they are denoised first and the result is then filtered with ``cleanAux``, as
    Blender Cycles' "accurate" prefilter does, so that their own noise is not copied into
    the image. A normal needs an albedo. Returns a new float32 array. Raises ImportError,
    saying how to install it, where no Open Image Denoise library is found.
    """
    color = _image(image, "image")
    if normal is not None and albedo is None:
        raise ValueError("normal: needs an albedo too")
    a = None if albedo is None else _image(albedo, "albedo", color.shape)
    n = None if normal is None else _image(normal, "normal", color.shape)
    return _glint.denoise(color, a, n)
