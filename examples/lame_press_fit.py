"""A shrink fit with a compliant rough interface: the macro solver against Lamé's solution.

A hollow steel shaft (bore radius 10 mm) is pressed into a bronze hub (outer
radius 40 mm) along a 20 mm radius with 20 micrometres of radial
interference.  Long cylinders are in plane strain; each one is a thick ring
whose radial displacement is ``u_r = A r + B/r`` (Lamé).  Under the
interface pressure ``p`` the hub's bore opens by ``p C_out`` and the shaft
closes by ``p C_in`` (compliances from Lamé's solution).

The surfaces are rough, and the asperities flatten too: the homogenized
interface law is a Winkler layer ``p = k_n x`` (its closure ``x``).  Here
``k_n = 1e13 Pa/m``: a layer that gives 1 micrometre under 10 MPa.  The
interference is shared between the three compliances in series,

    p = delta / (C_in + C_out + 1/k_n),

so the rough interface carries noticeably less pressure than Lamé's
rigid-interface press fit (``1/k_n = 0``).

The scene is built in Python as the dictionary a TOML file would hold
(kind ``macro``, shape ``coaxial``: a quarter of both tubes with symmetry
supports), validated by :func:`ngcontact.scene.loader.from_dict` and solved
by ``ngcontact.solve``; the interference enters as a negative gap.  The key
number is the mean interface pressure of the finite element solution.

    python examples/lame_press_fit.py
"""
import numpy as np

import ngcontact
from ngcontact.scene.loader import from_dict
from ngcontact.verification.lame import lame_press_fit_pressure

A, B, C = 0.010, 0.020, 0.040          # shaft bore, interface, hub outer radius [m]
STEEL, BRONZE = (210e9, 0.30), (110e9, 0.34)   # (E [Pa], nu)
DELTA = 20e-6                          # radial interference [m]
K_N = 1e13                             # interface (Winkler) stiffness [Pa/m]


def main() -> float:
    """Solve the press fit; return the mean contact pressure on the interface [Pa]."""
    scene = from_dict({
        "kind": "macro",
        "title": "Steel shaft in a bronze hub, rough interface",
        "materials": {"steel": {"E": STEEL[0], "nu": STEEL[1]},
                      "bronze": {"E": BRONZE[0], "nu": BRONZE[1]}},
        "bodies": {"rough": "steel", "counter": "bronze"},     # inner = rough, outer = counter
        "geometry": {"shape": "coaxial", "setting": "plane_strain",
                     "dimensions": {"a": A, "b": B, "c": C}},
        # linear law: p = k_n (J_n - g); a negative gap is an interference
        "interface": {"law": "linear", "kn": K_N, "gap": -DELTA},
        # the quarter model: symmetry planes x = 0 and y = 0
        "supports": [{"boundary": "sym_x", "components": ["x"]},
                     {"boundary": "sym_y", "components": ["y"]}],
        # order 4 on curved elements: the circular interface is represented to ~1e-4
        "discretization": {"order": 4, "maxh": 0.005},
    })
    report, _ = ngcontact.solve(scene)

    # The pressure along the interface is uniform in theory; its scatter is the discretization error.
    pressure = np.asarray(report["results"]["interface"]["pressure"])
    mean = float(pressure.mean())

    exact = lame_press_fit_pressure(A, B, C, *STEEL, *BRONZE, DELTA, k_n=K_N)
    rigid = lame_press_fit_pressure(A, B, C, *STEEL, *BRONZE, DELTA)
    print(f"Lame, rigid interface:        {rigid / 1e6:8.3f} MPa")
    print(f"Lame, compliant interface:    {exact / 1e6:8.3f} MPa")
    print(f"finite elements, min .. max:  {pressure.min() / 1e6:8.3f} .. {pressure.max() / 1e6:.3f} MPa")
    print(f"mean interface pressure {mean / 1e6:.4f} MPa ({mean / exact - 1:+.1e} off Lame)")
    return mean


if __name__ == "__main__":
    main()
