"""Render the Cornell box and show it (with matplotlib when installed), or save it."""

import pathlib
import sys

import numpy as np

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
scene = glint.load_file(ROOT / "scenes" / "cornell-box.json")
result = glint.render(scene, spp=16, progress=lambda done, total: print(f"\r{done}/{total} spp", end=""))
print(f"\n{result.stats['rays'] / result.stats['seconds'] / 1e6:.1f} Mrays/s")

try:
    import matplotlib.pyplot as plt
except ImportError:
    glint.write_image("cornell.png", result.image)
    print("matplotlib is not installed: wrote cornell.png", file=sys.stderr)
else:
    # Linear to display: a simple clip and gamma is enough for a preview.
    plt.imshow(np.clip(result.image, 0, 1) ** (1 / 2.2))
    plt.axis("off")
    plt.show()
