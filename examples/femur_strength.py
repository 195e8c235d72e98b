"""A hip stem press-fitted into a femur: contact pressure and the strength of the coating layer.

The shipped scene ``geometries/femur_stem.toml`` is the application of
Orlik (2004), Sec. 4.2-4.3: an axisymmetric femur with a cementless titanium
stem pushed into its canal with 50 micrometres of radial interference and
loaded by 1 MPa on its top.  The porous coating of the stem is far too fine
to mesh; the interface carries instead the homogenized law of the paper's
hip cell (square hills, ``k_n0 = 32 GPa/m``) with Coulomb friction 0.3.

``ngcontact.solve`` runs the scene exactly as ``ngcontact run`` does but
writes nothing: it returns the report (plain numbers, see the README's report
reference) and the outcome (the NGSolve meshes and fields).  The scene's
``[strength]`` section then goes back down to the micro scale (paper eqs.
74-78): at every interface point the hip cell is loaded by the macro
pressure, shear and strain, the micro von Mises stress is recovered, and its
largest value in each body is compared with that body's ultimate stress.
The key number is the strength safety factor ``sigma_u / max sigma_eq`` of
the weaker body (eq. 78 holds when it exceeds 1).

This file is the README's Quick start: the body of :func:`main` (without its
``return``), after the imports, is the README's code block, and
``tests/test_examples.py`` checks that they are the same.

Run from the repository's top directory (scene paths are relative to it)::

    python examples/femur_strength.py
"""
import ngcontact


def main() -> float:
    """Solve the femur scene; return the strength safety factor of its coating layer."""
    # Solve a scene file as `ngcontact run` does, without writing output files.
    report, outcome = ngcontact.solve("geometries/femur_stem.toml")
    print(report["effects"])                      # the physical terms that were assembled

    # The interface sample with the largest contact pressure (compression positive, Pa).
    peak = report["results"]["maxima"]["pressure"]
    print(f"peak contact pressure {peak['pressure'] / 1e6:.3f} MPa at z = {peak['z'] * 1e3:.0f} mm")

    # Micro stresses in the coating (paper eqs. 74-78): the largest von Mises stress of
    # each body against its ultimate stress; the safety factor is that of the weaker one.
    strength = report["results"]["strength"]
    worst = strength["bodies"][strength["critical_body"]]
    print(f"largest micro von Mises stress {worst['max_sigma_eq'] / 1e6:.2f} MPa "
          f"in the {strength['critical_body']} body (sigma_u = {worst['sigma_u'] / 1e6:.0f} MPa)")
    print(f"strength safety factor {strength['safety_factor']:.3f}")
    return strength["safety_factor"]


if __name__ == "__main__":
    main()
