"""CalculiX (ccx) solves two blocks and a press fit with the exported law and agrees with this package within 1 %.

Requirement: the law exported for ccx (pressure-overclosure table, friction with the stick slope), used by a
real ccx run on the two blocks of ``ngcontact.verification.calculix_model`` pressed and sheared, gives the reaction
forces and contact pressures of this package's macro solve of the same blocks with the same law read back from
the exported JSON file, within 1 %.  The press lies inside the table's kinked (nonlinear) range and the
interface sticks everywhere in ccx (its stick branch is then the linear law both codes share).  Skipped, with
the reason, where ``ccx`` is not installed (Debian package ``calculix-ccx``; ``.ci/run`` installs it).
"""
import os

import numpy as np
import pytest

from ngcontact.verification.calculix_model import Blocks, ccx_path

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELL = os.path.join(ROOT, "geometries", "macro", "sinusoid_gap_cell.toml")

pytestmark = pytest.mark.skipif(ccx_path() is None, reason="CalculiX `ccx` is not on PATH (install the Debian "
                                "package calculix-ccx to run the client check)")


def test_ccx_agrees_with_the_macro_solve_within_one_percent(tmp_path, monkeypatch):
    from ngcontact.export.calculix_check import compare
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    blocks = Blocks(length=0.02, h_block=0.005, h_base=0.005, E=210e9, nu=0.3, nx=20, ny_block=5, ny_base=5,
                    press=2e-6, shear=0.5e-6)
    r = compare(CELL, str(tmp_path), blocks, length_unit=1e-4, mu=0.3, p_max=1e8)
    law = r["law"]
    # the load tests the law's nonlinear part: pressures between the first and the last kink
    p_ccx = r["ccx"]["pressure"]
    assert 0.2 * law.full_contact_pressure() < p_ccx.min() and p_ccx.max() < law.full_contact_pressure()
    assert p_ccx.max() < law.p_max, "ccx holds the pressure constant beyond the table"
    assert r["stick"] < 1.0, f"ccx slips somewhere (|tau| / (mu p) = {r['stick']:.3g})"
    bad = [f"{name}: ngcontact {a:.6g}, ccx {b:.6g} ({d:.2%})" for name, _, a, b, d in r["rows"] if not d < 0.01]
    assert not bad, "ccx and ngcontact differ by more than 1 %:\n" + "\n".join(bad)
    assert all(np.isfinite([a, b]).all() for _, _, a, b, _ in r["rows"])


def test_ccx_press_fit_agrees_within_one_percent(tmp_path, monkeypatch):
    """Plane-strain press fit: the interference is the exported law's gap g0 (the table shifted by it)."""
    from ngcontact.export.calculix_check import compare_press_fit
    from ngcontact.verification.calculix_model import PressFit
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    fit = PressFit(a=0.01, b=0.02, c=0.03, E=210e9, nu=0.3, n_theta=20, n_inner=5, n_outer=5)
    r = compare_press_fit(CELL, str(tmp_path), fit, length_unit=1e-4, gap=-3e-6, p_max=1e8)
    assert r["law"].gap == -3e-6
    p = r["ccx"]["pressure"]
    assert p.min() > 0 and p.max() < r["law"].full_contact_pressure(), "inside the law's nonlinear range"
    bad = [f"{name}: ngcontact {a:.6g}, ccx {b:.6g} ({d:.2%})" for name, _, a, b, d in r["rows"] if not d < 0.01]
    assert not bad, "ccx and ngcontact differ by more than 1 %:\n" + "\n".join(bad)
