"""Every headline quantity of a spectral cell refined to a tolerance carries its estimate (issue 35).

Westergaard's sinusoid ``g0 = 2h sin^2(pi x)`` (period 1) between two layers twice the period deep (their
finite depth moves the half-space answer by less than the errors held here) gives closed forms for the
contact fraction ``2a`` (:mod:`ngcontact.verification.westergaard`) and for the coefficients of eq. 34 on the
real contact set ``|x| < a``: ``k_n0 = k_n 2a`` and ``g_n = k_n int_{-a}^{a} g0 dx = k_n h (2a - sin(2 pi a) /
pi)``.  The mean closure and the normal effective stiffness are held against the same cell on a grid 16
times finer.  The estimate, in each quantity's measure (:func:`ngcontact.cell.cell_solution.measure`),
bounds the true error in that measure: effectivity at least 1.
"""
import json
import math

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline, measure
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import sweep_to_tolerance, uncontrolled
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star
from sinusoid_cell import sinusoid_cell

NU, H, K_N = 0.3, 0.01, 1e3
P_STAR = westergaard_p_star(e_star(1.0, NU) / 2, H, 1.0)
LOADS = (0.05, 0.2, 0.5)


def _cell(n):
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 2.0), counter=Layer(1.0, NU, 2.0),
                        gap=2 * H * np.sin(np.pi * np.arange(n) / n) ** 2, k_n=K_N, enforcement="exact", tol=1e-12,
                        max_iter=100000)


def _closed_forms(ratio):
    two_a = westergaard_contact_fraction(ratio * P_STAR, P_STAR)
    return {"contact_fraction": two_a, "coefficient_k_n": K_N * two_a,
            "coefficient_g_n": K_N * H * (two_a - math.sin(math.pi * two_a) / math.pi)}


@pytest.fixture(scope="module")
def refined():
    loads = [cell_load(2, pressure=r * P_STAR) for r in LOADS]
    sweep = sweep_to_tolerance(_cell, loads, 1e-3, 64, 2, 2 ** 16)
    finer = _cell(16 * sweep.history[-1]["grid"]).sweep(loads)
    return sweep, finer


def test_every_headline_quantity_of_each_load_is_estimated(refined):
    sweep, _ = refined
    for est, sol in zip(sweep.estimates, sweep.solutions):
        assert set(est) == {"contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n",
                            "coefficient_g_n"}       # k_t, k_nt, g_t, G_n, G_t: zero on every grid (flat)
        assert set(est) <= set(headline(sol.results))
    assert sweep.estimate <= 1e-3 and uncontrolled(2) == () and uncontrolled(3) == ("normal_stiffness",)


def test_the_estimates_bound_the_true_errors_on_westergaard(refined):
    sweep, finer = refined
    scales = sweep.scales
    for k, (ratio, est, sol, ref) in enumerate(zip(LOADS, sweep.estimates, sweep.solutions, finer)):
        exact = dict(_closed_forms(ratio))
        head, fine = headline(sol.results), headline(ref.results)
        exact.update({name: fine[name] for name in ("mean_closure", "normal_stiffness")})
        for name, e in est.items():
            error = abs(head[name] - exact[name]) / scales[k][name]
            assert e >= error, (k, name, e, error)
        # the measures: a coefficient against its whole-surface value (k_n, k_n mean g0), not its own
        assert scales[k]["coefficient_k_n"] == pytest.approx(K_N)
        assert scales[k]["coefficient_g_n"] == pytest.approx(K_N * H, rel=1e-9)
        assert scales[k]["contact_fraction"] == 1.0 and measure("contact_fraction") == "absolute"
        assert scales[k]["mean_closure"] == abs(head["mean_closure"])


def test_the_2d_coefficients_are_integrals_over_the_located_contact_set(refined):
    """``k_n0`` is ``k_n`` times the reported contact fraction (edges between points), and ``g_n`` on the
    reported grid is within its estimate of the closed form, where the points in contact alone miss it by
    more."""
    sweep, _ = refined
    for ratio, sol in zip(LOADS, sweep.solutions):
        c = sol.results["coefficients"]
        assert c["k_n"] == pytest.approx(K_N * sol.results["contact_fraction"], rel=1e-12)
        exact = _closed_forms(ratio)["coefficient_g_n"]
        counted = K_N * H * 2 * float(np.sum(np.sin(np.pi * np.arange(sweep.history[-1]["grid"]) /
                                                    sweep.history[-1]["grid"]) ** 2 *
                                             (sol.fields["pressure"] > 0))) / sweep.history[-1]["grid"]
        assert abs(c["g_n"] - exact) < abs(counted - exact)


def test_a_spectral_scene_with_a_tolerance_reports_the_coefficients_and_holds_the_stiffness(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(sinusoid_cell(pressure="0.000863075, 0.0034523", depth="2.0",
                                  discretization='method = "spectral"\ngrid = 128\ntolerance = 1e-3'))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    rep = json.loads((tmp_path / "o" / "report.json").read_text())
    acc = rep["results"]["accuracy"]
    assert acc["met"]
    for k, load in enumerate(rep["results"]["loads"]):
        entries = {q["name"]: q for q in acc["quantities"] if q["load"] == k}
        assert {"contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n",
                "coefficient_g_n"} <= set(entries)
        g_n = entries["coefficient_g_n"]
        assert g_n["value"] == load["coefficients"]["g_n"] and g_n["controlled"] == "relative to its group"
        assert g_n["error"] == pytest.approx(g_n["controlled_error"] * g_n["scale"])
        assert g_n["relative_error"] == pytest.approx(g_n["error"] / g_n["value"])
        assert all(q["met"] and q["counted"] for q in entries.values())      # the 2D stiffness held too
        stiffness = entries["normal_stiffness"]
        assert stiffness["value"] == load["effective_stiffness"]["matrix"][0][0]
        assert load["error_estimate"]["normal_stiffness"] == stiffness["controlled_error"] <= 1e-3
        assert load["error_estimate"]["coefficient_g_n"] == g_n["controlled_error"] <= 1e-3
