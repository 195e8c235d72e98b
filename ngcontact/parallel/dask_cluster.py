"""The workers of a ``dask.distributed`` scheduler (:mod:`ngcontact.parallel.executor`): Dask is the cluster
engine, this module only submits.

The scheduler's address is checked as the executor is made, by Dask's own
parsing (:func:`address_problem`): a malformed one is refused before any
connection.  The connection, on first use, gets :data:`CONNECT_SECONDS`:
a first knock (a bare connection and Dask's handshake, no client) tells
whether a scheduler answers there, so that a client is made only for a
scheduler that does (a client whose connection fails half-way tries to
close itself again as the interpreter ends, and waits a minute there).
Both failures are :class:`SchedulerError`: an input to correct, or a
scheduler to start, before any solve (the runner names the address's key).
"""
from __future__ import annotations

import logging
import time
from typing import Any, Sequence

from ngcontact.errors import NgcontactError
from ngcontact.parallel.batch_executor import Executor
from ngcontact.parallel.batch_member import in_worker, one_thread, reason, run_member, threads_asleep

log = logging.getLogger("ngcontact.parallel.executor")

#: Seconds a scheduler has to answer the first connection.
CONNECT_SECONDS = 5.0

#: The forms of a scheduler's address.
ADDRESS_FORMS = "tcp://HOST:PORT or HOST:PORT (also tls://, ws://, wss://, ucx:// HOST:PORT)"


def address_problem(address: str) -> str | None:
    """What is wrong with the form of a scheduler's ``address`` (Dask's own parsing), None if nothing."""
    if not isinstance(address, str) or not address.strip():
        return "empty"
    try:
        from distributed.comm.addressing import parse_address, parse_host_port
        from distributed.comm.registry import backends
    except ImportError:  # pragma: no cover - a dependency of the package; the connection names it missing
        return None
    try:
        scheme, location = parse_address(address, strict=False)
    except ValueError as exc:
        return str(exc)
    if scheme not in backends or scheme == "inproc":       # inproc: this process only, no workers elsewhere
        return f"unknown scheme {scheme!r}"
    try:
        host, port = parse_host_port(location)
    except ValueError as exc:
        return "missing port number" if "missing port" in str(exc) else f"invalid port in {location!r}"
    if not host:
        return "no host"
    if not 1 <= port <= 65535:
        return f"port {port} is not in 1..65535"
    return None


class SchedulerError(NgcontactError):
    """A scheduler address that is malformed, or where no scheduler answers: ``address``, and ``allowed``,
    what is wrong and what to do."""

    def __init__(self, address: str, allowed: str):
        self.address = address
        self.allowed = allowed
        super().__init__(f"scheduler {address!r}: {allowed}")


def check_address(address: str) -> None:
    """Refuse a malformed scheduler ``address`` (:class:`SchedulerError`)."""
    problem = address_problem(address)
    if problem is not None:
        raise SchedulerError(address, f"{problem}; the address of a dask.distributed scheduler: {ADDRESS_FORMS}")


class DaskCluster(Executor):
    """The workers of the ``dask.distributed`` scheduler at ``address`` (e.g. ``tcp://10.0.0.5:8786``)."""

    name = "dask"

    def __init__(self, address: str):
        check_address(address)
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
            self._knock()
            try:
                self._client = Client(self.address, timeout=CONNECT_SECONDS, set_as_default=False)
            except Exception as exc:   # gone since it answered the knock
                raise self._unreachable(exc) from None
            info = self._client.scheduler_info()["workers"].values()
            self.workers = max(1, sum(w.get("nthreads", 1) for w in info))
        return self._client

    def _knock(self) -> None:
        """Whether a scheduler answers at the address within :data:`CONNECT_SECONDS`: a bare connection and
        Dask's handshake, on an event loop of its own (in a thread: the caller's may run one already)."""
        import asyncio
        from concurrent.futures import ThreadPoolExecutor
        from distributed.comm import connect
        from distributed.security import Security

        async def knock():
            comm = await connect(self.address, timeout=CONNECT_SECONDS,
                                 **Security().get_connection_args("client"))
            await comm.close()

        async def bounded():      # the handshake's read has no deadline of its own (another server there)
            await asyncio.wait_for(knock(), CONNECT_SECONDS)

        try:
            with ThreadPoolExecutor(1, thread_name_prefix="ngcontact-knock") as pool:
                pool.submit(asyncio.run, bounded()).result()
        except Exception as exc:
            raise self._unreachable(exc) from None

    def _unreachable(self, exc: BaseException) -> SchedulerError:
        log.debug("scheduler %s: %s", self.address, reason(exc))
        timeout = isinstance(exc, TimeoutError) or "Timed out" in str(exc)      # asyncio's is the builtin
        detail = "" if timeout else f" ({reason(exc)})"
        return SchedulerError(self.address, f"no dask.distributed scheduler answered there within "
                              f"{CONNECT_SECONDS:g} s{detail}: start one there (dask scheduler) or correct "
                              "the address")

    def start(self, modules: Sequence[str] = ()) -> None:
        """Connect to the scheduler now: an address that does not answer fails before any solve."""
        self.client  # noqa: B018 - the property connects

    def start_on_demand(self, modules: Sequence[str] = ()) -> None:
        """Connect now too: the cluster's workers run already, and a wrong address fails before any solve."""
        self.start(modules)

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
            with threads_asleep():          # this process only waits: its NGSolve threads leave the cores
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
