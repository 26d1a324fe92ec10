"""Error against a reference as passes accumulate: falls as 1/spp for Monte Carlo."""

import json
import pathlib

import numpy as np

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
d = json.loads((ROOT / "scenes" / "cornell-box.json").read_text())
d["film"].update(width=128, height=128)
scene = glint.load_dict(d, base_dir=ROOT / "scenes")
reference = glint.render(scene, spp=512, seed=99).image

session = glint.Session(scene, spp=256)
spps, errors = [], []
while session.spp < session.target_spp:
    session.render_passes(max(1, session.spp))  # doubling
    mse = float(np.mean((session.image() - reference) ** 2))
    spps.append(session.spp)
    errors.append(mse)
    print(f"{session.spp:4d} spp: MSE {mse:.3e}")

try:
    import matplotlib.pyplot as plt
except ImportError:
    print("(install matplotlib for the plot)")
else:
    plt.loglog(spps, errors, "o-", label="MSE")
    plt.loglog(spps, errors[0] * spps[0] / np.array(spps), "--", label="1/spp")
    plt.xlabel("samples per pixel")
    plt.legend()
    plt.show()
