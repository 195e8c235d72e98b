"""Imported last by a pool's fork server (:mod:`ngcontact.parallel.fork_server`): its imports are done.

In the server (its environment names a record in
:data:`~ngcontact.parallel.fork_server.READY_ENV`, which this removes so
that no worker sees it): the server asks for the kernel's death signal when
the run's thread that started it ends (where that was the run's main
thread, whose end is the run's), ends at once if the run is gone already,
and enters itself in its record (``worker PID START``): the run reads there
that the server is ready, and a later pool's orphan guard finds it there.
No thread is started: the server forks its workers.  Imported anywhere
else, it does nothing.
"""
from __future__ import annotations

import os

from ngcontact.parallel import worker_lifetime
from ngcontact.parallel.fork_server import READY_ENV


def enter_server() -> bool:
    """The steps above, where this process is a fork server being started; whether it is one."""
    value = os.environ.pop(READY_ENV, None)
    if value is None:
        return False
    record, main, run = value.rsplit(":", 2)
    if main == "1":
        worker_lifetime.death_signal()
    if os.getppid() != int(run):
        os._exit(1)
    worker_lifetime.enter(record or None)
    return True


enter_server()
