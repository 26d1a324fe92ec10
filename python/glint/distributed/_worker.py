"""What runs on the workers: one Ray task renders one block (a pixel region times a pass
range) through a glint Session and returns the film block as bytes. Each worker process
builds a scene's world once, on its first task of that scene, and keeps it for the next
tasks (Ray reuses worker processes), keyed by the scene pack's content hash."""

import os
import shutil
import tempfile
import time
from collections import OrderedDict
from typing import Any, Dict, List, Sequence, Tuple

from .. import Session
from . import _pack

#: Built scenes a worker process keeps: two, so that the frames of an animation, which
#: arrive in order, do not rebuild one another.
CACHED_SCENES = 2

_scenes: "OrderedDict[str, Any]" = OrderedDict()


def _scene(key: str, pack_ref: Any) -> Tuple[Any, bool]:
    """The built scene of this pack, and whether it was built now."""
    if key in _scenes:
        _scenes.move_to_end(key)
        return _scenes[key], False
    import ray

    pack = ray.get(pack_ref)
    # The files are needed only while the world is built; nothing is left on disk.
    folder = tempfile.mkdtemp(prefix="glint-scene-")
    try:
        scene = _pack.unpack(pack, folder)
        scene.build()
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    _scenes[key] = scene
    while len(_scenes) > CACHED_SCENES:
        _scenes.popitem(last=False)
    return scene, True


def render_block(
    key: str,
    pack_box: List[Any],
    spp: int,
    seed: int,
    aovs: Sequence[str],
    threads: int,
    region: Tuple[int, int, int, int],
    passes: Tuple[int, int],
) -> Tuple[bytes, Dict[str, Any]]:
    """Renders passes ``passes`` of pixels ``region``. ``pack_box`` holds the pack's object
    reference inside a list, so that Ray hands the reference over rather than the pack
    itself (fetched only when the scene is not built here yet)."""
    start = time.perf_counter()
    scene, built = _scene(key, pack_box[0])
    session = Session(scene, spp, seed, list(aovs), threads, region)
    session.render_passes(passes[1] - passes[0], None, None, passes[0])
    stats = dict(session.stats)
    stats.update(built=built, pid=os.getpid(), task_seconds=time.perf_counter() - start)
    return session.film_bytes(), stats
