"""Cutting a render into tasks: pixel tiles times pass ranges, the early passes of the
whole image first (the image converges evenly, and the film's leading complete passes,
what progress and ``glint resume`` count, grow steadily). Work a resumed film already holds
is left out."""

import math
from dataclasses import dataclass
from typing import List, Sequence, Tuple

Region = Tuple[int, int, int, int]  # x0, y0, x1, y1 (exclusive)
Passes = Tuple[int, int]  # first, end (exclusive)
Block = Tuple[Region, Passes]

#: Tasks per worker slot that automatic sizing aims at: enough for the last tasks to
#: finish close together (the tail costs about one task of one slot), few enough that the
#: driver's per-task cost stays small beside the rendering (BENCHMARKS.md).
TASKS_PER_SLOT = 24


@dataclass(frozen=True)
class Task:
    frame: int
    region: Region
    passes: Passes


def tiles(width: int, height: int, tile: int) -> List[Region]:
    """Square tiles of ``tile`` pixels (smaller at the right and bottom edges), row-major."""
    return [
        (x, y, min(x + tile, width), min(y + tile, height))
        for y in range(0, height, tile)
        for x in range(0, width, tile)
    ]


def auto_passes_per_task(pass_count: int, tile_count: int, slots: int) -> int:
    """Passes per task so that the render makes about ``TASKS_PER_SLOT`` tasks per slot."""
    target = max(1, TASKS_PER_SLOT * slots)
    return max(1, min(pass_count, math.ceil(pass_count * tile_count / target)))


def _contains(outer: Region, inner: Region) -> bool:
    return outer[0] <= inner[0] and outer[1] <= inner[1] and inner[2] <= outer[2] and inner[3] <= outer[3]


def _intersects(a: Region, b: Region) -> bool:
    return max(a[0], b[0]) < min(a[2], b[2]) and max(a[1], b[1]) < min(a[3], b[3])


def _missing(span: Passes, have: List[Passes]) -> List[Passes]:
    """The parts of ``span`` that no range of ``have`` covers."""
    out, start = [], span[0]
    for a, b in sorted(have):
        if b <= start or a >= span[1]:
            continue
        if a > start:
            out.append((start, a))
        start = max(start, b)
    if start < span[1]:
        out.append((start, span[1]))
    return out


def plan(
    frame: int, width: int, height: int, pass_count: int, tile: int, passes_per_task: int, done: Sequence[Block]
) -> List[Task]:
    """The tasks of one frame. ``done``: blocks the film already holds (a resumed
    checkpoint); each must cover whole tiles, as the driver's own checkpoints and
    ``glint render --checkpoint`` do (ValueError otherwise)."""
    regions = tiles(width, height, tile)
    have: List[List[Passes]] = []
    for r in regions:
        ranges = []
        for region, passes in done:
            if _contains(region, r):
                ranges.append(passes)
            elif _intersects(region, r):
                raise ValueError(
                    f"the film's block x {region[0]}..{region[2]}, y {region[1]}..{region[3]} does not cover whole "
                    f"tiles of {tile} pixels: resume with the tile size it was rendered with"
                )
        have.append(ranges)
    tasks = []
    for first in range(0, pass_count, passes_per_task):
        span = (first, min(first + passes_per_task, pass_count))
        for r, ranges in zip(regions, have):
            tasks.extend(Task(frame, r, p) for p in _missing(span, ranges))
    return tasks
