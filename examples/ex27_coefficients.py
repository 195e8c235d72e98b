"""Paper Example 27: homogenized stiffness of a rectangular valley, numerically and in closed form.

When every point of the rough contact surface ``S_C`` is in contact and the
micro penalty ``k_n`` is constant, the homogenized interface stiffness (paper
eq. 34) is a purely geometric integral over one cell of period ``|T|``:

    K0 = (k_n / |T|) * integral over S_C of n n^T ds,

``n`` the micro normal.  Its entries in the macro frame (normal ``n0``,
tangent ``t0``) are ``k_n0``, ``k_t0`` and the coupling ``k_nt0``.  A face
parallel to the macro interface contributes its length to ``k_n0``, a face
normal to it its length to ``k_t0``: a rectangular valley turns part of a
pressing contact into a shear-carrying one (the valley walls hold the
interface against sliding without any friction).

Here the valley is 0.4 wide and 0.3 deep in a unit period: the faces parallel
to ``S_0`` are the two plateaus (0.6 together) and the valley bottom (0.4),
the faces normal to it the two walls (0.3 each), so in units of ``k_n/|T|``

    k_n0 = 0.6 + 0.4 = 1.0,   k_t0 = 2 x 0.3 = 0.6,   k_nt0 = 0 (symmetric).

The cell is built from a profile (:mod:`ngcontact.geometry.profiles`: the
rough body below, the counter body filling the valley above) and the
coefficients integrated on its curved mesh by
:func:`ngcontact.cell.coefficients.coefficients`.  The key number is
``k_t0``, the tangential stiffness that only the walls provide.

    python examples/ex27_coefficients.py
"""
from ngcontact.cell.coefficients import coefficients
from ngcontact.geometry.profiles import profile_cell, rectangular_valley


def main() -> float:
    """Compute the Example-27 coefficients of the rectangular valley; return ``k_t0`` (units of ``k_n/|T|``)."""
    width, depth = 0.4, 0.3                       # valley in a unit period |T| = 1

    # One periodic cell: the rough body (0.8 below the summits) and the counter body
    # (0.6 above them) filling the valley; the mesh is only needed for the surface integral.
    cell = profile_cell(rectangular_valley(width=width, depth=depth), h_rough=0.8, h_counter=0.6,
                        maxh=0.1, order=2)

    # Eq. 34 with k_n = 1: the coefficients come out in units of k_n / |T|.
    c = coefficients(cell, kn=1.0)

    # The closed form from the face lengths.
    exact = {"k_n": (1.0 - width) + width, "k_t": 2 * depth, "k_nt": 0.0}
    for key in ("k_n", "k_t", "k_nt"):
        print(f"{key}0 = {getattr(c, key):+.12f}   closed form {exact[key]:+.12f}")
    print(f"homogenized friction mu0 = k_nt0 / k_n0 = {c.mu:.2e} (no preferred sliding direction)")
    print(f"k_t0 = {c.k_t:.10f} k_n/|T|")
    return c.k_t


if __name__ == "__main__":
    main()
