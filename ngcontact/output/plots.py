"""Every figure the package draws, from plain data (arrays, dicts, lists).

Computation never imports matplotlib: drivers attach plot callables that
call these functions with the numbers they computed, and the writer of
:mod:`ngcontact.output.report` draws them into the output directory.
"""
from __future__ import annotations

import numpy as np


def _pyplot():
    """Matplotlib's pyplot on the non-interactive Agg backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def epsilon_study(path: str, rows: list, laws) -> None:
    """Error against ``eps`` (field and reaction) and cost against ``eps``."""
    plt = _pyplot()
    eps = np.array([r["eps"] for r in rows])
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, color in zip(laws, ("C0", "C1", "C2")):
        ax[0].loglog(eps, [r[f"{name}_field"] for r in rows], "o-", color=color, label=f"{name}: field")
        ax[0].loglog(eps, [r[f"{name}_reaction"] for r in rows], "s--", color=color, label=f"{name}: reaction")
    ax[0].loglog(eps, eps / eps[0] * rows[0]["bundle_field"], "k:", label="slope 1")
    ax[0].axhline(0.01, color="gray", lw=0.8)
    ax[0].set_xlabel("eps [m]")
    ax[0].set_ylabel("relative error against the resolved solution")
    ax[0].legend(fontsize=7)
    ax[1].loglog(eps, [r["time_resolved"] for r in rows], "o-", label="resolved")
    ax[1].loglog(eps, [r["time_homogenized"] for r in rows], "s-", label="homogenized (bundle)")
    ax[1].set_xlabel("eps [m]")
    ax[1].set_ylabel("wall time [s]")
    ax[1].legend(fontsize=8)
    for a in ax:
        a.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
