"""Progress of a batch of independent solves: one bar on a terminal, plain lines elsewhere.

Called as ``progress(label, finished, total)`` by
:mod:`ngcontact.parallel.executor` (``finished = 0`` when a batch starts).
On a terminal a ``tqdm`` bar shows the finished count and the estimated
time left; in a log file or a pipe a plain line per finished member says
the same (``loads: 3/16 finished, about 12 s left``).  ``quiet`` silences it.
"""
from __future__ import annotations

import sys
import time
from typing import IO


class BatchProgress:
    """``progress(label, finished, total)`` for the batches of one run."""

    def __init__(self, quiet: bool = False, stream: IO[str] | None = None):
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self._bar = None
        self._start = 0.0

    @property
    def terminal(self) -> bool:
        isatty = getattr(self.stream, "isatty", None)
        return bool(isatty and isatty())

    def __call__(self, label: str, finished: int, total: int) -> None:
        if self.quiet:
            return
        if finished == 0:
            self._begin(label, total)
            return
        if self._bar is not None:
            self._bar.update(finished - self._bar.n)
            if finished >= total:
                self._bar.close()
                self._bar = None
            return
        elapsed = time.perf_counter() - self._start
        left = elapsed / finished * (total - finished)
        print(f"{label}: {finished}/{total} finished, about {left:.0f} s left", file=self.stream, flush=True)

    def _begin(self, label: str, total: int) -> None:
        self.close()
        self._start = time.perf_counter()
        if self.terminal:
            from tqdm import tqdm
            self._bar = tqdm(total=total, desc=label, unit="solve", file=self.stream, dynamic_ncols=True,
                             bar_format="{desc}: {n_fmt}/{total_fmt} |{bar}| {elapsed}<{remaining}")
        else:
            print(f"{label}: {total} independent solves", file=self.stream, flush=True)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
