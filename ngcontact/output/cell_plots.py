"""The cell's figures, from plain data: the pressure and slip along a 2D cell's contact surface, a 3D grid's
pressure map, the contact curve of a sweep and a measured topography's power spectrum (drawn as
:mod:`ngcontact.output.plots` draws every figure)."""
from __future__ import annotations

import numpy as np

from ngcontact.output.plots import pyplot


#: the most points a line of :func:`cell_surface` is drawn through: far more than the figure's pixels across
MAX_LINE_POINTS = 4096


def line_points(x, y) -> tuple[np.ndarray, np.ndarray]:
    """The points of a line ``y(x)`` to draw: all of them up to :data:`MAX_LINE_POINTS`, else in each of
    ``MAX_LINE_POINTS / 2`` runs of consecutive points its lowest and its highest, in their order, so that the
    line keeps its envelope (a pressure peak, a contact edge) at a cost that does not grow with a fine grid."""
    x, y = np.asarray(x), np.asarray(y)
    if len(y) <= MAX_LINE_POINTS:
        return x, y
    bounds = np.linspace(0, len(y), MAX_LINE_POINTS // 2 + 1).astype(int)
    keep = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        keep += sorted({a + int(np.argmin(y[a:b])), a + int(np.argmax(y[a:b]))})
    return x[keep], y[keep]


def cell_surface(path: str, surfaces: list) -> None:
    """Contact pressure and slip along the cell's contact surface, one line per load (a long one through its
    envelope, :func:`line_points`).

    ``surfaces``: one dict per load with arrays ``x``, ``pressure``, ``slip``.
    """
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
    for k, sf in enumerate(surfaces):
        a1.plot(*line_points(sf["x"], sf["pressure"]), label=f"load {k}")
        a2.plot(*line_points(sf["x"], sf["slip"]))
    a1.set_ylabel("pressure (compression +)")
    a2.set_ylabel("|slip|")
    a2.set_xlabel("x")
    a1.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def cell_contact_curve(path: str, pressure, contact_fraction, mean_closure) -> None:
    """Contact fraction and mean closure against the transmitted mean pressure."""
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(8, 3.5))
    a1.plot(pressure, contact_fraction, "o-")
    a1.set_xlabel("mean pressure")
    a1.set_ylabel("contact fraction")
    a2.plot(pressure, mean_closure, "o-")
    a2.set_xlabel("mean pressure")
    a2.set_ylabel("mean closure")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def pressure_map(path: str, pressures: list, period: float) -> None:
    """Contact pressure over one period of a 3D cell, one panel per load (in contact: nonzero)."""
    plt = pyplot()
    n = len(pressures)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 0.6, 3.4), squeeze=False)
    for k, (ax, p) in enumerate(zip(axes[0], pressures)):
        im = ax.imshow(p, origin="lower", extent=(0, period, 0, period), cmap="viridis")
        ax.set_title(f"load {k}: contact {float((p > 0).mean()):.3f}", fontsize=8)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        fig.colorbar(im, ax=ax, shrink=0.8, label="pressure")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def topography_psd(path: str, psd: dict, title: str) -> None:
    """The radially averaged power spectral density ``C(q)`` of a measured topography, log-log."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5, 4))
    q, C = np.asarray(psd["q"], float), np.asarray(psd["C"], float)
    keep = (q > 0) & (C > 0)
    ax.loglog(q[keep], C[keep], "o-", ms=3)
    ax.set_xlabel("wave number q [1/m]")
    ax.set_ylabel("C(q) [m^4]")
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
