"""What the inverse-rendering examples share: Adam, and PSNR."""

import numpy as np


class Adam:
    """Adam (Kingma and Ba 2015), one state per parameter name."""

    def __init__(self, lr, beta1=0.9, beta2=0.999, eps=1e-8):
        self.lr, self.beta1, self.beta2, self.eps = lr, beta1, beta2, eps
        self.m, self.v, self.t = {}, {}, {}

    def step(self, name, x, grad):
        m = self.m[name] = self.beta1 * self.m.get(name, 0.0) + (1 - self.beta1) * grad
        v = self.v[name] = self.beta2 * self.v.get(name, 0.0) + (1 - self.beta2) * grad * grad
        t = self.t[name] = self.t.get(name, 0) + 1
        m_hat, v_hat = m / (1 - self.beta1**t), v / (1 - self.beta2**t)
        return x - self.lr * m_hat / (np.sqrt(v_hat) + self.eps)


def psnr(x, truth):
    """Peak signal-to-noise ratio of `x` against `truth`, the peak being truth's largest value."""
    mse = float(np.mean((x - truth) ** 2))
    return 10 * np.log10(float(truth.max()) ** 2 / mse)
