"""Inverse rendering: recover the Cornell box's red wall colour and its back wall's texture
from a target image, by gradient descent on glint's gradients (glint.render_gradient).

The loss is the mean squared difference between a render and the target. Each step renders
the image with one seed and the gradient with another (so that the two are independent and
the gradient of the squared difference is unbiased), and moves the parameters with Adam.

Run: python examples/python/inverse_cornell.py [--steps N] [--quiet]
It prints the loss as it goes and, at the end, how far the loss fell and how close the
recovered parameters are to the truth; it exits non-zero if the loss did not fall 100-fold,
the colour is not within 2% of the truth (relative Euclidean error), or the texture's PSNR
is under 30 dB.
"""

import argparse
import pathlib
import sys

import numpy as np

import glint
from optim import Adam, psnr

HERE = pathlib.Path(__file__).resolve().parent


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=120)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel of each step's renders")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args()

    scene = glint.load_file(HERE / "scenes" / "cornell-textured.xml")
    params = glint.traverse(scene)
    colour, texture = "materials.red.reflectance", "materials.back.reflectance"
    # The truth: the scene's red, and a texture of stripes and a gradient.
    true_colour = params[colour]
    y, x = np.mgrid[0:8, 0:8] / 7.0
    true_texture = np.stack([0.2 + 0.6 * x, 0.3 + 0.5 * (y > 0.5), 0.8 - 0.6 * x * y], axis=2).astype(np.float32)
    params[texture] = true_texture
    params.update()
    target = glint.render(scene, spp=1024, seed=1_000_000).image

    def loss_against_target():
        # The target's own seed: where the parameters are the truth, the images are the same.
        image = glint.render(scene, spp=1024, seed=1_000_000).image
        return float(np.mean((image - target) ** 2))

    # Start from grey.
    params[colour] = np.full(3, 0.3)
    params[texture] = np.full((8, 8, 3), 0.5, np.float32)
    params.update()
    first_loss = loss_against_target()

    adam = Adam(lr=0.02)
    for step in range(args.steps):
        image = glint.render(scene, spp=args.spp, seed=2 * step).image
        grad_image = 2.0 * (image - target) / image.size
        grads = glint.render_gradient(scene, (colour, texture), grad_image, spp=args.spp, seed=2 * step + 1)
        params[colour] = np.clip(adam.step(colour, params[colour], grads[colour]), 0.0, 1.0)
        params[texture] = np.clip(adam.step(texture, params[texture], grads[texture]), 0.0, 1.0).astype(np.float32)
        params.update()
        if not args.quiet and step % 10 == 0:
            print(f"step {step:3d}: loss {float(np.mean((image - target) ** 2)):.3e}, {colour} {params[colour].round(4)}")

    last_loss = loss_against_target()
    colour_error = float(np.linalg.norm(params[colour] - true_colour) / np.linalg.norm(true_colour))
    texture_psnr = psnr(params[texture], true_texture)
    print(f"loss fell {first_loss / last_loss:.0f}-fold ({first_loss:.3e} -> {last_loss:.3e})")
    print(f"{colour}: {params[colour].round(4)} (truth {np.round(true_colour, 4)}), relative error {100 * colour_error:.2f}%")
    print(f"{texture}: PSNR {texture_psnr:.1f} dB against the truth")
    ok = first_loss / last_loss >= 100 and colour_error <= 0.02 and texture_psnr >= 30
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
