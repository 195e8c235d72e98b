"""The law file of ``ngcontact export --format json``: the law itself, readable back by a macro scene.

Carries everything (nothing is lost): the direction bundle (paper eqs.
31-33), ``K0`` and the gap forces (eq. 34), the pressure-closure table, the
friction coefficient and stick slope, the macro gap, the units and the
source scene's hashes.  Numbers are written with Python's shortest exact
representation, so a macro scene reading the file back
(``interface.law = "file"``, :mod:`ngcontact.scene.law_file`) solves with
the very same law.
"""
from __future__ import annotations

import json

import numpy as np

from ngcontact._version import __version__
from ngcontact.export.law_table import ExportedLaw
from ngcontact.scene.law_file import FORMAT, FORMAT_VERSION

UNITS = {"length": "m", "stress": "Pa", "stiffness": "Pa/m (N/m^3)", "weights": "Pa/m", "gaps": "m",
         "closure": "m", "pressure": "Pa", "K0": "Pa/m", "gap_force": "Pa", "mu": "1", "stick_slope": "Pa/m",
         "frame": "local (n0, t0[, t1]); n0 from the rough into the counter body; compression positive"}


def _plain(a) -> list:
    return np.asarray(a, float).tolist()


def as_dict(law: ExportedLaw) -> dict:
    """The JSON object of :mod:`ngcontact.scene.law_file`."""
    return {
        "format": FORMAT, "format_version": FORMAT_VERSION, "written_by": f"ngcontact {__version__}",
        "source": law.source, "units": UNITS,
        "coefficients": None if law.K0 is None else {
            "K0": _plain(law.K0), "gap_force": _plain(law.gap_force),
            "k_n0": float(law.K0[0, 0]), "k_t0": _plain(np.diag(law.K0)[1:]), "k_nt0": _plain(law.K0[0, 1:])},
        "bundle": None if law.bundle is None else {k: _plain(v) for k, v in law.bundle.items()},
        "normal_curve": {"kinks": _plain(law.kinks), "slope_increments": _plain(law.slopes),
                         "full_contact_pressure": law.full_contact_pressure(), "k_n0": law.k_n0},
        "table": {"closure": _plain(law.closure), "pressure": _plain(law.pressure), "tolerance": law.tolerance,
                  "extrapolation": "zero pressure below the first closure; beyond the last, the last slope"},
        "friction": {"mu": law.mu, "mu_source": law.mu_source, "stick_slope": law.stick_slope},
        "gap": law.gap,
        "not_carried_by_contact_cards": list(law.notes),
    }


def text(law: ExportedLaw) -> str:
    return json.dumps(as_dict(law), indent=1, allow_nan=False) + "\n"
