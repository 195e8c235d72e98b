"""The workers of a ``dask.distributed`` scheduler (:mod:`ngcontact.parallel.executor`): Dask is the cluster
engine, this module only submits."""
from __future__ import annotations

import time
from typing import Any, Sequence

from ngcontact.errors import NgcontactError
from ngcontact.parallel.batch_executor import Executor
from ngcontact.parallel.batch_member import in_worker, one_thread, reason, run_member


class DaskCluster(Executor):
    """The workers of the ``dask.distributed`` scheduler at ``address`` (e.g. ``tcp://10.0.0.5:8786``)."""

    name = "dask"

    def __init__(self, address: str):
        self.address = address
        self._client: Any = None      # the distributed Client, connected on first use

    @property
    def client(self):
        """The connection to the scheduler, made on first use."""
        if self._client is None:
            try:
                from distributed import Client
            except ImportError as exc:  # pragma: no cover - a dependency of the package
                raise NgcontactError(f"scheduler {self.address!r}: dask.distributed is not installed") from exc
            try:
                self._client = Client(self.address, timeout=30, set_as_default=False)
            except Exception as exc:
                raise NgcontactError(f"scheduler {self.address!r}: cannot connect ({reason(exc)})") from exc
            info = self._client.scheduler_info()["workers"].values()
            self.workers = max(1, sum(w.get("nthreads", 1) for w in info))
        return self._client

    def start(self, modules: Sequence[str] = ()) -> None:
        """Connect to the scheduler now: an address that does not answer fails before any solve."""
        self.client  # noqa: B018 - the property connects

    def _map(self, fn, items, names, label, progress, fault) -> list:
        from distributed import as_completed
        client = self.client
        results: dict[int, Any] = {}
        failures = {k: 0 for k in range(len(items))}
        index: dict[Any, int] = {}

        def submit(k):
            fut = client.submit(_dask_member, fn, items[k], names[k], failures[k], fault, pure=False,
                                key=f"ngcontact-{label}-{names[k]}-{failures[k]}-{time.time_ns()}")
            index[fut] = k
            return fut

        futures = as_completed([submit(k) for k in range(len(items))], loop=client.loop)
        try:
            for fut in futures:
                k = index.pop(fut)
                if fut.status == "finished":
                    results[k] = fut.result()
                    if progress is not None:
                        progress(label, len(results), len(items))
                    continue
                exc = fut.exception()
                self._failed(label, names[k], failures, k, exc)
                futures.add(submit(k))
        except BaseException:
            client.cancel(list(index))
            raise
        return [results[k] for k in range(len(items))]

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None


def _dask_member(fn, item, name, attempt, fault):
    if not in_worker():
        one_thread(ignore_sigint=False)
    return run_member(fn, item, name, attempt, fault)
