"""``python -m glint.distributed SCENE -o OUT --spp N [--address ADDR]``: ``glint render``
on a Ray cluster, with the same progress bar, summary line, one-line errors and exit
codes (130 after Ctrl-C, 143 after SIGTERM, having written the image so far)."""

import argparse
import math
import os
import signal
import sys
import time
import warnings
from typing import List, Optional

from .. import INTEGRATORS
from .._errors import SceneError
from . import Progress, render


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m glint.distributed", description="Render a scene on a Ray cluster (as glint render does)."
    )
    p.add_argument("scene", help="scene file (.json, Mitsuba .xml, .obj, .ply)")
    p.add_argument("-o", "--output", help="output image (.png, .exr or .pfm; default: the scene's name with .png, "
                                          "next to it)")
    p.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    p.add_argument("--seed", type=int, default=0, help="random seed")
    p.add_argument("--integrator", choices=INTEGRATORS, help="integrator (default: the scene's)")
    p.add_argument("--max-depth", type=int, help="longest path (path: segments, -1 unbounded; whitted: recursion depth)")
    p.add_argument("--strategy", help="path tracer estimator: mis, light or bsdf")
    p.add_argument("--light-selection", help="light selection for next-event estimation: power (default), tree, auto, uniform or area")
    p.add_argument("--sampler", help="sampler: sobol (the default) or independent")
    p.add_argument("--width", type=int, help="image width (overrides the scene's film)")
    p.add_argument("--height", type=int, help="image height (overrides the scene's film)")
    p.add_argument("--aov", action="append", default=[], metavar="NAME[,NAME...]",
                   help="extra layers: albedo, normal, depth, position, variance, spp, bvh-cost")
    p.add_argument("--denoise", action="store_true",
                   help="denoise with Intel Open Image Denoise (the image as rendered is kept as the layer noisy)")
    p.add_argument("--address", help="Ray cluster address (default: start a local Ray instance)")
    p.add_argument("--tile", type=int, default=128, help="tile side in pixels")
    p.add_argument("--passes-per-task", type=int, help="passes per task (default: about 24 tasks per worker)")
    p.add_argument("--cpus-per-task", type=int, default=1, help="CPUs (threads) per task")
    p.add_argument("--checkpoint", help="write the film here every --checkpoint-every seconds and on Ctrl-C")
    p.add_argument("--checkpoint-every", type=float, default=60.0, help="seconds between checkpoints")
    p.add_argument("--resume", help="continue this checkpoint (from glint render or this command)")
    p.add_argument("-D", dest="define", action="append", default=[], metavar="NAME=VALUE",
                   help="override a Mitsuba <default> value (repeatable)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.add_argument("--preview", nargs="?", const=True, default=False, metavar="ADDR",
                   help="serve a live view of the merged film and the workers in the browser (default "
                        "127.0.0.1 at a free port, printed); its Stop acts as Ctrl-C")
    return p


class Bar:
    """The command line's progress bar on stderr: elapsed time, a 40-character bar, percent,
    ETA, samples per pixel reached and Mrays/s."""

    def __init__(self, show: bool):
        self.show = show
        self.last = 0.0

    def __call__(self, p: Progress) -> None:
        now = time.perf_counter()
        if not self.show or now - self.last < 0.1:
            return
        self.last = now
        frac = p.samples_done / p.samples_total if p.samples_total else 1.0
        eta = p.elapsed * (1 - frac) / frac if frac > 0 else math.inf
        filled = int(40 * frac)
        bar = "█" * filled + "░" * (40 - filled)
        mrays = p.rays / max(p.elapsed, 1e-9) / 1e6
        line = (
            f"{_clock(p.elapsed)} {bar} {int(100 * frac):>3}% ETA {_eta(eta):>4} "
            f"{p.spp_done}/{p.spp_total} spp, {mrays:.1f} Mrays/s"
        )
        sys.stderr.write("\r" + line)
        sys.stderr.flush()

    def finish(self) -> None:
        if self.show and self.last:
            sys.stderr.write("\r\x1b[2K")
            sys.stderr.flush()


def _clock(s: float) -> str:
    s = int(s)
    return f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"


def _eta(s: float) -> str:
    if not math.isfinite(s):
        return "?"
    s = int(s)
    return f"{s}s" if s < 60 else f"{s // 60}m" if s < 3600 else f"{s // 3600}h"


def _load(a: argparse.Namespace):
    from .. import load_file

    defines = {}
    for d in a.define:
        name, eq, value = d.partition("=")
        if not eq or not name:
            raise ValueError(f"-D {d}: expected NAME=VALUE")
        defines[name] = value
    return load_file(a.scene, **defines)


def main(argv: Optional[List[str]] = None) -> int:
    a = _parser().parse_args(argv)
    if a.output is None:
        a.output = os.path.splitext(a.scene)[0] + ".png"
    # SIGTERM stops the render as Ctrl-C does (the image so far is written).
    got: List[int] = []

    def on_term(sig: int, _frame: object) -> None:
        got.append(sig)
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, on_term)
    # A checkpoint that cannot be written warns (RuntimeWarning): one line, as glint render.
    warnings.showwarning = lambda message, *_args, **_kw: None if a.quiet else print(
        f"glint: warning: {message}", file=sys.stderr
    )
    bar = Bar(not a.quiet and sys.stderr.isatty())
    target = [0, 0]

    def report(p: Progress) -> None:
        target[:] = [p.spp_done, p.spp_total]
        bar(p)

    try:
        scene = _load(a)
        if not a.quiet:
            for w in scene.warnings:
                print(f"glint: warning: {w}", file=sys.stderr)
        result = render(
            scene, spp=a.spp, seed=a.seed, out=a.output, address=a.address, tile=a.tile,
            passes_per_task=a.passes_per_task, resume=a.resume, checkpoint=a.checkpoint,
            checkpoint_every=a.checkpoint_every, cpus_per_task=a.cpus_per_task, report=report,
            preview=a.preview,
            integrator=a.integrator, max_depth=a.max_depth, strategy=a.strategy, light_selection=a.light_selection,
            sampler=a.sampler, width=a.width, height=a.height, denoise=a.denoise,
            aovs=[name for names in a.aov for name in names.split(",") if name],
        )
    except KeyboardInterrupt:
        bar.finish()
        if not a.quiet:
            written = ", ".join(w for w in (a.output, a.checkpoint or a.resume) if w)
            print(f"glint: interrupted at {target[0]} of {target[1]} spp: wrote {written}", file=sys.stderr)
        return 128 + (got[0] if got else signal.SIGINT)
    except (SceneError, ValueError, TypeError, OSError, ImportError) as e:
        bar.finish()
        print(f"glint: error: {e}", file=sys.stderr)
        return 1
    bar.finish()
    if not a.quiet:
        s = result.stats
        rays = s["rays"] + s["shadow_rays"]
        # As glint render's "load": everything before the first task (here Ray's start too).
        load_s = s["load_seconds"] + s["ray_seconds"]
        render_s = s["seconds"] - load_s
        written = ", ".join(w for w in (a.output, a.checkpoint or a.resume) if w)
        print(
            f"glint: {a.scene} {_size(result)} @ {result.spp} spp in {render_s:.3f} s (load {load_s:.3f} s): "
            f"{rays / 1e6:.1f} M rays ({rays / max(render_s, 1e-9) / 1e6:.2f} Mrays/s), "
            f"{s['discarded_samples']} discarded samples -> {written}",
            file=sys.stderr,
        )
    return 0


def _size(result) -> str:
    h, w = result.image.shape[:2]
    return f"{w}x{h}"


if __name__ == "__main__":
    sys.exit(main())
