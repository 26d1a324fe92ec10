"""Sweep the left wall's colour through traverse: each frame rebuilds no BVH."""

import pathlib

import numpy as np

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
scene = glint.load_file(ROOT / "scenes" / "cornell-box.json")
params = glint.traverse(scene)
print("parameters:", ", ".join(params))
for i, t in enumerate(np.linspace(0, 1, 5)):
    params["materials.red.reflectance"] = (1 - t) * np.array([0.63, 0.065, 0.05]) + t * np.array([0.05, 0.1, 0.63])
    params.update()
    r = glint.render(scene, spp=8)
    glint.write_image(f"sweep-{i}.png", r.image)
    print(f"frame {i}: mesh BVHs built so far {r.stats['mesh_bvh_builds']}, top level {r.stats['top_level_builds']}")
