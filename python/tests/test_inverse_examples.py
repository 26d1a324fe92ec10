"""The inverse-rendering examples converge: each runs as a user would run it, and exits 0
only if the loss fell at least 100-fold and the recovered parameters are within 2% of the
truth (a colour, relative Euclidean error) or reach a PSNR of 30 dB (a texture, an
environment map). Their seeds are fixed and glint's gradients are deterministic, so each run
is the same run."""

import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


@pytest.mark.parametrize("example", ["inverse_cornell.py", "inverse_envmap.py"])
def test_inverse_rendering_example_converges(example):
    r = subprocess.run([sys.executable, str(EXAMPLES / example), "--quiet"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{example} did not converge:\n{r.stdout}\n{r.stderr}"
    assert "fell" in r.stdout and "PSNR" in r.stdout, r.stdout
