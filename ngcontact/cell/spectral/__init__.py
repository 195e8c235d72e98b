"""The small-slope cell problem on the grid of its gap, solved with FFTs.

Both bodies are flat periodic layers whose surface compliance is diagonal in Fourier space (paper eqs.
49-51 in the small-slope form); :class:`~ngcontact.cell.spectral.layered_cell.SpectralCell` solves the
contact problem by constrained conjugate gradients (frictionless) or accelerated proximal gradients
(friction), and :class:`~ngcontact.cell.spectral.spectral_solver.SpectralCellSolver` answers the cell
protocol of :mod:`ngcontact.cell.cell_solver` with it.  Nothing here knows the FE cell.
"""
