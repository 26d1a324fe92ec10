"""Shared fixtures: the repository's scenes, small versions of them, and the CLI binary."""

import json
import os
import pathlib

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
