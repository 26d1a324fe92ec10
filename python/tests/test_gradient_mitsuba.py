"""glint's gradients (``render_gradient``) against Mitsuba 3.9.1's (``prb``).

The scenes and the reference files are in tests/scenes/gradients/ (its README says how
scripts/reference-gradients made them). For each scene the test renders with glint, with
seeds of its own, and compares:

1. the primal image: the per-channel mean over all pixels, from K seeded ``render`` calls,
   with Mitsuba's, within 4 combined standard errors;
2. each parameter's gradient of ``L = sum(G * image)`` (G = ``grad_image``, the rule the
   reference file states), mean of K seeded ``render_gradient`` calls, with Mitsuba's mean:
   every component within ``t * sqrt(se_glint^2 + se_mitsuba^2)``, where t is Student's t
   quantile for a two-sided family-wise false-alarm rate FAMILY_ALPHA shared among the
   scene's components (Bonferroni: each one at FAMILY_ALPHA / n), with K - 1 degrees of
   freedom (glint's standard error, from K runs, dominates; K - 1 is the fewest Welch's
   approximation can give, so the bound is conservative);
3. physics that does not need Mitsuba: gradients of diffuse reflectances and of a light's
   radiance are positive (G is positive: raising them brightens the image), and the image is
   linear in the light's radiance, so the radiance gradient times the radiance is the loss
   of each channel (glint's gradient against glint's own image);
4. the rough conductor's alpha gradient is negative (a rougher sphere is darker here, as
   Mitsuba's finite difference, in the reference file's checks, also says).

Standard errors are sample standard deviations (ddof 1) over the runs / sqrt(runs).
"""

import json
import math
import pathlib

import numpy as np
import pytest

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
GRADIENTS = ROOT / "tests" / "scenes" / "gradients"

# The rule scripts/reference-gradients writes into each file; the test makes the same G.
GRAD_IMAGE_RULE = "G[y, x, c] = 1 + (x + 2 y) / (W + 2 H), y the row (0 at the top), x the column, every channel alike"

# Two-sided false-alarm rate of each scene's gradient comparison, all components together.
FAMILY_ALPHA = 0.01
# The primal check's bound, in combined standard errors (per channel about 0.1% false alarms
# at 15 degrees of freedom).
PRIMAL_Z = 4.0

# glint's runs (K) and samples per pixel per scene: about 3 M paths with gradients in all.
# Mitsuba's references have 32 runs x 256 spp, so their standard errors are a few times
# smaller than glint's.
GLINT_RUNS = {"cornell": (16, 32), "textured": (16, 32), "conductor": (16, 128)}
SEEDS = range(1, 100)


def grad_image(h: int, w: int) -> np.ndarray:
    """GRAD_IMAGE_RULE as an array (h, w, 3) float32."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    g = 1.0 + (x + 2.0 * y) / (w + 2.0 * h)
    return np.repeat(g[..., None], 3, axis=2).astype(np.float32)


def t_quantile(p: float, dof: int) -> float:
    """The t with P(T > t) = p for Student's t with dof degrees of freedom (p < 0.5): bisection
    on the tail, the density integrated by Simpson's rule from t to a far bound."""

    def log_pdf(t: float) -> float:
        return (
            math.lgamma((dof + 1) / 2)
            - math.lgamma(dof / 2)
            - 0.5 * math.log(dof * math.pi)
            - (dof + 1) / 2 * math.log1p(t * t / dof)
        )

    def tail(t: float) -> float:
        # Substituting t = t0 / u maps (t0, inf) onto (0, 1]: integrand pdf(t0/u) t0 / u^2.
        n = 4000
        h = 1.0 / n
        total = 0.0
        for i in range(n + 1):
            u = max(i * h, 1e-12)
            f = math.exp(log_pdf(t / u)) * t / (u * u)
            total += f * (1 if i in (0, n) else 4 if i % 2 else 2)
        return total * h / 3

    lo, hi = 0.0, 1000.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if tail(mid) > p:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def mean_se(samples) -> tuple:
    a = np.asarray(samples, dtype=np.float64)
    return a.mean(0), a.std(0, ddof=1) / math.sqrt(len(a))


def reference(name: str) -> dict:
    ref = json.loads((GRADIENTS / f"{name}.mitsuba.json").read_text())
    assert ref["grad_image"] == GRAD_IMAGE_RULE, "the reference file was made with another G: make both agree"
    return ref


class Run:
    """glint's K seeded primal renders and K seeded gradient renders of one scene."""

    def __init__(self, name: str):
        self.name = name
        self.ref = reference(name)
        self.scene = glint.load_file(GRADIENTS / f"{name}.xml")
        self.k, self.spp = GLINT_RUNS[name]
        w, h = self.ref["resolution"]
        self.G = grad_image(h, w)
        self.names = tuple(self.ref["parameters"])
        seeds = list(SEEDS)[: self.k]
        images = [glint.render(self.scene, spp=self.spp, seed=s).image for s in seeds]
        assert images[0].shape == (h, w, 3)
        self.primal = [img.reshape(-1, 3).mean(0) for img in images]
        # The loss of each channel, per run, for the linearity check.
        self.losses = [(img * self.G).reshape(-1, 3).sum(0) for img in images]
        self.grads = {n: [] for n in self.names}
        for s in seeds:
            g = glint.render_gradient(self.scene, params=self.names, grad_image=self.G, spp=self.spp, seed=s)
            assert set(g) == set(self.names), f"render_gradient returned {sorted(g)}, asked for {self.names}"
            for n in self.names:
                a = np.asarray(g[n], dtype=np.float64)
                shape = tuple(self.ref["parameters"][n]["shape"])
                assert a.shape == shape, f"{n}: shape {a.shape}, expected {shape}"
                assert np.all(np.isfinite(a)), f"{n}: not finite"
                self.grads[n].append(a.reshape(-1))

    def gradient(self, n: str) -> tuple:
        return mean_se(self.grads[n])


_runs = {}


def run_of(name: str) -> Run:
    if name not in _runs:
        _runs[name] = Run(name)
    return _runs[name]


SCENES = ["cornell", "textured", "conductor"]


@pytest.mark.parametrize("name", SCENES)
def test_primal_image_mean_matches_mitsuba(name):
    r = run_of(name)
    m, se = mean_se(r.primal)
    ref_m, ref_se = np.array(r.ref["primal"]["mean"]), np.array(r.ref["primal"]["stderr"])
    bound = PRIMAL_Z * np.sqrt(se**2 + ref_se**2)
    assert np.all(np.abs(m - ref_m) <= bound), (
        f"{name}: image mean per channel glint {m} +- {se}, Mitsuba {ref_m} +- {ref_se}: "
        f"differences {m - ref_m} exceed {bound}"
    )


@pytest.mark.parametrize("name", SCENES)
def test_gradients_match_mitsuba(name):
    r = run_of(name)
    n_components = sum(len(r.ref["parameters"][n]["mean"]) for n in r.names)
    t = t_quantile(FAMILY_ALPHA / (2 * n_components), r.k - 1)
    failures = []
    for n in r.names:
        p = r.ref["parameters"][n]
        m, se = r.gradient(n)
        ref_m, ref_se = np.array(p["mean"]), np.array(p["stderr"])
        assert m.shape == ref_m.shape
        bound = t * np.sqrt(se**2 + ref_se**2)
        bad = np.nonzero(np.abs(m - ref_m) > bound)[0]
        if len(bad):
            i = bad[np.argmax((np.abs(m - ref_m) / bound)[bad])]
            failures.append(
                f"{n} ({p['mitsuba_key']}): {len(bad)} of {m.size} components differ; the worst, #{i}: "
                f"glint {m[i]:.5g} +- {se[i]:.3g}, Mitsuba {ref_m[i]:.5g} +- {ref_se[i]:.3g}, "
                f"bound {bound[i]:.3g} ({t:.2f} combined standard errors)"
            )
    assert not failures, f"{name}:\n" + "\n".join(failures)


@pytest.mark.parametrize("name", SCENES)
def test_gradient_signs(name):
    """Raising a diffuse reflectance or a light's radiance brightens every pixel it changes
    and G is positive, so those gradients are positive: each component's mean lies above
    zero by more than 4 standard errors (Mitsuba's lie above it by far more)."""
    r = run_of(name)
    for n in r.names:
        if n.endswith((".reflectance", ".emission")):
            m, se = r.gradient(n)
            assert np.all(m > 4 * se), f"{name}: {n}: not all positive: {m} +- {se}"
    if name == "conductor":
        m, se = r.gradient("materials.metal.alpha")
        assert m[0] < -4 * se[0], f"alpha gradient {m[0]} +- {se[0]}: expected negative"


@pytest.mark.parametrize("name", SCENES)
def test_emission_gradient_is_image_over_radiance(name):
    """The image is linear in the light's radiance: gradient * radiance = each channel's loss,
    glint's gradient against glint's own images, within 4 combined standard errors."""
    r = run_of(name)
    radiance = np.array(r.ref["parameters"]["shapes.light.emission"]["value"])
    g, g_se = r.gradient("shapes.light.emission")
    loss, loss_se = mean_se(r.losses)
    bound = 4 * np.sqrt((g_se * radiance) ** 2 + loss_se**2)
    assert np.all(np.abs(g * radiance - loss) <= bound), (
        f"{name}: gradient x radiance {g * radiance}, loss per channel {loss}, bound {bound}"
    )


def test_t_quantile():
    # Tables: t_0.975 with 15 dof 2.131, t_0.9995 with 15 dof 4.073, with 7 dof 5.408; and
    # with many degrees of freedom the normal's 1.960.
    assert abs(t_quantile(0.025, 15) - 2.131) < 2e-3
    assert abs(t_quantile(0.0005, 15) - 4.073) < 2e-3
    assert abs(t_quantile(0.0005, 7) - 5.408) < 2e-3
    assert abs(t_quantile(0.025, 100000) - 1.960) < 2e-3


def test_reference_files_are_complete():
    """The reference files have every parameter with its key, shape, mean and standard error."""
    for name in SCENES:
        ref = reference(name)
        assert ref["mitsuba_version"] == "3.9.1"
        for n, p in ref["parameters"].items():
            size = int(np.prod(p["shape"])) if p["shape"] else 1
            assert len(p["mean"]) == len(p["stderr"]) == size, n
            assert all(s > 0 for s in p["stderr"]), n
