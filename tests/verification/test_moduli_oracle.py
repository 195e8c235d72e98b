"""The contact modulus of :mod:`ngcontact.verification.moduli`, against its limits and symmetries.

Two equal bodies halve the modulus of one against a rigid body, ``E2 = inf``
is the rigid body, and the order of the bodies does not matter.  The P-wave
and shear moduli are checked against the 3D isotropic stiffness matrix in
``test_laminate_oracle.py``.
"""
import math

import pytest

from ngcontact.errors import ModelError
from ngcontact.verification.moduli import e_star

E, NU = 1.0, 0.3


def test_e_star_of_two_equal_bodies_and_of_a_rigid_one():
    assert e_star(E, NU, E, NU) == pytest.approx(E / (2 * (1 - NU ** 2)), rel=1e-15)
    assert e_star(E, NU) == pytest.approx(E / (1 - NU ** 2), rel=1e-15)
    assert e_star(E, NU, math.inf) == e_star(E, NU)
    assert e_star(2.0, 0.2, 5.0, 0.4) == pytest.approx(e_star(5.0, 0.4, 2.0, 0.2), rel=1e-15)
    with pytest.raises(ModelError, match="nu2"):
        e_star(1.0, 0.3, 2.0)
    with pytest.raises(ModelError, match=r"nu1 = 0\.5: must lie in"):
        e_star(1.0, 0.5)
