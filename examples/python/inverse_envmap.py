"""Inverse rendering: recover an environment map from an image of a nearly mirror sphere (a
light probe), by gradient descent on glint's gradients (glint.render_gradient).

The loss is the mean squared difference between a render and the target; each step renders
the image and the gradient with different seeds (so the gradient of the squared difference
is unbiased) and moves the map's texels with Adam.

Run: python examples/python/inverse_envmap.py [--steps N] [--quiet]
It exits non-zero if the loss did not fall 100-fold or the recovered map's PSNR against the
truth is under 30 dB.
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
    ap.add_argument("--steps", type=int, default=150)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel of each step's renders")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args()

    scene = glint.load_file(HERE / "scenes" / "envmap-probe.xml")
    params = glint.traverse(scene)
    sky = "lights.sky.data"
    # The truth: a sky that brightens towards the zenith, a warm horizon band and a sun.
    v, u = np.mgrid[0:8, 0:16]
    true_sky = np.stack([0.3 + 0.1 * v, 0.4 + 0.05 * v, 1.0 - 0.08 * v], axis=2)
    true_sky[3:5] += np.array([0.6, 0.3, 0.0])
    true_sky[2, 5] = [4.0, 3.6, 3.0]
    true_sky = true_sky.astype(np.float32)
    params[sky] = true_sky
    params.update()
    target = glint.render(scene, spp=1024, seed=1_000_000).image

    def loss_against_target():
        image = glint.render(scene, spp=1024, seed=1_000_000).image
        return float(np.mean((image - target) ** 2))

    params[sky] = np.full_like(true_sky, 0.5)
    params.update()
    first_loss = loss_against_target()

    adam = Adam(lr=0.05)
    for step in range(args.steps):
        image = glint.render(scene, spp=args.spp, seed=2 * step).image
        grad_image = 2.0 * (image - target) / image.size
        grads = glint.render_gradient(scene, (sky,), grad_image, spp=args.spp, seed=2 * step + 1)
        params[sky] = np.maximum(adam.step(sky, params[sky], grads[sky]), 0.0).astype(np.float32)
        params.update()
        if not args.quiet and step % 10 == 0:
            print(f"step {step:3d}: loss {float(np.mean((image - target) ** 2)):.3e}")

    last_loss = loss_against_target()
    sky_psnr = psnr(params[sky], true_sky)
    print(f"loss fell {first_loss / last_loss:.0f}-fold ({first_loss:.3e} -> {last_loss:.3e})")
    print(f"{sky}: PSNR {sky_psnr:.1f} dB against the truth")
    return 0 if first_loss / last_loss >= 100 and sky_psnr >= 30 else 1


if __name__ == "__main__":
    sys.exit(main())
