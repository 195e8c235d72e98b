"""Westergaard's wavy contact: the cell solver against the exact real contact area.

Two elastic bodies whose surfaces leave a periodic gap ``2h sin^2(pi x/lambda)``
between them are pressed together by a mean pressure ``p``.  They first touch
along lines, one per period; as ``p`` grows the contact patches widen until,
at

    p* = pi E* h / lambda        (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2),

the gap is closed everywhere.  Below ``p*`` Westergaard's solution gives the
share of each period in contact,

    2a/lambda = (2/pi) asin(sqrt(p/p*)),

which grows like the square root of the load at first.  The real contact
area is the quantity the homogenized law is made of (paper eq. 34 integrates
over it only), so it is the first thing a cell solver must get right.

The shipped scene ``geometries/cells/westergaard.toml`` models it as the
paper's cell problem with a flat interface carrying the sinusoid as its
initial gap (the small-slope model the formula assumes), a stiff penalty
``k_n = 1e3 E`` and five loads ``p/p*`` from 0.05 to 1.2.  The example reads
the scene with ``ngcontact.load`` to compute ``p*`` from its own numbers
(:mod:`ngcontact.verification.westergaard`), solves it with ``ngcontact.solve``
and prints the contact fraction of every load next to Westergaard's.  The
key number is the fraction at ``p = p*/2`` (exactly 1/2); the finite penalty
lets the bodies overlap slightly and widens the patches by a share of the
answer that the report states (``results.accuracy.model``: about +0.3 %).

Run from the repository's top directory (scene paths are relative to it)::

    python examples/westergaard.py
"""
import ngcontact
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

SCENE = "geometries/cells/westergaard.toml"


def main() -> float:
    """Solve the Westergaard cell scene; return the contact fraction at ``p = p*/2``."""
    # The scene as validated data: the oracle takes its numbers from the same file.
    scene = ngcontact.load(SCENE)
    rough = scene.materials[scene.bodies.rough]
    counter = scene.materials[scene.bodies.counter]
    p_star = westergaard_p_star(e_star(rough.E, rough.nu, counter.E, counter.nu),
                                scene.contact.gap.h, scene.geometry.period)
    print(f"p* = {p_star:.6g}")

    # One cell solve per load of the sweep (Newton on the penalty contact problem).
    report, _ = ngcontact.solve(scene)

    key = None
    print("  p/p*   contact fraction   Westergaard   relative difference")
    for load in report["results"]["loads"]:
        p = load["mean_pressure"]                 # (1/|T|) * integral of the contact pressure
        exact = westergaard_contact_fraction(p, p_star)
        got = load["contact_fraction"]            # |{x in S_C : pressure > 0}| / |T|
        print(f"  {p / p_star:4.2f}   {got:16.5f}   {exact:11.5f}   {got / exact - 1:+.2e}")
        if abs(p / p_star - 0.5) < 1e-3:
            key = got
    print(f"contact fraction at p = p*/2: {key:.5f} (Westergaard: 0.5)")
    return key


if __name__ == "__main__":
    main()
