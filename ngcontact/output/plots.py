"""The figures of the macro, strength, ensemble and study stages, from plain data (arrays, dicts, lists); the
cell's are in :mod:`ngcontact.output.cell_plots`.

Computation never imports matplotlib: drivers attach plot callables that
call these functions with the numbers they computed, and the writer of
:mod:`ngcontact.output.report` draws them into the output directory.
"""
from __future__ import annotations

import math

import numpy as np


def pyplot():
    """Matplotlib's pyplot on the non-interactive Agg backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def epsilon_study(path: str, rows: list, laws) -> None:
    """Error against ``eps`` (field and reaction; thin dotted: the field error's discretization estimate, where
    the rows carry it; the bundle law's L2 error over the whole bodies without and with the first-order
    corrector, where the rows carry it) and cost against ``eps``."""
    plt = pyplot()
    eps = np.array([r["eps"] for r in rows])
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, color in zip(laws, ("C0", "C1", "C2")):
        ax[0].loglog(eps, [r[f"{name}_field"] for r in rows], "o-", color=color, label=f"{name}: field")
        ax[0].loglog(eps, [r[f"{name}_reaction"] for r in rows], "s--", color=color, label=f"{name}: reaction")
        if f"{name}_field_discretization" in rows[0]:
            ax[0].loglog(eps, [r[f"{name}_field_discretization"] for r in rows], "x:", color=color, lw=0.8,
                         label=f"{name}: field, discretization estimate")
    for key, style in (("l2", "v-"), ("l2_corrected", "^-")):
        if f"bundle_{key}" in rows[0]:
            ax[0].loglog(eps, [r[f"bundle_{key}"] for r in rows], style, color="C3" if key == "l2" else "C4",
                         label=f"bundle: {key} (whole bodies)")
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


def epsilon_errors(path: str, rows: list, laws, rates: dict, levels: dict) -> None:
    """One panel per error of the epsilon study: per law the modelling error against ``eps`` (markers), its
    discretization estimate (thin dotted) and the fitted line ``C eps^rate`` over the levels it was fitted on
    (dashed; ``rates[law][error]`` and ``levels[law][error]`` as :func:`ngcontact.drivers.study_epsilon.rates`
    returns them), so that each rate can be read against the levels the share rule let in."""
    plt = pyplot()
    keys = [k for k in dict.fromkeys(k for law in laws for k in rates.get(law, {}))]
    if not keys:
        return
    cols = min(3, len(keys))
    nrows = -(-len(keys) // cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.4 * nrows), squeeze=False)
    eps = np.array([r["eps"] for r in rows])
    for ax, key in zip(axes.flat, keys):
        for name, color in zip(laws, ("C0", "C1", "C2")):
            col = f"{name}_{key}"
            if col not in rows[0]:
                continue
            ax.loglog(eps, [max(r[col], 1e-300) for r in rows], "o-", color=color, label=name)
            ax.loglog(eps, [max(r[f"{col}_discretization"], 1e-300) for r in rows], "x:", color=color, lw=0.8)
            rate, used = rates.get(name, {}).get(key), levels.get(name, {}).get(key, [])
            if rate is not None and used:
                fit = [r for r in rows if r["N"] in used]
                x = np.log([r["eps"] for r in fit])
                c = float(np.mean(np.log([r[col] for r in fit]) - rate * x))
                ax.loglog(np.exp(x), np.exp(c + rate * x), "--", color=color, lw=1.6,
                          label=f"{name}: rate {rate:.2f}")
        ax.set_title(key, fontsize=9)
        ax.set_xlabel("eps [m]", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[len(keys):]:
        ax.set_visible(False)
    fig.suptitle("modelling error (markers), its discretization estimate (dotted), fitted rate (dashed)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------ macro
STATUS_LEVELS = {"open": 0, "stick": 1, "slip": 2}


def _status_panel(axes, ax, where, status, xlabel: str, size: float) -> None:
    """The contact status (open, stick, slip) along the interface in ``ax``, the last panel of ``axes``."""
    ax.scatter(where, [STATUS_LEVELS[x] for x in status], s=size)
    ax.set_yticks(list(STATUS_LEVELS.values()), list(STATUS_LEVELS))
    ax.set_xlabel(xlabel)
    for a in axes:
        a.grid(alpha=0.3)


def macro_interface(path: str, prof: dict) -> None:
    """Pressure, shear, jumps and status along the interface.

    ``prof``: arrays ``s``, ``pressure``, ``shear``, ``jump_n``, ``jump_t``
    and a list ``status`` of ``"open"``, ``"stick"``, ``"slip"``.
    """
    plt = pyplot()
    s = np.asarray(prof["s"]) * 1e3
    fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    ax[0].plot(s, np.asarray(prof["pressure"]) / 1e6, label="pressure p (compression > 0)")
    ax[0].plot(s, np.asarray(prof["shear"]) / 1e6, label="shear (along t0)")
    ax[0].set_ylabel("MPa")
    ax[0].legend()
    ax[1].plot(s, np.asarray(prof["jump_n"]) * 1e6, label="J . n0 (closure)")
    ax[1].plot(s, np.asarray(prof["jump_t"]) * 1e6, label="J . t0 (slip)")
    ax[1].set_ylabel("um")
    ax[1].legend()
    _status_panel(ax, ax[2], s, prof["status"], "arc length s along the interface [mm] (from the top end)", 4)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def macro_interface_3d(path: str, surf: dict) -> None:
    """Pressure and shear on a 3D interface surface, seen from two sides, and the status.

    ``surf``: arrays ``x, y, z``, ``pressure``, ``shear`` and a list ``status``
    (:func:`ngcontact.macro.macro_measures.interface_surface`).
    """
    plt = pyplot()
    fig = plt.figure(figsize=(13, 4.2))
    x, y, z = (np.asarray(surf[c]) * 1e3 for c in ("x", "y", "z"))
    for i, (key, label) in enumerate((("pressure", "pressure p [MPa]"), ("shear", "|shear| [MPa]"))):
        ax = fig.add_subplot(1, 3, i + 1, projection="3d")
        sc = ax.scatter(x, y, z, c=np.asarray(surf[key]) / 1e6, s=3, cmap="viridis")
        fig.colorbar(sc, ax=ax, shrink=0.7, label=label)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_zlabel("z [mm]")
    ax = fig.add_subplot(1, 3, 3, projection="3d")
    colors = {"open": "tab:gray", "stick": "tab:blue", "slip": "tab:red"}
    for st, c in colors.items():
        sel = np.array([s == st for s in surf["status"]])
        if sel.any():
            ax.scatter(x[sel], y[sel], z[sel], s=3, c=c, label=st)
    ax.legend()
    ax.set_title("status")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def macro_interface_axial(path: str, surf: dict) -> None:
    """The 3D interface samples against the axial position ``z``: the counterpart of :func:`macro_interface`.

    ``surf`` as in :func:`macro_interface_3d` plus ``jump_n``; every sample
    is a point, coloured by its angle ``atan2(y, x)`` about the ``z`` axis
    (on a surface of revolution the points of one height coincide when the
    solution is axisymmetric, and their spread shows where it is not).
    """
    plt = pyplot()
    z = np.asarray(surf["z"]) * 1e3
    angle = np.degrees(np.arctan2(np.asarray(surf["y"]), np.asarray(surf["x"])))
    fig, ax = plt.subplots(4, 1, figsize=(8, 10), sharex=True, constrained_layout=True)
    rows = (("pressure", 1e-6, "pressure p [MPa]\n(compression > 0)"), ("shear", 1e-6, "|shear| [MPa]"),
            ("jump_n", 1e6, "J . n0 [um]\n(closure)"))
    for a, (key, scale, label) in zip(ax, rows):
        sc = a.scatter(z, np.asarray(surf[key]) * scale, c=angle, s=3, cmap="twilight")
        a.set_ylabel(label)
    fig.colorbar(sc, ax=ax, shrink=0.6, label="angle about z [deg]")
    _status_panel(ax, ax[3], z, surf["status"], "axial position z [mm]", 3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def macro_fields(path: str, x, y, triangles, values: dict, axisymmetric: bool) -> None:
    """Four panels of paper Fig. 10: radial / axial stress, von Mises stress and strain.

    ``x, y``: point coordinates [m]; ``triangles``: ``(n, 3)`` indices into
    them; ``values``: field name -> values at the points (stresses in Pa).
    """
    plt = pyplot()
    from matplotlib.tri import Triangulation
    tri = Triangulation(np.asarray(x) * 1e3, np.asarray(y) * 1e3, np.asarray(triangles))
    fig, axes = plt.subplots(1, 4, figsize=(11, 7))
    for ax, (n, v) in zip(axes, values.items()):
        scale, unit = (1.0, "-") if n == "von_mises_strain" else (1e-6, "MPa")
        tc = ax.tripcolor(tri, np.asarray(v) * scale, shading="gouraud", cmap="viridis")
        fig.colorbar(tc, ax=ax, shrink=0.8, label=unit)
        ax.set_title(n.replace("_", " "))
        ax.set_aspect("equal")
        ax.set_xlabel("r [mm]" if axisymmetric else "x [mm]")
    axes[0].set_ylabel("z [mm]" if axisymmetric else "y [mm]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------ manufactured solution
def convergence(path: str, rows: list, rates: dict) -> None:
    """Log-log plot of the L2 and H1 errors against ``h``, one line per order.

    ``rows``: dicts with ``order``, ``h``, ``l2``, ``h1``, ``setting``;
    ``rates``: order -> ``{"l2": rate, "h1": rate}``.
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    for ax, norm, label in zip(axes, ("l2", "h1"), ("L2 error", "H1-seminorm error")):
        for p in sorted({r["order"] for r in rows}):
            sel = sorted((r for r in rows if r["order"] == p), key=lambda r: r["h"])
            h = [r["h"] for r in sel]
            e = [r[norm] for r in sel]
            rate = rates.get(p, {}).get(norm, math.nan)
            ax.loglog(h, e, "o-", label=f"p = {p} (rate {rate:.2f})")
        ax.set_xlabel("h")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"manufactured solution, setting {rows[0]['setting']}")
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ------------------------------------------------------------------ strength check
def strength_map(path: str, s, values: dict, sigma_u: dict, criterion: str, pressure, shear,
                 xlabel: str | None = None) -> None:
    """Largest micro ``sigma_eq`` along the interface per body, against ``sigma_u``.

    ``s``: arc length [m] (or, with ``xlabel``, another position along the
    interface, e.g. the axial position of 3D samples); ``values``: body ->
    largest equivalent stress over the cell at each ``s`` [Pa]; ``sigma_u``:
    body -> strength [Pa]; ``pressure``, ``shear``: the macro tractions at
    ``s`` [Pa] (3D: the magnitude of the shear).  Points, not lines, for
    samples that do not form a curve.
    """
    plt = pyplot()
    s = np.asarray(s) * 1e3
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    style = {} if xlabel is None else {"ls": "none", "marker": ".", "ms": 2}
    for (b, v), c in zip(values.items(), ("C0", "C1")):
        ax[0].plot(s, np.asarray(v) / 1e6, color=c, label=f"max over the cell, {b}", **style)
        ax[0].axhline(sigma_u[b] / 1e6, color=c, ls="--", label=f"sigma_u {b}")
    ax[0].set_ylabel(f"{criterion.replace('_', ' ')} [MPa]")
    ax[0].set_yscale("log")
    ax[0].legend(fontsize=7)
    ax[1].plot(s, np.asarray(pressure) / 1e6, label="macro pressure p", **style)
    ax[1].plot(s, np.asarray(shear) / 1e6, label="macro shear", **style)
    ax[1].set_ylabel("MPa")
    ax[1].set_xlabel(xlabel or "arc length s along the interface [mm] (from the top end)")
    ax[1].legend(fontsize=7)
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def worst_cell(path: str, points, eq, criterion: str, dim: int, tangents: tuple[str, str] = ("t0", "hoop")) -> None:
    """Equivalent stress in the worst cell (paper Fig. 8).

    ``points``: ``(n, dim)`` sample points of the cell; ``eq``: the
    equivalent stress there [Pa].  2D: the map over the cell.  3D: two
    sections through the point of the largest equivalent stress, the vertical
    plane ``y = y_max`` (x-z) and the horizontal plane ``z = z_max`` (x-y),
    each from the sample points within a thin slab around the plane.
    ``tangents``: the macro directions of the cell's ``x, y`` axes (a 3D
    cell under a 3D macro scene: ``t1, t2``).
    """
    plt = pyplot()
    pts = np.asarray(points)
    eq = np.asarray(eq) / 1e6
    label = f"{criterion.replace('_', ' ')} [MPa]"
    k = int(np.argmax(eq))
    if dim == 2:
        fig, ax = plt.subplots(figsize=(7, 5.5))
        sc = ax.scatter(pts[:, 0], pts[:, 1], c=eq, s=4, cmap="viridis")
        ax.plot(*pts[k, :2], "r+", ms=14, mew=2)
        ax.set_aspect("equal")
        ax.set_xlabel("x (t0)")
        ax.set_ylabel("y (n0)")
        fig.colorbar(sc, ax=ax, shrink=0.8, label=label)
        ax.set_title(f"worst cell: max {eq[k]:.3g} MPa (+)")
    else:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
        span = np.ptp(pts, axis=0)
        tx, ty = (f"x ({tangents[0]})", f"y ({tangents[1]})")
        for ax, (normal, a, b, names) in zip(axes, ((1, 0, 2, (tx, "z (n0)")), (2, 0, 1, (tx, ty)))):
            slab = np.abs(pts[:, normal] - pts[k, normal]) <= 0.03 * span[normal]
            sc = ax.scatter(pts[slab, a], pts[slab, b], c=eq[slab], s=6, cmap="viridis",
                            vmin=eq.min(), vmax=eq.max())
            ax.plot(pts[k, a], pts[k, b], "r+", ms=14, mew=2)
            ax.set_aspect("equal")
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
            which = "y" if normal == 1 else "z"
            ax.set_title(f"section {which} = {pts[k, normal]:.3g}")
        fig.colorbar(sc, ax=axes, shrink=0.85, label=label)
        fig.suptitle(f"worst cell: max {eq[k]:.3g} MPa (+)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def ensemble_law(path: str, pressure, bands: dict, labels: dict, members: int) -> None:
    """An ensemble's law against the transmitted pressure: the mean of each quantity and its 95 % band."""
    plt = pyplot()
    names = list(bands)
    fig, ax = plt.subplots(1, len(names), figsize=(3.6 * len(names), 3.6))
    order = np.argsort(pressure)
    p = np.asarray(pressure)[order]
    for a, name in zip(np.atleast_1d(ax), names):
        b = {k: np.asarray(v)[order] for k, v in bands[name].items()}
        a.fill_between(p, b["low"], b["high"], color="C0", alpha=0.3, label="95 % band of the mean")
        a.plot(p, b["mean"], "o-", color="C0", label=f"mean of {members} members")
        a.set_xscale("log")
        a.set_xlabel("transmitted pressure")
        a.set_title(labels.get(name, name), fontsize=9)
        a.grid(True, which="both", alpha=0.3)
    np.atleast_1d(ax)[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def ensemble_band(path: str, shrink: dict) -> None:
    """Relative standard error of the ensemble mean against the number of members, with ``M^(-1/2)``."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5, 4))
    for name, s in shrink.items():
        rate = s["rate"]
        label = f"{name} (rate {rate:.2f})" if rate is not None else name
        ax.loglog(s["members"], s["relative_standard_error"], "o-", label=label)
    first = next(iter(shrink.values()))
    M = np.asarray(first["members"], float)
    e0 = max(max(s["relative_standard_error"]) for s in shrink.values()) or 1.0
    ax.loglog(M, e0 * (M / M[0]) ** -0.5, "k:", label="M^(-1/2)")
    ax.set_xticks(M, [str(int(m)) for m in M])
    ax.minorticks_off()
    ax.set_xlabel("members M")
    ax.set_ylabel("standard error / |mean| (mean over loads)")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def work_precision(path: str, quantity: str, measure: str, series: dict, target: float | None = None) -> None:
    """Error of ``quantity`` against wall time, log-log, one line per knob (``series``: knob -> (seconds,
    errors) of its levels; levels with a zero error are left out); the target as a horizontal line."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    drawn = False
    for k, (knob, (seconds, errors)) in enumerate(series.items()):
        pts = [(t, e) for t, e in zip(seconds, errors) if t > 0 and e > 0]
        if pts:
            ax.loglog([t for t, _ in pts], [e for _, e in pts], "o-", color=f"C{k}", label=knob)
            drawn = True
    if target is not None:
        ax.axhline(target, color="gray", lw=0.8, ls="--", label=f"target {target:g}")
    if not drawn:
        ax.text(0.5, 0.5, "every level equals the reference", ha="center", transform=ax.transAxes)
    ax.set_xlabel("wall time of the level [s]")
    ax.set_ylabel(f"{measure} error against the finest level")
    ax.set_title(quantity, fontsize=10)
    if drawn or target is not None:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
