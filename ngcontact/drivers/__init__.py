"""Drivers: compose geometry, model and solver for one scene kind.

Each driver takes a validated scene and returns a
:class:`ngcontact.output.report.Outcome`; it does no file I/O itself.
"""
