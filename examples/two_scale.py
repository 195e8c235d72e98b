"""Two-scale coupling: the interface law follows the contact pressure (paper Sec. 3.5).

On a machined stem the grooves touch the bone only near their crests, and the
real contact area, and with it the interface stiffness, grows with the
pressure.  One homogenized law for the whole interface cannot capture that.
The scene ``geometries/femur_stem_two_scale.toml`` (the femur of
``examples/femur_strength.py`` with a grooved stem, cell
``geometries/cells/stem_grooves.toml``) couples the scales instead:

1. start from an assumed contact set (10 % of each groove in contact),
2. solve the macro problem with that law,
3. take the macro normal stresses as the loads of the groove cell and
   tabulate its response: real contact fraction and mean closure against
   the pressure (refined adaptively, so that the number of cell solves does
   not grow with the interface points; cached on disk, so a second run
   solves no cell problem; the scene solves this small-slope cell, a flat
   interface with the grooves in its gap, by the spectral method),
4. solve the macro problem again, warm-started, with the cell's own
   response ``p(closure)`` as the interface law at every point (the fixed
   point of the paper's coefficient updates), and stop once the table
   covers the macro pressures and the pressure changes by less than ``tol``
   (10 kPa) anywhere.

The report's ``two_scale`` entry holds the history.  The key number is the
peak contact pressure of the converged coupled solution.

Run from the repository's top directory (scene paths are relative to it);
about 10 s::

    python examples/two_scale.py
"""
import ngcontact


def main() -> float:
    """Run the coupled femur scene; return its converged peak contact pressure [Pa]."""
    report, _ = ngcontact.solve("geometries/femur_stem_two_scale.toml")
    loop = report["results"]["two_scale"]

    print(" iteration   peak pressure [MPa]   largest change [kPa]   cell solves so far")
    for step in loop["history"]:
        change = "-" if step["max_change"] is None else f"{step['max_change'] / 1e3:.1f}"
        print(f" {step['iteration']:9d}   {step['max_pressure'] / 1e6:19.3f}   {change:>20}"
              f"   {step['cell_solves']:18d}")
    print(f"converged: {loop['converged']} after {loop['iterations']} law updates, "
          f"{loop['macro_solves']} macro and {loop['cell_solves']} cell solves")

    # The real contact share of the grooves along the interface, from the cell table.
    fraction = loop["interface_coefficients"]["contact_fraction"]
    print(f"groove contact fraction along the interface: {min(fraction):.3f} .. {max(fraction):.3f}")

    peak = max(report["results"]["interface"]["pressure"])
    print(f"peak contact pressure {peak / 1e6:.3f} MPa")
    return peak


if __name__ == "__main__":
    main()
