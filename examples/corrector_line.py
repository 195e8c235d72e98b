"""The first-order corrector along a line across the rough interface: u^eps, u^0 and u^0 + eps u^1.

The scene ``geometries/direct/block_rect_valleys.toml`` (two blocks meeting along rectangular valleys,
sheared and pressed) is solved twice with ``N = 8`` periods: resolved (``u^eps``, the valleys in the
mesh) and homogenized (``u^0``, a flat interface ``S_0`` at ``y = 0`` carrying the cell's bundle law).
Along the vertical line through the middle of a valley the counter's tooth fills ``-0.3 eps < y < 0``:
there ``u^eps`` is the counter's displacement, while ``u^0`` is the rough body's, one interface jump
away.  The corrector of :mod:`ngcontact.coupling.first_order_corrector` gives the tooth the counter's
macro field, extended across ``S_0``, and adds the cell's boundary layer ``eps u^1``
(:mod:`ngcontact.drivers.boundary_layer_cells`: one FE cell per period, loaded by the period's mean macro
traction).  The key number is the largest ``|u_x^c - u_x^eps|`` on the line
divided by the largest ``|u_x^eps|`` there (``u^0`` alone: the jump's share).  Writes the plot to
``corrector_line.png`` in the working directory (``main(out=...)``: elsewhere).

    python examples/corrector_line.py
"""
import numpy as np

from ngcontact.coupling.first_order_corrector import FirstOrderCorrector
from ngcontact.drivers import run_resolved as drv
from ngcontact.drivers import study_epsilon as study
from ngcontact.drivers.boundary_layer_cells import boundary_layer
from ngcontact.drivers.modelling_error import displacement_at, resolved_body
from ngcontact.laws.homogenized import InterfaceLaw
from ngcontact.scene.loader import load

SCENE = "geometries/direct/block_rect_valleys.toml"
N = 8                # periods: eps = L / N
VALLEY = 3           # the line runs through the middle of this period's valley


def main(out: str = "corrector_line.png") -> float:
    """Solve both models, sample the line, plot it; return the corrected field's largest relative error."""
    scene = load(SCENE)
    eps = drv.eps_of(scene, N)
    resolved = drv.solve_scene(scene, drv.problem_of(scene, drv.build_resolved(scene, N)))
    flat = drv.build_flat(scene, scene.study.interface_maxh)
    macro = study.solve_homogenized(scene, flat, InterfaceLaw(normal=study.cell_bundle(scene)))
    y = np.linspace(-2.0 * eps, 2.0 * eps, 80)      # no sample on the interfaces y = 0, -0.3 eps
    line = np.column_stack([np.full_like(y, (VALLEY + 0.5) * eps), y])
    body = resolved_body(resolved.problem.mesh, line)
    corrector = FirstOrderCorrector(macro, eps, width=2.0 * eps, layer=boundary_layer(scene, macro, N))
    u_eps = displacement_at(resolved, line, body)
    u_0, u_c = corrector.homogenized(line), corrector.at(line, body)
    scale = np.max(np.abs(u_eps[:, 0]))
    plain = float(np.max(np.abs(u_0[:, 0] - u_eps[:, 0])) / scale)
    corrected = float(np.max(np.abs(u_c[:, 0] - u_eps[:, 0])) / scale)
    print(f"eps = {eps:g} m, line x = {line[0, 0]:g} m, {np.count_nonzero((body == 1) & (y < 0))} samples "
          "in the counter's tooth below S_0")
    print(f"largest |u_x - u_x^eps| / largest |u_x^eps| on the line: u^0 {plain:.4f}, "
          f"u^0 + eps u^1 {corrected:.4f}")
    _plot(out, y / eps, u_eps, u_0, u_c)
    return corrected


def _plot(out, y, u_eps, u_0, u_c) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for k, name in enumerate(("u_x", "u_y")):
        ax[k].plot(y, u_eps[:, k], "k-", lw=2, label="u^eps (resolved)")
        ax[k].plot(y, u_0[:, k], "C0--", label="u^0 (homogenized)")
        ax[k].plot(y, u_c[:, k], "C1:", lw=2, label="u^0 + eps u^1")
        ax[k].axvspan(-0.3, 0.0, color="gray", alpha=0.2)
        ax[k].set_xlabel("y / eps")
        ax[k].set_ylabel(f"{name} [m]")
        ax[k].grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
