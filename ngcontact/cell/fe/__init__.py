"""The cell problem by finite elements: two meshed bodies and their contact surface ``S_C`` (any profile).

:class:`~ngcontact.cell.fe.cell_problem.CellProblem` discretizes the cell problem of paper eqs. 49-51
(penalized, eq. 65, or with exact non-penetration) and solves its loads by Newton's method;
:class:`~ngcontact.cell.fe.fe_cell.FECell` answers the cell protocol of :mod:`ngcontact.cell.cell_solver`
with it.  Nothing here knows the spectral cell: its start of first loads arrives as a
:class:`~ngcontact.cell.fe.load_start.Predictor` object.
"""
