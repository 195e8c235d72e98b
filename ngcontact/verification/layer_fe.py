"""The layer compliance of :mod:`ngcontact.cell.spectral.layer_compliance`, solved by finite elements.

An independent check of the closed form: one Fourier mode of a layer
``-h < z < 0`` clamped at ``z = -h`` is a two-point boundary value problem
through the thickness.  With the plane-strain mode

    u_x = a(z) sin(k x),   u_z = b(z) cos(k x),

and the surface tractions ``sigma_xz = S sin(k x)``, ``sigma_zz = T cos(k x)``,
the elastic energy per period (times 2) is

    W(a, b) = 1/2 int_{-h}^{0} [ lam (k a + b')^2 + 2 mu (k a)^2 + 2 mu b'^2
                                 + mu (a' - k b)^2 ] dz  -  T b(0) - S a(0),

and for the antiplane mode ``u_y = c(z) cos(k x)`` under ``sigma_yz = T cos(k x)``

    W(c) = 1/2 int mu (c'^2 + k^2 c^2) dz - T c(0).

Their minimizers, computed here with ``H1`` elements of high order on a 1D
mesh graded towards the loaded face, give ``C_nn = b(0)/T`` and
``c_ln = -a(0)/T`` under the normal load, ``C_ll = a(0)/S`` under the
tangential one, and ``C_aa = c(0)/T``: the quantities of the closed form
(whose complex amplitude ``u_x = i c_ln T e^{ikx}`` is the real mode
``-c_ln T sin(kx)``).
"""
from __future__ import annotations

import ngsolve as ng
from ngsolve.meshes import Make1DMesh


def _mesh(k: float, h: float, n: int):
    # elements of about 1/(4k) near the surface where the mode lives, geometric towards the clamp
    ratio = min(1.0, 1.0 / max(k * h, 1e-12))
    grade = max(1.0, 1.0 / ratio) ** (1.0 / 3.0)
    return Make1DMesh(n, mapping=lambda s: -h * (1.0 - s) ** grade if grade > 1.0 else -h * (1.0 - s))


def layer_fe_compliance(k: float, E: float, nu: float, h: float, *, order: int = 12,
                        elements: int = 24) -> dict[str, float]:
    """``{"nn", "ll", "ln", "aa"}``: the layer's compliances for the wave number ``k > 0`` by 1D FE.

    The 1D mesh maps ``s in [0, 1]`` to ``z = -h (1 - s)^grade`` (``s = 1``
    the loaded face) so that thick layers get small elements where the
    mode decays.
    """
    if not k > 0:
        raise ValueError(f"k = {k!r}: the finite element check needs k > 0 (k = 0 is the uniform layer)")
    mu = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mesh = _mesh(k, h, elements)
    # the mapping sends s = 0 to the clamp z = -h ('left') and s = 1 to the loaded face z = 0 ('right')
    V = ng.H1(mesh, order=order, dirichlet="left")
    X = V * V
    (a, b), (va, vb) = X.TnT()
    da, db = ng.grad(a)[0], ng.grad(b)[0]
    dva, dvb = ng.grad(va)[0], ng.grad(vb)[0]
    form = ng.BilinearForm(X, symmetric=True)
    form += (lam * (k * a + db) * (k * va + dvb) + 2 * mu * k * a * k * va + 2 * mu * db * dvb
             + mu * (da - k * b) * (dva - k * vb)) * ng.dx
    form.Assemble()
    inv = form.mat.Inverse(X.FreeDofs(), inverse="umfpack")
    top = mesh.Boundaries("right")
    out = {}
    for name, (S, T) in (("normal", (0.0, 1.0)), ("tangential", (1.0, 0.0))):
        f = ng.LinearForm(X)
        f += (S * va + T * vb) * ng.ds(top)
        f.Assemble()
        u = ng.GridFunction(X)
        u.vec.data = inv * f.vec
        a0 = ng.Integrate(u.components[0], mesh, definedon=top)
        b0 = ng.Integrate(u.components[1], mesh, definedon=top)
        if name == "normal":
            out["nn"], out["ln"] = float(b0), float(-a0)
        else:
            out["ll"] = float(a0)
    W = ng.H1(mesh, order=order, dirichlet="left")
    c, vc = W.TnT()
    anti = ng.BilinearForm(W, symmetric=True)
    anti += mu * (ng.grad(c)[0] * ng.grad(vc)[0] + k * k * c * vc) * ng.dx
    anti.Assemble()
    f = ng.LinearForm(W)
    f += vc * ng.ds(top)
    f.Assemble()
    cu = ng.GridFunction(W)
    cu.vec.data = anti.mat.Inverse(W.FreeDofs(), inverse="umfpack") * f.vec
    out["aa"] = float(ng.Integrate(cu, mesh, definedon=top))
    return out
