"""The modelling error of a homogenized interface in a macro run: an estimate from the ratio of scales.

Paper Sec. 3.3 (Prop. 29): the solution ``u^eps`` of the problem with the resolved rough layer of period
``eps`` converges to the homogenized ``u^0`` as ``eps / L`` falls, ``L`` the length over which the
interface carries its load.  For a law that does not depend on ``eps`` (the bundle of paper eqs. 31-33)
the epsilon studies (:mod:`ngcontact.drivers.study_epsilon`, on meshes whose share of the error they
estimate and keep small) measure an error linear in the ratio,

    E(eps) <= C eps / L,

over the relative field (L2 away from the layer) and probe errors, ``L`` the interface's length (for the
femur stem: the arc length of ``S_0``).  :data:`CONSTANTS` holds, per law, the largest ``C = E L / eps``
those studies found for the shipped scenes (``docs/benchmarks.md``, sections ``epsilon_*``; a test
recomputes it from a study and checks the constant still bounds it).  A macro run whose law homogenizes a
roughness of known period states

    E ~ C eps / L,   eps = the roughness period,  L = the interface's length (3D: the square root of its area),

flagged as an estimate: ``C`` comes from other geometries, and the scene's own constant may be
smaller (the rectangular-valley blocks measure one a hundred times smaller than the femur's grooves).

Laws without a constant say why instead: the whole-surface linearization (paper eq. 34) glues every wall,
and where walls open its error does not fall with ``eps`` at all (the studies measure a field error that
stays put); a law given by its numbers, with no roughness period, homogenizes nothing the package knows.
"""
from __future__ import annotations

from typing import Any

#: per law: the largest E L / eps of the shipped epsilon studies (field and probe errors) and where from
CONSTANTS = {"bundle": (0.48, "femur_stem_grooves epsilon study, probe error at N = 4 (E N = 0.474); the block "
                              "study's constant is 0.005")}
#: per law: why its modelling error has no estimate from eps
NO_CONSTANT = {"linear": "the whole-surface linear law glues every wall; where walls open its error does not fall "
                         "with eps (the epsilon studies measure a field error that stays put): use the bundle law",
               "tabulated": "a tabulated pressure-closure law carries no tangential coupling of the walls; no epsilon "
                            "study measures its constant",
               "file": "no epsilon study measures the constant of a law read from a file",
               "two_scale": "no epsilon study measures the constant of the two-scale loop's pressure-dependent law"}


def estimate(law: str, period: float | None, length: float) -> dict[str, Any]:
    """The modelling-error estimate of a macro run whose interface ``law`` homogenizes a roughness of
    ``period`` (``None``: not known) over an interface of ``length`` (module docstring).

    ``{"estimated", "relative_error", "eps_over_length", "constant", "how"}``; ``relative_error`` is
    ``None`` where no estimate exists, and ``how`` says why.
    """
    out: dict[str, Any] = {"estimated": False, "relative_error": None, "eps_over_length": None,
                           "constant": None}
    if period is None:
        out["how"] = ("not estimated: the law is given by its numbers and the scene states no roughness period "
                      "(interface.roughness_period, or a law from interface.cell)")
        return out
    ratio = float(period) / float(length)
    out["eps_over_length"] = ratio
    if law not in CONSTANTS:
        out["how"] = "not estimated: " + NO_CONSTANT.get(law, f"no epsilon study measures the {law} law's constant")
        return out
    constant, source = CONSTANTS[law]
    out.update(estimated=True, relative_error=constant * ratio, constant=constant,
               how=f"an estimate C eps / L (paper Prop. 29, error linear in eps) with eps = {period:.3g} m the "
                   f"roughness period, L = {length:.3g} m the interface's length, and C = {constant:g} the "
                   f"largest measured ({source}); the scene's own constant may be smaller")
    return out
