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

A run's batches (:meth:`DaskCluster.start_on_demand`, as the runner opens
them) go to the cluster only where their rest repays its trips and the
connection: their first members are solved and timed in this process, and
condition (4) of :mod:`ngcontact.parallel.dask_payoff` decides, as
:mod:`ngcontact.parallel.worker_payoff` does for a local pool; the batch's
record says where it ran and why.  A run connects (imports dask.distributed,
most of a second, and makes a client) only once a batch's rest repays that
too: a run whose batches all stay here costs the serial run, its address
checked by a bare TCP connection (:meth:`DaskCluster._reach`; a plain TCP
address is also read without dask.distributed, :func:`tcp_host_port`).  A cluster used directly
(:func:`ngcontact.parallel.executor.use`) sends every member there.
"""
from __future__ import annotations

import functools
import logging
import re
import socket
import statistics
import time
from typing import Any, Sequence

from ngcontact.errors import NgcontactError
from ngcontact.parallel import dask_payoff
from ngcontact.parallel.batch_executor import Executor
from ngcontact.parallel.judged_batches import shifted_progress
from ngcontact.parallel.batch_member import in_worker, one_thread, reason, run_member, threads_asleep

log = logging.getLogger("ngcontact.parallel.executor")

#: Seconds a scheduler has to answer the first connection.
CONNECT_SECONDS = 5.0

#: The forms of a scheduler's address.
ADDRESS_FORMS = "tcp://HOST:PORT or HOST:PORT (also tls://, ws://, wss://, ucx:// HOST:PORT)"


#: A plain TCP address (``tcp://HOST:PORT`` or ``HOST:PORT``, the host a name, IPv4 or bracketed IPv6): read
#: here, without importing dask.distributed (most of a second: :func:`tcp_host_port`).
_TCP = re.compile(r"(?:tcp://)?(?P<host>[A-Za-z0-9][A-Za-z0-9.\-]*|\[[0-9A-Fa-f:.]+\]):(?P<port>[0-9]{1,5})")


def tcp_host_port(address: str) -> tuple[str, int] | None:
    """``(host, port)`` of a plain TCP ``address`` whose port is in 1..65535, None for any other form (which
    Dask's own parsing reads: :func:`address_problem`)."""
    match = _TCP.fullmatch(address) if isinstance(address, str) else None
    if match is None or not 1 <= int(match["port"]) <= 65535:
        return None
    return match["host"].strip("[]"), int(match["port"])


def address_problem(address: str) -> str | None:
    """What is wrong with the form of a scheduler's ``address`` (Dask's own parsing), None if nothing."""
    if not isinstance(address, str) or not address.strip():
        return "empty"
    if tcp_host_port(address) is not None:
        return None
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
        self._modules: tuple[str, ...] = ()   # what the workers import before a batch's members
        self.judged = False           # the run's batches: the rest of each goes to the cluster only where repaid
        self._part_wall = 1.0         # ``w`` of the last members sent (dask_payoff: a fresh cluster's part)

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

    def _reach(self) -> None:
        """Whether something answers at a plain TCP address (a bare TCP connection within
        :data:`CONNECT_SECONDS`: dask.distributed is not imported, as a batch kept in this process never
        needs it); for any other form, Dask's handshake (:meth:`_knock`)."""
        where = tcp_host_port(self.address)
        if where is None:
            import distributed  # noqa: F401 - the knock's import, named missing as the client's is
            self._knock()
            return
        try:
            socket.create_connection(where, timeout=CONNECT_SECONDS).close()
        except (ConnectionRefusedError, socket.timeout) as exc:        # nothing listens there: no detail
            raise self._unreachable(TimeoutError(str(exc))) from None
        except OSError as exc:                                           # a name that does not resolve, ...
            raise self._unreachable(exc) from None

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

    def start(self, modules: Sequence[str] = (), forecast=None) -> None:
        """Connect to the scheduler now (an address that does not answer fails before any solve); the run's
        batches then go to the cluster only where they repay it (:meth:`_judged_map`), the workers importing
        ``modules`` and the members' module first (a local pool's ``forecast`` is not a cluster's)."""
        self.client  # noqa: B018 - the property connects
        self.judged = True
        self._modules = tuple(dict.fromkeys(self._modules + tuple(modules)))

    def start_on_demand(self, modules: Sequence[str] = ()) -> None:
        """The run's batches go to the cluster only where they repay it (:meth:`_judged_map`), the workers
        importing ``modules`` and the members' module first; no connection is made before a batch whose rest
        repays it too (dask.distributed imported and a client connected in this process, ``K`` of
        :mod:`ngcontact.parallel.dask_payoff`), but an address where nothing answers fails now
        (:meth:`_reach`), before any solve."""
        if self._client is None:
            self._reach()
            self.workers = max(1, round(dask_payoff.cost_seconds(self.address, "workers", 1.0)))
        self.judged = True
        self._modules = tuple(dict.fromkeys(self._modules + tuple(modules)))

    def _map(self, fn, items, names, label, progress, fault) -> list:
        if not self.judged:
            self._where("dask", f"every member on the cluster's {self.workers} worker threads")
            return self._cluster_map(fn, items, names, label, progress, fault)
        if len(items) == 1:
            self._where("serial", "a single member: solved in this process")
            return Executor._map(self, fn, items, names, label, progress, fault)
        return self._judged_map(fn, items, names, label, progress, fault)

    def _judged_map(self, fn, items, names, label, progress, fault) -> list:
        """A batch of the run: members solved here, each timed, while the cluster's workers import the
        members' modules; then condition (4) of :mod:`ngcontact.parallel.dask_payoff`, with the trip timed on
        the cluster now, sends the rest there or keeps it here (the batch's record says which and why).  Its
        probe is cancelled however the batch ends (:meth:`~ngcontact.parallel.dask_payoff.Probe.cancel`): a
        batch kept here leaves no probe importing on the workers."""
        probes: list[dask_payoff.Probe] = []
        if self._client is not None:        # connected: the workers import while members are solved here
            probes.append(dask_payoff.Probe(self.client, label))
            probes[0].warm(self._modules + (fn.__module__,))
        try:
            return self._probed_map(probes, fn, items, names, label, progress, fault)
        finally:
            for probe in probes:
                probe.cancel()

    def _probed_map(self, probes, fn, items, names, label, progress, fault) -> list:
        clock = self.member_clock
        done: list = []
        while len(done) < len(items):
            k = len(done)
            done += Executor._map(self, fn, items[k:k + 1], names[k:k + 1], label,
                                  shifted_progress(progress, k, len(items)), fault)
            if len(done) < dask_payoff.MEASURED or len(done) == len(items):
                continue
            if not probes:      # not connected: the connection is part of what the rest must repay
                ahead = self._ahead(clock.least_wall, len(items) - len(done))
                if not ahead.repaid:
                    return self._here(fn, items, names, label, progress, fault, done, ahead.describe(len(done)))
                probes.append(self._connect(label, fn))
                probes[0].wait_warm(clock.least_wall)     # a warm cluster's imports: no member's time
            probe = probes[0]
            if not probe.warm_done():
                continue
            try:
                trip = probe.round_trip(items[len(done)], dask_payoff.result_bytes(done[-1]))
            except Exception as exc:   # a worker that cannot import the members' module, or a lost one
                why = (f"{len(done)} members solved here; the cluster's probe failed ({reason(exc)}): the other "
                       f"{len(items) - len(done)} in this process")
                probe.cancel()
                return self._here(fn, items, names, label, progress, fault, done, why)
            dask_payoff.remember_cost(self.address, "round_trip", trip)
            payoff = dask_payoff.connected(self.address, clock.least_wall, len(items) - len(done),
                                           len(probe.workers))
            probe.cancel()                 # done with: its results leave the workers
            why = payoff.describe(len(done))
            if payoff.repaid and not dask_payoff.wall_known(self.address) and payoff.rest > payoff.workers:
                part = payoff.workers      # no ``w`` yet: one member per worker measures it first
                done += self._cluster_map(fn, items[len(done):len(done) + part], names[len(done):len(done) + part],
                                          label, shifted_progress(progress, len(done), len(items)), fault,
                                          record=False)
                payoff = dask_payoff.connected(self.address, clock.least_wall, len(items) - len(done),
                                               payoff.workers, self._part_wall)
                why += (f"; the cluster having solved no member yet, the first {part} there measured a member's "
                        f"time on a worker; then {payoff.describe(len(done) - part)}")
            if not payoff.repaid:
                return self._here(fn, items, names, label, progress, fault, done, why)
            self._where("dask", why)
            log.debug("%s: %s", label, why)
            rest = self._cluster_map(fn, items[len(done):], names[len(done):], label,
                                     shifted_progress(progress, len(done)), fault)
            return done + rest
        importing = bool(probes) and not probes[0].warm_done()
        self._where("serial", f"all {len(done)} members solved here"
                    + (" while the cluster's workers imported their modules" if importing else ""))
        return done

    def _ahead(self, member_seconds: float, rest: int) -> dask_payoff.DaskPayoff:
        """Condition (4) before the connection: its cost ``K`` (the connection and the probe's two trips), the
        cluster's workers, trip and extra time as this scheduler's record has them
        (:mod:`ngcontact.parallel.dask_payoff`)."""
        known = dask_payoff.measured_costs(self.address, "workers")
        cost = functools.partial(dask_payoff.largest_cost, self.address)
        workers = max(1, round(statistics.median(known))) if known else rest
        return dask_payoff.DaskPayoff(member_seconds, rest, workers, cost("round_trip"),
                                      dask_payoff.member_extra(self.address, member_seconds),
                                      cost("connect", dask_payoff.CONNECT_ESTIMATE),
                                      workers_known=bool(known), probe=2.0 * cost("round_trip"))

    def _connect(self, label: str, fn) -> dask_payoff.Probe:
        """Connect now (``K`` timed and recorded, and the cluster's workers) and start the batch's probe."""
        t0 = time.perf_counter()
        client = self.client
        dask_payoff.remember_cost(self.address, "connect", time.perf_counter() - t0)
        probe = dask_payoff.Probe(client, label)
        dask_payoff.remember_cost(self.address, "workers", float(len(probe.workers)))
        probe.warm(self._modules + (fn.__module__,))
        return probe

    def _here(self, fn, items, names, label, progress, fault, done, why) -> list:
        """The rest of a batch in this process, ``why`` recorded with it."""
        self._where("serial", why)
        log.debug("%s: %s", label, why)
        return done + Executor._map(self, fn, items[len(done):], names[len(done):], label,
                                    shifted_progress(progress, len(done), len(items)), fault)

    def _cluster_map(self, fn, items, names, label, progress, fault, record: bool = True) -> list:
        from distributed import as_completed
        client = self.client
        results: dict[int, Any] = {}
        seconds: list[float] = []
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
                        results[k], s = fut.result()
                        seconds.append(s)
                        if progress is not None:
                            progress(label, len(results), len(items))
                        continue
                    exc = fut.exception()
                    self._failed(label, names[k], failures, k, exc)
                    futures.add(submit(k))
        except BaseException:
            client.cancel(list(index))
            raise
        wall = dask_payoff.member_wall(seconds, self.member_clock.least_wall)
        self._part_wall = 1.0 if wall is None else wall
        if wall is not None and record:  # ``w``: a member's wall time on a worker over the quickest here
            dask_payoff.remember_cost(self.address, "member_wall", wall)
        return [results[k] for k in range(len(items))]

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None


def _dask_member(fn, item, name, attempt, fault):
    """One member on a worker: its result and its wall seconds there (what the batch waits for, whatever
    share of the worker machine's cores it got: ``w`` of :mod:`ngcontact.parallel.dask_payoff`)."""
    if not in_worker():
        one_thread(ignore_sigint=False)
    wall = time.perf_counter()
    result = run_member(fn, item, name, attempt, fault)
    return result, time.perf_counter() - wall
