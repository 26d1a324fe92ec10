"""Shared fixtures: the repository's scenes, small versions of them, and the CLI binary."""

import contextlib
import json
import os
import pathlib
import threading

import pytest

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


def cornell_dict(size: int = 64) -> dict:
    """The Cornell box scene as a dict, at size x size pixels."""
    d = json.loads((SCENES / "cornell-box.json").read_text())
    d["film"]["width"] = size
    d["film"]["height"] = size
    return d


def cornell(size: int = 64) -> glint.Scene:
    return glint.load_dict(cornell_dict(size), base_dir=SCENES)


@pytest.fixture
def cli() -> pathlib.Path:
    """The release CLI (scripts/test-python builds it and sets GLINT_CLI)."""
    path = pathlib.Path(os.environ.get("GLINT_CLI", ROOT / "target" / "release" / "glint"))
    if not path.exists():
        pytest.fail(f"{path} is missing: build it with cargo build --release -p glint-cli")
    return path


@contextlib.contextmanager
def counting_thread():
    """A Python thread counting while the block runs: it counts only where the GIL is free.
    Yields a list whose one item is the count."""
    counter = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1
            stop.wait(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        yield counter
    finally:
        stop.set()
        t.join()
