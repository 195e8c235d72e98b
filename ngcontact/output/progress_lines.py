"""Progress lines of a long computation inside a stage, printed as the run's stage lines are.

A spectral solve running longer than a few seconds, or each level of a refinement, logs an INFO record to
:data:`PROGRESS_LOGGER` (``logging.getLogger("ngcontact.progress")``: the rooms below the output need no
import of this one).  Within :func:`progress_lines` those records become notes of the run's
:class:`~ngcontact.output.report.Clock`, so they appear where the stage lines appear and ``--quiet`` drops
them with the rest; outside it they go nowhere the run did not ask for.
"""
from __future__ import annotations

import logging
from contextlib import contextmanager

from ngcontact.output.report import Clock

#: The logger of the progress lines of long computations inside a stage (a spectral solve running longer
#: than a few seconds, each level of a refinement): :func:`progress_lines` prints them as the stage lines.
PROGRESS_LOGGER = "ngcontact.progress"


class _ProgressHandler(logging.Handler):
    def __init__(self, clock: Clock):
        super().__init__(logging.INFO)
        self.clock = clock

    def emit(self, record: logging.LogRecord) -> None:
        self.clock.note(record.getMessage())


@contextmanager
def progress_lines(clock: Clock):
    """Within the block, INFO records of :data:`PROGRESS_LOGGER` are progress lines of ``clock`` (printed as
    the stage lines are, so ``--quiet`` drops them too) and nothing else."""
    logger = logging.getLogger(PROGRESS_LOGGER)
    handler = _ProgressHandler(clock)
    level, propagate = logger.level, logger.propagate
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)
        logger.propagate = propagate
