"""Rendering on a Ray cluster, bit-identical to a local render.

::

    import glint.distributed
    result = glint.distributed.render("scenes/cornell-box.json", spp=256, out="cornell.exr")
    # or on a running cluster: address="HEAD:6379" (see docs/distributed.md)

The render is cut into tasks of (pixel tile x pass range). The driver loads the scene and
builds it once (bad input fails here, with the command line's one-line error, before any
task is submitted), packs the description and the bytes of every file its build reads
into Ray's object store once, and keeps every worker slot busy; each worker process builds
the world once per scene and renders its tasks into film blocks, which the driver adds
into the film. The film's sums are exact, so the image is bit-identical to ``glint.render``
and ``glint render`` with the same seed, spp and pass size (the defaults are the same).

A worker process killed mid-task has its task run again by Ray (``max_retries``); the
driver can checkpoint the film (``checkpoint=``, the format ``glint resume`` reads), and a
render given ``resume=`` a checkpoint renders only what it lacks. Ctrl-C cancels the tasks
in flight, writes the image so far (and the checkpoint) and raises KeyboardInterrupt.
"""

import os
import time
from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Sequence, Tuple, Union

from .. import Preview, RenderResult, Scene, load_file, make_session, show_preview
from . import _pack, _plan
from ._driver import Driver, Frame, Progress, write_frame

__all__ = ["Progress", "render"]

_Path = Union[str, os.PathLike]


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise ImportError("glint.distributed needs Ray: pip install ray") from None
    return ray


def _address(address: Optional[str]) -> str:
    """What ``ray.init`` is given. No address: ``RAY_ADDRESS`` if set, else a new local
    instance ("local"; plain ``ray.init()`` would join whatever cluster ``ray start`` last
    started on this machine). Given an address, Ray's token authentication is turned on if
    a token is at hand (``RAY_AUTH_TOKEN``, ``RAY_AUTH_TOKEN_PATH`` or ``~/.ray/auth_token``)
    and ``RAY_AUTH_MODE`` is unset, as Ray does for a cluster it finds itself: ``ray start
    --head`` turns authentication on when the token file exists, but Ray leaves it off for a
    driver given an explicit address, which the cluster then refuses. A cluster without
    authentication accepts a driver that sends a token."""
    if address is None:
        address = os.environ.get("RAY_ADDRESS") or "local"
    if address != "local" and "RAY_AUTH_MODE" not in os.environ:
        import logging

        try:
            # What Ray does itself for a cluster it finds on its own (Ray 2.5x and later).
            from ray._private.authentication import authentication_token_setup as auth
        except ImportError:
            return address
        quiet = logging.getLogger(auth.__name__)
        level = quiet.level
        quiet.setLevel(logging.ERROR)  # not "token authentication is enabled" on every call
        try:
            auth.maybe_enable_token_auth_if_token_available(warn_if_disabled=False)
        finally:
            quiet.setLevel(level)
    return address


def _per_frame(value: Any, n: int, arg: str) -> List[Optional[str]]:
    """One path per frame: None, a list of n, or (for several frames) a pattern with
    ``{frame}`` (``"frame-{frame:03d}.exr"``)."""
    if value is None:
        return [None] * n
    if isinstance(value, (list, tuple)):
        if len(value) != n:
            raise ValueError(f"{arg}: {len(value)} paths for {n} frames")
        return [None if v is None else os.fspath(v) for v in value]
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{arg} must be a path, not {type(value).__name__}")
    value = os.fspath(value)
    if n == 1:
        return [value]
    if "{frame" not in value:
        raise ValueError(f"{arg}: for {n} frames give a list of paths or a pattern with {{frame}}")
    return [value.format(frame=i) for i in range(n)]


def _check_count(value: Any, arg: str) -> Optional[int]:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{arg} must be an int, not {type(value).__name__}")
    if value < 1:
        raise ValueError(f"{arg} must be at least 1, got {value}")
    return value


def _load(scene: Any) -> "tuple[Scene, str]":
    if isinstance(scene, Scene):
        return scene, "scene"
    if isinstance(scene, (str, os.PathLike)):
        return load_file(scene), os.fspath(scene)
    raise TypeError(f"scene must be a path or a glint.Scene, not {type(scene).__name__}")


def render(
    scene: Union[_Path, Scene, Sequence[Union[_Path, Scene]]],
    spp: Optional[int] = None,
    seed: int = 0,
    out: Any = None,
    address: Optional[str] = None,
    tile: int = 128,
    passes_per_task: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    resume: Any = None,
    *,
    aovs: Sequence[str] = (),
    checkpoint: Any = None,
    checkpoint_every: float = 60.0,
    cpus_per_task: int = 1,
    max_retries: int = 5,
    report: Optional[Callable[[Progress], Any]] = None,
    preview: Union[bool, str] = False,
    denoise: bool = False,
    **overrides: Any,
) -> Union[RenderResult, List[RenderResult]]:
    """Renders on Ray and returns what ``glint.render`` returns (a list of them for a
    list of scenes, the frames of an animation, which share the workers).

    ``scene``: a scene file or a loaded ``glint.Scene`` (edits included), or a list.
    ``spp``, ``seed``, ``aovs``: as ``glint.render``. ``out``: image to write (layers
    as the command line writes them); for several frames a list or a pattern with ``{frame}``. ``address``: the Ray
    cluster (``None``: a local Ray instance, started and stopped here; a Ray already
    initialised in this process is used as it is). ``tile``: tile side in pixels.
    ``passes_per_task``: default about 24 tasks per worker slot. ``progress(done_spp,
    total_spp)``: at most four times a second and at the end. ``resume``: a checkpoint to
    continue (its output is the default ``out``). ``checkpoint``: where to write the film
    every ``checkpoint_every`` seconds, at the end and on Ctrl-C (default: the ``resume``
    file). ``cpus_per_task``: CPUs (and threads) per task. ``max_retries``: how often Ray
    runs a task again whose worker died. ``report(Progress)``: after every block.
    ``preview``: True (or "HOST:PORT") serves the live page of ``glint.render(preview=True)``
    showing the driver's merged film and each worker's tasks; its Stop acts as Ctrl-C.
    ``denoise``: as ``glint.render`` (on the driver, once the film is whole).
    ``overrides``: the scene settings ``glint.render`` overrides (``integrator``,
    ``max_depth``, ``strategy``, ``light_selection``, ``sampler``, ``width``, ``height``).
    """
    frames_in = list(scene) if isinstance(scene, (list, tuple)) else [scene]
    if not frames_in:
        raise ValueError("scene: an empty list")
    n = len(frames_in)
    tile = _check_count(tile, "tile")
    passes_per_task = _check_count(passes_per_task, "passes_per_task")
    cpus_per_task = _check_count(cpus_per_task, "cpus_per_task")
    if not isinstance(checkpoint_every, (int, float)) or not checkpoint_every > 0:
        raise ValueError(f"checkpoint_every must be a positive number of seconds, got {checkpoint_every!r}")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable")
    outs, resumes = _per_frame(out, n, "out"), _per_frame(resume, n, "resume")
    checkpoints = _per_frame(checkpoint, n, "checkpoint")
    aovs = list(aovs) if not isinstance(aovs, str) else aovs
    started = time.perf_counter()

    # Everything that can be wrong with the input fails here, before Ray is reached.
    frames: List[Frame] = []
    for i, s in enumerate(frames_in):
        sc, name = _load(s)
        session = make_session(sc, spp=spp, seed=seed, aovs=aovs, denoise=denoise, **overrides)
        # What the command line checks before the scene is built, for the image and every
        # layer file beside it.
        out_i = outs[i]
        if out_i is not None:
            session.check_outputs(out_i, denoise)
        sc.build()
        if resumes[i] is not None:
            recorded = session.load_film(resumes[i])
            if out_i is None and recorded is not None:
                out_i = os.fspath(recorded)
                session.check_outputs(out_i, denoise)
        ck = checkpoints[i] if checkpoints[i] is not None else resumes[i]
        frames.append(Frame(sc, name, session, _pack.pack(sc), seed, out_i, ck, denoise))
    load_seconds = time.perf_counter() - started
    live = None
    if preview is not False and preview is not None:
        if not isinstance(preview, (bool, str)):
            raise TypeError(f"preview must be True or an address, not {type(preview).__name__}")
        live = Preview(None if preview is True else preview, frames[0].name)
        show_preview(live)

    ray = _ray()
    own_ray = not ray.is_initialized()
    if own_ray:
        import logging

        ray.init(address=_address(address), include_dashboard=False, logging_level=logging.WARNING)
    try:
        options = _Options(tile, passes_per_task, cpus_per_task, max_retries, checkpoint_every, live)
        # Time to load and build the scene on the driver, and to start or reach Ray.
        load = (load_seconds, time.perf_counter() - started - load_seconds)
        results = _run(ray, frames, options, _callback(progress, report), started, load)
    finally:
        if own_ray:
            ray.shutdown()
    return results if isinstance(scene, (list, tuple)) else results[0]


@dataclass
class _Options:
    tile: int
    passes_per_task: Optional[int]
    cpus_per_task: int
    max_retries: int
    checkpoint_every: float
    preview: Any = None


def _callback(progress: Optional[Callable[[int, int], Any]], report: Optional[Callable[[Progress], Any]]) -> Any:
    """What the driver calls after each block: ``report`` every time, ``progress`` at most
    four times a second."""
    last = [-1.0]

    def on_block(p: Progress) -> None:
        if report:
            report(p)
        if progress and p.elapsed - last[0] >= 0.25:
            last[0] = p.elapsed
            progress(p.spp_done, p.spp_total)

    return on_block


def _run(ray: Any, frames: List[Frame], o: _Options, on_block: Any, started: float, load: Tuple[float, float]) -> list:
    from ._worker import render_block

    began = time.perf_counter()
    for f in frames:
        f.pack_ref = ray.put(f.pack)
    broadcast_seconds = time.perf_counter() - began
    slots = max(1, int(ray.cluster_resources().get("CPU", 1) // o.cpus_per_task))
    tasks: List[_plan.Task] = []
    for i, f in enumerate(frames):
        passes = f.session.pass_count
        width, height = f.session.width, f.session.height
        tiles = len(_plan.tiles(width, height, o.tile))
        ppt = o.passes_per_task or _plan.auto_passes_per_task(passes, tiles * len(frames), slots)
        tasks.extend(_plan.plan(i, width, height, passes, o.tile, ppt, f.session.blocks()))
    remote = ray.remote(num_cpus=o.cpus_per_task, max_retries=o.max_retries)(render_block)
    driver = Driver(frames, tasks, remote, o.cpus_per_task, o.checkpoint_every, on_block, o.preview)
    already_whole = [f for f in frames if f.tasks_left == 0]
    try:
        totals = driver.run()
    except KeyboardInterrupt:
        for f in frames:
            write_frame(f)
        raise
    for f in already_whole:
        write_frame(f)
    p = driver.progress(time.perf_counter() - started)
    on_block(p)
    seconds = time.perf_counter() - started
    results = []
    for f in frames:
        stats = dict(f.session.stats)
        stats.update(f.rays)
        stats.update(
            seconds=seconds,
            load_seconds=load[0],
            ray_seconds=load[1],
            broadcast_seconds=broadcast_seconds,
            scene_bytes=f.pack.size,
            slots=slots,
            tasks=totals.tasks,
            world_builds=totals.world_builds,
            workers=len(totals.pids),
            worker_seconds=totals.worker_seconds,
            merge_seconds=totals.merge_seconds,
            merged_pixels=totals.merged_pixels,
        )
        image, layers = f.outputs()
        results.append(RenderResult(image=image, aovs=dict(layers), spp=f.session.spp, stats=stats))
    return results
