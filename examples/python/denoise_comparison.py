"""Noisy, denoised (albedo and normal guided) and reference images side by side."""

import json
import pathlib

import numpy as np

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
d = json.loads((ROOT / "scenes" / "cornell-box.json").read_text())
d["film"].update(width=256, height=256)
scene = glint.load_dict(d, base_dir=ROOT / "scenes")

noisy = glint.render(scene, spp=16, aovs=["albedo", "normal"])
denoised = glint.denoise(noisy.image, albedo=noisy.aovs["albedo"], normal=noisy.aovs["normal"])
reference = glint.render(scene, spp=512, seed=1).image


def rel_mse(a):
    return float(np.mean((a - reference) ** 2 / (reference**2 + 1e-2)))


print(f"relative MSE: noisy {rel_mse(noisy.image):.2e}, denoised {rel_mse(denoised):.2e}")
row = np.concatenate([noisy.image, denoised, reference], axis=1)
try:
    import matplotlib.pyplot as plt
except ImportError:
    glint.write_image("denoise-comparison.png", row)
    print("wrote denoise-comparison.png (noisy | denoised | reference)")
else:
    plt.imshow(np.clip(row, 0, 1) ** (1 / 2.2))
    plt.title("noisy | denoised | reference")
    plt.axis("off")
    plt.show()
