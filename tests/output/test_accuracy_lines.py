"""An accuracy verdict in one terminal line, and its unmet quantities at the top of report.html."""
from ngcontact.output.report import accuracy_line
from ngcontact.output.report_html import accuracy_warnings

VERDICT = {"tolerance": 0.01, "met": False,
           "checks": [{"load": None, "name": "equilibrium", "value": 1e-12, "limit": 1e-6, "ok": True}],
           "quantities": [
               {"name": "peak_pressure", "value": 1.45e6, "error": 240.0, "relative_error": 1.7e-4, "met": True,
                "how": "geometric"},
               {"name": "von_mises_base", "value": 2.1e7, "error": None, "relative_error": None, "met": False,
                "how": "a stress singularity"},
               {"load": 1, "name": "contact_fraction", "value": 0.3, "error": 0.01, "relative_error": 0.033,
                "met": False, "how": "refinement"},
               {"load": 0, "name": "contact_fraction", "value": 0.2, "error": 0.001, "relative_error": 0.005,
                "met": True, "how": "refinement"}]}


def test_the_terminal_line_gives_each_quantity_once_with_its_worst_error():
    line = accuracy_line({"accuracy": VERDICT})
    assert line is not None and line.startswith("accuracy NOT met (tolerance 0.01): ")
    assert "peak_pressure 1.45e+06 +/- 0.02%" in line and "von_mises_base 2.1e+07 (no estimate)" in line
    assert line.count("contact_fraction") == 1 and "+/- 3.30%" in line
    assert accuracy_line({}) is None


def test_unmet_quantities_head_the_page():
    lines = accuracy_warnings({"results": {"accuracy": VERDICT}})
    assert len(lines) == 2
    assert "von_mises_base" in lines[0] and "no error estimate: a stress singularity" in lines[0]
    assert lines[1].endswith("load 1, contact_fraction = 0.3, estimated relative error 0.033")
    assert accuracy_warnings({"results": {"accuracy": dict(VERDICT, met=True)}}) == []


def test_the_terminal_line_ends_with_the_modelling_error_where_it_is_estimated():
    modelling = {"estimated": True, "relative_error": 3.7e-4, "eps_over_length": 7.7e-4, "constant": 0.48,
                 "how": "an estimate C eps / L"}
    line = accuracy_line({"accuracy": dict(VERDICT, modelling=modelling)})
    assert line is not None and line.endswith("; modelling error of the homogenized interface ~ 0.04% "
                                              "(estimate C eps / L)")
    none = dict(modelling, estimated=False, relative_error=None, how="not estimated: no period")
    assert "modelling" not in (accuracy_line({"accuracy": dict(VERDICT, modelling=none)}) or "")


def test_a_verdict_without_an_estimate_says_so_on_the_terminal():
    how = "not estimated: set discretization.tolerance to refine the discretization and estimate its error"
    line = accuracy_line({"accuracy": {"tolerance": 0.01, "met": True, "estimated": False, "how": how,
                                       "checks": []}})
    assert line == f"accuracy {how}"
