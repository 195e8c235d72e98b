"""Geometry: periodic rough cells and macro bodies, built with Netgen.

Geometry knows no physics.  Every builder returns a mesh whose regions and
boundaries follow one naming contract:

Cells (periodic in the tangential directions)
    regions   ``rough`` (paper ``D``, carries the roughness, below) and
              ``counter`` (paper ``Omega``, above);
    faces     ``contact``  the potential contact surface ``S_C``;
              ``free``     free surfaces ``S_N`` bounding voids (summit arrangement);
              ``bottom``   the far face of ``rough``;
              ``top``      the far face of ``counter``;
              ``periodic`` lateral faces, identified periodically;
              ``symmetry_x``, ``symmetry_y`` instead of them on a quarter
              ``[0, P/2]^2`` of a 3D cell even about its mid-lines (mirror
              planes ``x = 0, P/2`` and ``y = 0, P/2``).
    The macro interface normal ``n0`` is ``+e_y`` in 2D and ``+e_z`` in 3D;
    the tangential coordinates are ``x`` (2D) or ``x, y`` (3D); the cell
    spans ``[0, period]`` in each of them; ``|T|`` is the period (2D) or the
    product of the periods (3D).  The micro normal on ``contact`` points from
    ``rough`` into ``counter``.
"""
