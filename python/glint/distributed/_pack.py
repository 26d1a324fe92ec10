"""A scene packed for workers that share no file system with the driver: its description
(JSON, the scene file and its includes already parsed into it, edits and sampling applied)
and the bytes of every file its build reads, under a content hash that workers cache the
built world by."""

import hashlib
import os
from dataclasses import dataclass
from typing import Dict, Tuple

from .. import _glint


@dataclass(frozen=True)
class ScenePack:
    """``files`` maps each path as the description names it to (where it goes in the
    worker's copy of the tree, its bytes): relative places keep an OBJ file's ``mtllib``
    names pointing at the copies of its material files."""

    description: str
    files: Dict[str, Tuple[str, bytes]]
    instanced: Tuple[int, ...]
    key: str

    @property
    def size(self) -> int:
        """Bytes shipped: the description and the files."""
        return len(self.description) + sum(len(b) for _, b in self.files.values())


def pack(scene: "_glint.Scene") -> ScenePack:
    """Packs a loaded scene (its sampling as the render will use it)."""
    # A side file that is missing (an OBJ file's material library) is left out: the
    # worker's reader goes on without it, as the driver's does.
    contents: Dict[str, bytes] = {
        os.fspath(p): data for p, data in scene.build_files() if data is not None
    }
    absolute = {p: os.path.abspath(p) for p in contents}
    root = os.path.commonpath([os.path.dirname(a) for a in absolute.values()]) if absolute else ""
    files = {p: (os.path.relpath(absolute[p], root), data) for p, data in contents.items()}
    description = scene.description_json()
    instanced = tuple(scene._instanced())
    h = hashlib.sha256()
    for part in (description.encode(), repr(instanced).encode()):
        h.update(len(part).to_bytes(8, "little") + part)
    for path in sorted(files):
        place, data = files[path]
        for part in (path.encode("utf-8", "surrogateescape"), place.encode("utf-8", "surrogateescape"), data):
            h.update(len(part).to_bytes(8, "little") + part)
    return ScenePack(description, files, instanced, h.hexdigest())


def unpack(p: ScenePack, folder: str) -> "_glint.Scene":
    """Writes the pack's files under ``folder`` and loads the scene reading them there."""
    remap = {}
    for path, (place, data) in p.files.items():
        target = os.path.join(folder, place)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as f:
            f.write(data)
        remap[path] = target
    return _glint.load_description(p.description, remap, list(p.instanced))
