"""Measures of a macro solution: stresses, field extrema, the interface tractions and profile.

Post-processing of :class:`ngcontact.macro.macro_problem.MacroSolution`
(paper Fig. 10: the stress fields; eqs. 69-71: the homogenized interface
tractions ``tau = dW/da`` on ``S_0``).  The interface is sampled on its own
boundary elements, never by point evaluation on the interface.  Pressures
are compression positive.

Stress fields (radial / axial / hoop in axisymmetry), von Mises stress and
strain, their extrema with locations, the profile along the interface (arc
length, pressure, shear, jumps, status open / stick / slip; in 3D the same
on the interface surface), the force
transmitted through the interface and the detachment points.
"""
from __future__ import annotations

from typing import Any
import ngsolve as ng
import numpy as np
from ngcontact.fem import elasticity
from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.fem.two_body import Load, Support, boundary_labels, interface_normal  # noqa: F401  (public names of the macro problem)
from ngcontact.laws import interface_energy as ie
from ngcontact.fem.materials import von_mises
from ngcontact.fem.quadrature import energy_order
from ngcontact.errors import ModelError
from ngcontact.macro.macro_energy import energy_form, gap_cf, load_form
from ngcontact.macro.macro_problem import MacroSolution

#: Largest imbalance of a body's forces, relative to the largest force on
#: either body or to the force the interface carries in magnitude, for a
#: solution to be reported (a converged Newton iteration leaves ~1e-10).
EQUILIBRIUM_RTOL = 1e-6


def _by_region(sol: MacroSolution, fn):
    p = sol.problem
    return p.mesh.MaterialCF({p.rough: fn(sol.u_rough, p.materials[p.rough]),
                              p.counter: fn(sol.u_counter, p.materials[p.counter])})


def stress(sol: MacroSolution):
    """3x3 stress tensor field (both bodies)."""
    s = sol.problem.setting
    return _by_region(sol, lambda u, law: elasticity.stress(law, u, s))


def strain(sol: MacroSolution):
    """3x3 strain tensor field (both bodies)."""
    s = sol.problem.setting
    return _by_region(sol, lambda u, law: elasticity.strain(u, s))


def von_mises_strain(eps):
    """Equivalent strain ``sqrt(2/3 e:e)``, ``e`` the deviatoric strain."""
    e = eps - ng.Trace(eps) / 3.0 * ng.Id(3)
    return ng.sqrt(2.0 / 3.0 * ng.InnerProduct(e, e))


def stress_fields(sol: MacroSolution) -> dict:
    """Named scalar fields: stress components, von Mises stress and strain.

    Axisymmetric: ``sigma_r``, ``sigma_z``, ``sigma_hoop``, ``sigma_rz``;
    plane strain: ``sigma_xx``, ``sigma_yy``, ``sigma_zz``, ``sigma_xy``;
    3D: the six Cartesian components.  Always ``von_mises`` (stress) and
    ``von_mises_strain``.
    """
    sig = stress(sol)
    setting = sol.problem.setting
    if setting == "axisymmetric":
        out = {"sigma_r": sig[0, 0], "sigma_z": sig[1, 1], "sigma_hoop": sig[2, 2], "sigma_rz": sig[0, 1]}
    elif setting == "plane_strain":
        out = {"sigma_xx": sig[0, 0], "sigma_yy": sig[1, 1], "sigma_zz": sig[2, 2], "sigma_xy": sig[0, 1]}
    else:
        out = {f"sigma_{a}{b}": sig[i, j] for i, j, a, b in
               ((0, 0, "x", "x"), (1, 1, "y", "y"), (2, 2, "z", "z"), (1, 2, "y", "z"),
                (0, 2, "x", "z"), (0, 1, "x", "y"))}
    out["von_mises"] = von_mises(sig)
    out["von_mises_strain"] = von_mises_strain(strain(sol))
    return out


def _sample_rule(dim: int, inset: float = 1e-3):
    """Points at the vertices (moved ``inset`` inwards, off the axis ``r = 0``
    where the hoop strain ``u_r / r`` is 0/0), edge midpoints and centroid."""
    e = inset
    pts: list[tuple[float, ...]]
    if dim == 2:
        pts = [(e, e), (1 - 2 * e, e), (e, 1 - 2 * e), (0.5, e), (0.5 - e, 0.5 - e), (e, 0.5), (1 / 3, 1 / 3)]
    else:
        pts = [(e, e, e), (1 - 3 * e, e, e), (e, 1 - 3 * e, e), (e, e, 1 - 3 * e), (0.25, 0.25, 0.25)]
    return ng.IntegrationRule(pts, [0.0] * len(pts))


def field_extrema(sol: MacroSolution, fields: dict, candidates=None) -> dict:
    """Largest and smallest value of each field with its location and body.

    Sampled next to the vertices, at edge midpoints and centroids of every
    element, on each body's side separately (the fields jump across ``S_0``).
    ``candidates``: a function of this process's list of candidates (one
    :func:`extrema_candidates` per body) returning every process's in a fixed
    order (for a mesh distributed over MPI ranks); the first best is kept.
    """
    mine = [extrema_candidates(sol, fields, region) for region in (sol.problem.rough, sol.problem.counter)]
    every = mine if candidates is None else candidates(mine)
    out: dict[str, dict[str, dict[str, Any]]] = {name: {} for name in fields}
    for cand in every:
        for name, by_key in cand.items():
            for key, found in by_key.items():
                best = out[name].get(key)
                if best is None or (found["value"] > best["value"] if key == "max" else found["value"] < best["value"]):
                    out[name][key] = found
    return out


def extrema_candidates(sol: MacroSolution, fields: dict, region: str) -> dict:
    """The largest and smallest sample of each field in ``region`` on this process's elements (none where
    it has no elements of the region)."""
    mesh = sol.problem.mesh
    mips = mesh.MapToAllElements(_sample_rule(mesh.dim), mesh.Materials(region))
    xyz = np.asarray(ng.CF((ng.x, ng.y, ng.z)[:mesh.dim])(mips)).reshape(-1, mesh.dim)
    out: dict[str, dict[str, dict[str, Any]]] = {name: {} for name in fields}
    if not len(xyz):
        return out
    for name, cf in fields.items():
        vals = np.asarray(cf(mips)).ravel()
        for key, k in (("max", int(np.argmax(vals))), ("min", int(np.argmin(vals)))):
            out[name][key] = {"value": float(vals[k]), "location": [float(c) for c in xyz[k]], "body": region}
    return out


def interface_tractions(sol: MacroSolution) -> list:
    """Local traction components ``dW/da`` on ``S_0`` at the solution."""
    p = sol.problem
    return ie.traction(p.law, sol.local_jump, gap_cf(p.gap), sol.threshold)


def resultant(sol: MacroSolution) -> dict:
    """Force transmitted through ``S_0`` from the rough to the counter body.

    ``R = int_S0 tau w ds`` with the global traction ``tau = sum_k tau_k e_k``.
    Axisymmetric: only the axial component ``z`` (per full revolution; the
    radial tractions cancel around the circumference).  Plane strain: per unit
    thickness.  Integrated with the quadrature of the assembly (order ``2p``),
    so ``R`` is the discrete reaction and balances the applied loads to
    solver tolerance (the kinks of unilateral laws make other quadratures
    differ slightly).
    """
    p = sol.problem
    tau = interface_tractions(sol)
    glob = sum((t * e for t, e in zip(tau, sol.frame)), ng.CF((0,) * p.mesh.dim))
    w = elasticity.weight(p.setting)
    comps = COMPONENTS[p.setting]
    vals = [ng.Integrate(glob[i] * w, p.mesh, ng.BND, definedon=p.mesh.Boundaries(p.interface),
                         order=energy_order(p.order)) for i in range(p.mesh.dim)]
    if p.setting == "axisymmetric":
        return {"z": float(vals[1])}
    return {c: float(v) for c, v in zip(comps, vals)}


def mean_pressure(sol: MacroSolution) -> float:
    """Mean interface pressure ``int_S0 tau_n ds / int_S0 ds`` (compression positive; axisymmetric:
    weighted with ``r``), with the quadrature of :func:`resultant`."""
    p = sol.problem
    on = p.mesh.Boundaries(p.interface)
    w = elasticity.weight(p.setting)
    force = ng.Integrate(interface_tractions(sol)[0] * w, p.mesh, ng.BND, definedon=on, order=energy_order(p.order))
    return float(force / ng.Integrate(w, p.mesh, ng.BND, definedon=on, order=energy_order(p.order)))


def equilibrium(sol: MacroSolution, total=None) -> dict:
    """Each body's force balance at the solution, and its largest relative imbalance.

    For body ``B`` and every rigid translation ``e_i`` of it (axisymmetric:
    ``z`` only; a radial shift is no rigid motion), the residual of the
    discrete equilibrium (paper eq. 8 with the interface energy of eqs.
    69-71) tested with ``v = e_i`` on ``B`` splits into

        applied_i + interface_i + supports_i = - sum_{free dofs} r_k v_k

    since the elastic energy does not change under a translation:
    ``applied`` is the surface loads and body force on ``B``, ``interface`` the force the
    interface exerts on ``B``, ``supports`` the reactions of its Dirichlet
    dofs.  The imbalance vanishes at a converged solution; it is reported
    relative to the largest of these forces and of the interface force in
    magnitude, ``int |tau| w ds`` (an interference fit carries a large
    force whose resultant is zero).

    ``total``: the sum of a number over the MPI ranks of a distributed
    mesh (each rank's dot products of its part of the residual with the
    test field; identity in one process).

    Returns
    -------
    dict
        ``bodies``: per body and component ``applied``, ``interface``,
        ``supports``, ``imbalance``; ``scale`` and ``error`` (the largest
        imbalance over ``scale``).
    """
    p = sol.problem
    fes = sol.gfu.space
    add = total or float
    vectors = []
    for form in (energy_form(sol), load_form(sol)):
        vec = sol.gfu.vec.CreateVector()
        form.Apply(sol.gfu.vec, vec)
        vec.Distribute()      # a residual's shared dofs split over the ranks (nothing in one process)
        vectors.append(vec.FV().NumPy().copy())
    r, rl = vectors
    free = np.array(list(fes.FreeDofs()), dtype=bool)
    comps = ("z",) if p.setting == "axisymmetric" else COMPONENTS[p.setting]
    every = COMPONENTS[p.setting]
    test = ng.GridFunction(fes)
    bodies: dict[str, dict[str, dict[str, float]]] = {}
    for b, name in enumerate((p.rough, p.counter)):
        bodies[name] = {}
        for c in comps:
            test.vec[:] = 0.0
            test.components[b].Set(ng.CF(tuple(1.0 if k == c else 0.0 for k in every)))
            test.vec.Cumulate()   # the test field whole on every rank that shares a dof
            v = test.vec.FV().NumPy()
            applied = -add(float(rl @ v))
            interface = -add(float(r @ v)) - applied  # r = elastic + interface - applied; elastic(e_i) = 0
            supports = add(float(r[~free] @ v[~free]))
            bodies[name][c] = {"applied": applied, "interface": interface, "supports": supports,
                               "imbalance": -add(float(r[free] @ v[free]))}
    tau = interface_tractions(sol)
    magnitude = float(ng.Integrate(ng.sqrt(sum(t * t for t in tau)) * elasticity.weight(p.setting), p.mesh,
                                   ng.BND, definedon=p.mesh.Boundaries(p.interface), order=energy_order(p.order)))
    forces = [abs(f[k]) for comp in bodies.values() for f in comp.values()
              for k in ("applied", "interface", "supports")]
    scale = max(forces + [magnitude])
    worst = max(abs(f["imbalance"]) for comp in bodies.values() for f in comp.values())
    return {"bodies": bodies, "scale": scale, "error": worst / scale if scale > 0 else 0.0,
            "tolerance": EQUILIBRIUM_RTOL}


def interface_profile(sol: MacroSolution, points_per_element: int = 5) -> dict:
    """Values along the interface curve (2D and axisymmetric only).

    Returns arrays ``s`` (arc length from the end with the largest ``y``, or
    ``z``), the coordinates (``r, z`` or ``x, y``), ``pressure`` (compression
    positive), ``shear`` (traction along ``t0``), ``jump_n`` (``J . n0``,
    positive closes), ``jump_t`` (``J . t0``) and ``status``: ``open`` where
    ``p <= 0`` (for a bilateral linear law: tension), else ``stick`` / ``slip``
    (with friction: ``|J_t|`` within / beyond the Huber width; without: by
    whether the law has a tangential stiffness).  Element end points appear
    once per element, so values that jump at a kink of ``n0`` show both sides.
    """
    return profile_of(sol, profile_rows(sol, points_per_element))


def profile_rows(sol: MacroSolution, points_per_element: int = 5) -> np.ndarray:
    """The samples of :func:`interface_profile` on this process's interface elements, in their order:
    shape ``(elements, points, 6)``, columns ``x, y``, the tractions ``tau_n, tau_t``, the jumps ``a_n, a_t``."""
    p = sol.problem
    mesh = p.mesh
    if mesh.dim != 2:
        raise ModelError("an interface profile needs a 2D or axisymmetric mesh")
    k = max(2, int(points_per_element))
    rule = ng.IntegrationRule([(t,) for t in np.linspace(0.0, 1.0, k)], [0.0] * k)
    mips = mesh.MapToAllElements(rule, mesh.Boundaries(p.interface))
    tau = interface_tractions(sol)
    a = sol.local_jump
    cf = ng.CF((ng.x, ng.y, tau[0], tau[1], a[0], a[1]))
    return np.asarray(cf(mips)).reshape(-1, k, 6)


def profile_of(sol: MacroSolution, vals: np.ndarray) -> dict:
    """:func:`interface_profile` from the samples of every interface element (:func:`profile_rows`)."""
    p = sol.problem
    order = _chain(vals[:, 0, :2], vals[:, -1, :2])
    rows = np.concatenate([vals[e, ::-1] if flip else vals[e] for e, flip in order])
    steps = np.hypot(np.diff(rows[:, 0]), np.diff(rows[:, 1]))
    s = np.concatenate([[0.0], np.cumsum(steps)])
    press, shear, jn, jt = rows[:, 2], rows[:, 3], rows[:, 4], rows[:, 5]
    status = _status(sol, press, jt)
    names = COMPONENTS[p.setting]
    return {"s": s, names[0]: rows[:, 0], names[1]: rows[:, 1], "pressure": press, "shear": shear,
            "jump_n": jn, "jump_t": jt, "status": status}


def interface_surface(sol: MacroSolution) -> dict:
    """Values on the interface surface of a 3D solution, the counterpart of :func:`interface_profile`.

    Sampled on each boundary triangle of ``S_0`` at its three vertices, its
    edge midpoints and its centroid (a shared vertex once per triangle).
    Returns arrays ``x, y, z``, ``pressure`` (compression positive),
    ``shear_1``, ``shear_2`` (tractions along the local tangents ``t1, t2``
    of :mod:`ngcontact.laws.local_frame`), ``shear`` (their magnitude),
    ``jump_n``, ``jump_t1``, ``jump_t2``, and ``status`` as in the profile,
    and ``contact_area``: the area of ``S_0`` where ``p > 0`` over its whole
    area, integrated with the energy's quadrature.
    """
    return surface_of(sol, surface_rows(sol))


def surface_rows(sol: MacroSolution) -> np.ndarray:
    """The samples of :func:`interface_surface` on this process's interface triangles, in their order:
    one row per point (:data:`SURFACE_POINTS` of each triangle in turn), columns ``x, y, z``, the tractions
    ``tau_n, tau_1, tau_2`` and the jumps ``a_n, a_1, a_2``."""
    tau = interface_tractions(sol)
    a = sol.local_jump
    cf = ng.CF((ng.x, ng.y, ng.z, tau[0], tau[1], tau[2], a[0], a[1], a[2]))
    return np.asarray(cf(_surface_points(sol))).reshape(-1, 9)


def surface_of(sol: MacroSolution, v: np.ndarray) -> dict:
    """:func:`interface_surface` from the samples of every interface triangle (:func:`surface_rows`); the
    contact area is integrated over the (possibly distributed) mesh."""
    p = sol.problem
    mesh = p.mesh
    tau = interface_tractions(sol)
    shear = np.hypot(v[:, 4], v[:, 5])
    slip = np.hypot(v[:, 7], v[:, 8])
    on = mesh.Boundaries(p.interface)
    order = energy_order(p.order)
    area = ng.Integrate(ng.CF(1.0), mesh, ng.BND, definedon=on)
    pressed = ng.Integrate(ng.IfPos(tau[0], 1.0, 0.0), mesh, ng.BND, definedon=on, order=order)
    return {"x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "pressure": v[:, 3], "shear_1": v[:, 4],
            "shear_2": v[:, 5], "shear": shear, "jump_n": v[:, 6], "jump_t1": v[:, 7], "jump_t2": v[:, 8],
            "status": _status(sol, v[:, 3], slip), "contact_area": float(pressed / area)}


#: Sample points of :func:`interface_surface` in each boundary triangle: vertices, edge midpoints, centroid (last)
SURFACE_POINTS = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5), (1 / 3, 1 / 3))


def _surface_points(sol: MacroSolution):
    """The mapped :data:`SURFACE_POINTS` of every boundary triangle of ``S_0`` (3D meshes only)."""
    p = sol.problem
    if p.mesh.dim != 3:
        raise ModelError("an interface surface needs a 3D mesh")
    rule = ng.IntegrationRule(list(SURFACE_POINTS), [0.0] * len(SURFACE_POINTS))
    return p.mesh.MapToAllElements(rule, p.mesh.Boundaries(p.interface))


def interface_surface_frame(sol: MacroSolution) -> np.ndarray:
    """The local frame ``(n0, t1, t2)`` at the samples of :func:`interface_surface`, shape ``(n, 3, 3)``.

    Row ``k`` of sample ``i`` is the ``k``-th basis vector of
    :func:`ngcontact.laws.local_frame.local_frame` (the frame the law is
    written in), evaluated on the interface's own boundary elements.
    """
    frame = ng.CF(tuple(sol.frame))
    return np.asarray(frame(_surface_points(sol))).reshape(-1, 3, 3)


def interface_samples(sol: MacroSolution, points_per_element: int = 5) -> dict:
    """The interface samples of any macro solution: :func:`interface_profile` in 2D and axisymmetry,
    :func:`interface_surface` in 3D (``points_per_element`` applies to the profile only).

    Both carry ``pressure`` (compression positive) at the same points on
    every call for the same mesh, which is what the two-scale loop compares
    between its updates (:mod:`ngcontact.coupling.two_scale`).
    """
    if sol.problem.mesh.dim == 3:
        return interface_surface(sol)
    return interface_profile(sol, points_per_element)


def _status(sol: MacroSolution, press, jt) -> list:
    law = sol.problem.law
    if law.friction is not None:
        closed = np.where(np.abs(jt) <= law.friction.width, "stick", "slip")
    else:
        closed = np.full(len(press), "stick" if law.holds_tangentially else "slip")
    return [("open" if pv <= 0 else str(c)) for pv, c in zip(press, closed)]


def _chain(starts, ends) -> list:
    """Order segments into chains: list of ``(element, reversed)``."""
    def key(p):
        return (round(float(p[0]), 12), round(float(p[1]), 12))

    at: dict[tuple[float, float], list[int]] = {}
    for e, (a, b) in enumerate(zip(starts, ends)):
        at.setdefault(key(a), []).append(e)
        at.setdefault(key(b), []).append(e)
    left = set(range(len(starts)))
    order = []
    while left:
        ends_ = [pt for pt, es in at.items() if len([e for e in es if e in left]) == 1]
        pool = ends_ or [key(starts[e]) for e in left]
        cur = max(pool, key=lambda q: (q[1], -q[0]))
        while True:
            nxt = [e for e in at.get(cur, []) if e in left]
            if not nxt:
                break
            e = nxt[0]
            left.discard(e)
            flip = key(starts[e]) != cur
            order.append((e, flip))
            cur = key(starts[e]) if flip else key(ends[e])
    return order


def detachments(profile: dict) -> list:
    """Points along the interface where the status changes between open and closed.

    The location is interpolated linearly where the pressure changes sign
    (or halfway between the two samples when it does not).
    """
    names = [k for k in profile if k not in ("s", "pressure", "shear", "jump_n", "jump_t", "status")]
    s, p, st = profile["s"], profile["pressure"], profile["status"]
    out = []
    for i in range(len(s) - 1):
        if (st[i] == "open") == (st[i + 1] == "open"):
            continue
        theta = p[i] / (p[i] - p[i + 1]) if p[i] * p[i + 1] < 0 else 0.5
        point = {"s": float(s[i] + theta * (s[i + 1] - s[i]))}
        for c in names:
            point[c] = float(profile[c][i] + theta * (profile[c][i + 1] - profile[c][i]))
        point["opens_towards_larger_s"] = st[i + 1] == "open"
        out.append(point)
    return out


def peak_pressure(profile: dict) -> dict:
    """Largest contact pressure along the interface with its location."""
    k = int(np.argmax(profile["pressure"]))
    return {key: (float(profile[key][k]) if key != "status" else profile[key][k]) for key in profile}
