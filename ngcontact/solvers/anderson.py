"""Anderson acceleration of a fixed point ``x = F(x)``, with a lower bound on the iterate.

Given the last ``m + 1`` iterates ``x_j`` and their images ``F_j = F(x_j)``, with residuals
``f_j = F_j - x_j``, the next iterate is the image of the combination of the iterates whose
linearized residual is smallest (Anderson, J. ACM 12 (1965) 547-560; Walker & Ni, SIAM J. Numer. Anal.
49 (2011) 1715-1735, the form with mixing 1):

    gamma = argmin | f_k - sum_j gamma_j (f_(j+1) - f_j) |,
    x_(k+1) = F_k - sum_j gamma_j (F_(j+1) - F_j).

With one iterate it is the plain fixed point ``x_1 = F_0``.  The small least-squares problem is solved by
its normal equations (an ``m x m`` Gram matrix of plain sums, regularized by a relative ``REGULARIZE`` on its
diagonal: differences that are nearly dependent are dropped in effect, not amplified).  The iterate is
clipped at ``lower`` (a friction threshold stays non-negative).
"""
from __future__ import annotations

import numpy as np

#: relative Tikhonov term on the Gram matrix's diagonal
REGULARIZE = 1e-10


class Anderson:
    """The history of a fixed-point iteration and its next iterate (module docstring).

    ``depth``: the differences kept (``m``); ``lower``: the bound of the iterate (``None``: none).
    """

    def __init__(self, depth: int = 5, lower: float | None = 0.0):
        if depth < 0:
            raise ValueError(f"depth = {depth!r}: must be >= 0")
        self.depth, self.lower = depth, lower
        self.images: list[np.ndarray] = []
        self.residuals: list[np.ndarray] = []

    def next(self, x: np.ndarray, image: np.ndarray) -> np.ndarray:
        """The iterate after ``x``, whose image is ``image = F(x)``."""
        self.images.append(np.array(image, float))
        self.residuals.append(np.asarray(image, float) - x)
        del self.images[:-(self.depth + 1)]
        del self.residuals[:-(self.depth + 1)]
        out = self.images[-1].copy()
        if len(self.images) > 1:
            df = [b - a for a, b in zip(self.residuals[:-1], self.residuals[1:])]
            gram = np.array([[float(np.multiply(u, v).sum()) for v in df] for u in df])
            rhs = np.array([float(np.multiply(u, self.residuals[-1]).sum()) for u in df])
            gram[np.diag_indices_from(gram)] *= 1.0 + REGULARIZE
            gram[np.diag_indices_from(gram)] += REGULARIZE * max(float(np.trace(gram)), 1e-300)
            gamma = np.linalg.solve(gram, rhs)
            for g, a, b in zip(gamma, self.images[:-1], self.images[1:]):
                out -= g * (b - a)
        if self.lower is not None:
            np.maximum(out, self.lower, out=out)
        return out

    def reset(self) -> None:
        """Forget the history (the next iterate is the plain image)."""
        self.images.clear()
        self.residuals.clear()
