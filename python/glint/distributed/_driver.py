"""The driver's loop: keeps every worker slot busy with a bounded window of tasks, adds
each returned film block into its frame's film, checkpoints, and on Ctrl-C cancels what
is in flight and writes what it has.

Blocks are added as they arrive. The film's sums are exact integers (docs/rendering.md),
so the order of addition changes no bit: the image equals a local render's whatever the
arrival order, retries included."""

import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

from .. import DEFAULT_PASS_SPP, Scene, Session
from ._pack import ScenePack
from ._plan import Task

#: Tasks in flight per worker slot: one running, one queued beside it, so that a worker
#: starts its next task while the driver is still adding the last one.
WINDOW_PER_SLOT = 2
#: How long the driver waits for a block before it looks at the clock (checkpoints,
#: progress) and at the cluster's size (nodes that joined or left).
POLL_SECONDS = 0.25
#: The live preview shows the merged film at most this often (a copy of the film each time).
PREVIEW_SECONDS = 0.5
RESIZE_SECONDS = 2.0
#: The counters a worker's session reports, added up per frame and in all.
RAY_COUNTS = dict(rays=0, shadow_rays=0, camera_rays=0, discarded_samples=0)


@dataclass
class Frame:
    """One scene of the render and the driver's film of it."""

    scene: Scene
    name: str
    session: Session
    pack: ScenePack
    seed: int
    out: Optional[str]
    checkpoint: Optional[str]
    denoise: bool = False
    pack_ref: Any = None
    tasks_left: int = 0
    dirty: bool = False
    checkpoint_error: Optional[str] = None
    rays: Dict[str, int] = field(default_factory=lambda: dict(RAY_COUNTS))
    _outputs: Any = None

    def outputs(self) -> Any:
        """The film's image and layers, as written (denoised if asked, once per state of
        the film)."""
        blocks = self.session.blocks()
        if self._outputs is None or self._outputs[0] != blocks:
            self._outputs = (blocks, self.session.outputs(self.denoise))
        return self._outputs[1]


@dataclass
class Progress:
    """What the driver reports after each block: pixel samples added and in all, samples
    per pixel in the films' leading complete passes (summed over frames), rays traced."""

    samples_done: int
    samples_total: int
    spp_done: int
    spp_total: int
    rays: int
    elapsed: float


@dataclass
class Totals:
    tasks: int = 0
    world_builds: int = 0
    merge_seconds: float = 0.0
    merged_pixels: int = 0
    worker_seconds: float = 0.0
    rays: Dict[str, int] = field(default_factory=lambda: dict(RAY_COUNTS))
    pids: set = field(default_factory=set)


class Driver:
    def __init__(
        self,
        frames: List[Frame],
        tasks: List[Task],
        remote: Any,
        cpus_per_task: int,
        checkpoint_every: float,
        report: Optional[Callable[[Progress], None]],
        preview: Any = None,
    ):
        self.frames = frames
        self.queue = list(reversed(tasks))  # popped from the end: the plan's order
        self.remote = remote
        self.cpus = cpus_per_task
        self.checkpoint_every = checkpoint_every
        self.report = report
        self.in_flight: Dict[Any, Task] = {}
        self.totals = Totals()
        self.samples_total = sum(_pixels(t) * self._spp(t) for t in tasks)
        self.samples_done = 0
        for t in tasks:
            frames[t.frame].tasks_left += 1
        # The live preview (glint.Preview) and what it shows: the frame a block last came
        # for, and per worker process its tasks done and when it last sent one.
        self.preview = preview
        self.shown_frame = 0
        self.last_shown = 0.0
        self.workers: Dict[int, List[float]] = {}
        self.tasks_total = len(tasks)

    def _spp(self, t: Task) -> int:
        """Samples per pixel of the task's passes."""
        spp = self.frames[t.frame].session.target_spp
        return min(t.passes[1] * DEFAULT_PASS_SPP, spp) - t.passes[0] * DEFAULT_PASS_SPP

    def _slots(self) -> int:
        import ray

        return max(1, int(ray.cluster_resources().get("CPU", 1) // self.cpus))

    def _submit(self, window: int) -> None:
        while self.queue and len(self.in_flight) < window:
            t = self.queue.pop()
            f = self.frames[t.frame]
            s = f.session
            # The driver's film's layers, so that the workers' blocks merge into it.
            aovs = list(s.aov_channels())
            ref = self.remote.remote(f.pack.key, [f.pack_ref], s.target_spp, f.seed, aovs, self.cpus, t.region, t.passes)
            self.in_flight[ref] = t

    def run(self) -> Totals:
        import ray

        start = time.perf_counter()
        last_checkpoint = last_resize = start
        window = WINDOW_PER_SLOT * self._slots()
        try:
            self._submit(window)
            while self.in_flight:
                ready, _ = ray.wait(list(self.in_flight), num_returns=1, timeout=POLL_SECONDS)
                for ref in ready:
                    self._add(ref, self.in_flight.pop(ref))
                now = time.perf_counter()
                if now - last_resize >= RESIZE_SECONDS:
                    window, last_resize = WINDOW_PER_SLOT * self._slots(), now
                self._submit(window)
                if ready and self.report:
                    self.report(self.progress(now - start))
                if now - last_checkpoint >= self.checkpoint_every:
                    self.write_checkpoints()
                    last_checkpoint = now
                if self.preview is not None:
                    if self.preview.stop_requested():
                        raise KeyboardInterrupt  # the Stop button: as Ctrl-C
                    if ready and now - self.last_shown >= PREVIEW_SECONDS:
                        self.show(now - start, "rendering")
                        self.last_shown = now
        except BaseException:
            for ref in self.in_flight:
                ray.cancel(ref)
            self.in_flight.clear()
            raise
        if self.preview is not None:
            self.show(time.perf_counter() - start, "done")
        return self.totals

    def show(self, elapsed: float, state: str) -> None:
        """Publishes the merged film of the frame last added to, and the worker table."""
        now = time.perf_counter()
        self.preview.set_workers([
            (f"pid {pid}", int(done), self.tasks_total, f"last block {now - last:.1f} s ago")
            for pid, (done, last) in sorted(self.workers.items())
        ])
        rays = self.totals.rays["rays"] + self.totals.rays["shadow_rays"]
        mrays = rays / max(elapsed, 1e-9) / 1e6
        self.preview.publish(self.frames[self.shown_frame].session, elapsed, mrays, state)

    def _add(self, ref: Any, t: Task) -> None:
        import ray

        try:
            data, stats = ray.get(ref)
        except ray.exceptions.RayError as e:
            raise RuntimeError(f"glint.distributed: task {t} failed: {e}") from e
        f = self.frames[t.frame]
        began = time.perf_counter()
        blocks = f.session.merge_film(data)
        self.totals.merge_seconds += time.perf_counter() - began
        if blocks != [(t.region, t.passes)]:
            raise RuntimeError(f"glint.distributed: task {t} returned the block {blocks}")
        pixels = _pixels(t)
        self.samples_done += pixels * self._spp(t)
        tot = self.totals
        tot.tasks += 1
        tot.merged_pixels += pixels
        tot.world_builds += int(stats["built"])
        tot.worker_seconds += stats["task_seconds"]
        tot.pids.add(stats["pid"])
        w = self.workers.setdefault(stats["pid"], [0, 0.0])
        w[0] += 1
        w[1] = time.perf_counter()
        self.shown_frame = t.frame
        for k in RAY_COUNTS:
            tot.rays[k] += stats[k]
            f.rays[k] += stats[k]
        f.tasks_left -= 1
        f.dirty = True
        if f.tasks_left == 0:
            write_frame(f)

    def progress(self, elapsed: float) -> Progress:
        spp_done = sum(f.session.spp for f in self.frames)
        spp_total = sum(f.session.target_spp for f in self.frames)
        rays = self.totals.rays["rays"] + self.totals.rays["shadow_rays"]
        return Progress(self.samples_done, self.samples_total, spp_done, spp_total, rays, elapsed)

    def write_checkpoints(self) -> None:
        """A checkpoint that cannot be written (a full disk, a folder removed) does not end
        the render: it warns once per distinct error (``RuntimeWarning``), the file keeps
        its last good state (writes are atomic), and it is tried again next time."""
        for f in self.frames:
            if f.checkpoint and f.dirty:
                try:
                    f.session.save_film(f.checkpoint, f.out)
                except OSError as e:
                    if str(e) != f.checkpoint_error:
                        warnings.warn(
                            f"{e}; rendering goes on (the file keeps its last good state), "
                            f"next try in {self.checkpoint_every:g} s",
                            RuntimeWarning,
                            stacklevel=2,
                        )
                    f.checkpoint_error = str(e)
                    continue
                f.checkpoint_error = None
                f.dirty = False


def _pixels(t: Task) -> int:
    return (t.region[2] - t.region[0]) * (t.region[3] - t.region[1])


def write_frame(f: Frame) -> None:
    """Writes the frame's image and its layers (as the command line does) and checkpoint."""
    from .. import write_image

    image_error = None
    if f.out:
        image, layers = f.outputs()
        try:
            write_image(f.out, image, layers)
        except OSError as e:
            image_error = e
    # The film is written even when the image cannot be (a full disk): it holds the work.
    if f.checkpoint:
        try:
            f.session.save_film(f.checkpoint, f.out)
        except OSError as e:
            if image_error is not None:
                raise image_error from None
            warnings.warn(f"{e}; the image is written, the checkpoint keeps its last good state", RuntimeWarning)
        else:
            f.dirty = False
            if image_error is not None:
                raise OSError(
                    f"{image_error} (the film is saved: `glint resume {f.checkpoint} -o OTHER` writes the image)"
                ) from None
    if image_error is not None:
        raise image_error
