"""Campaigns on a Dask cluster: connecting to its scheduler, and batches whose worker died.

``run_campaign(..., scheduler=ADDRESS)`` sends its batches here
(:mod:`pushrecovery.campaign.execute`); docs/campaigns.md, "A push that crashes or hangs".
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.campaign.isolation import BatchRunner, PushRunner, check_batches
from pushrecovery.campaign.pushes import error_row, run_batch, run_push
from pushrecovery.campaign.spec import CampaignError, CampaignSpec
from pushrecovery.errors import ParameterTypeError, PushRecoveryError
from pushrecovery.extras import require

__all__ = ["CONNECT_TIMEOUT", "connect", "on_cluster"]

#: Seconds to wait for a Dask scheduler to answer.
CONNECT_TIMEOUT = 10.0


def connect(scheduler: str) -> Any:
    """Connect to the scheduler at ``scheduler`` (a client that is not made the default)."""
    require_type("scheduler", scheduler, str)
    require("campaign", "distributed", "a Dask scheduler")
    from distributed import Client
    from distributed.comm import parse_address

    malformed = CampaignError(
        f"--scheduler must be an address such as tcp://HOST:PORT, got {scheduler!r}"
    )
    try:
        scheme, location = parse_address(scheduler, strict=True)
    except ValueError:
        raise malformed from None
    # Dask accepts "tcp://" and then waits for the connect timeout: check host and port here.
    host, _, port = location.rpartition(":")
    if scheme in ("tcp", "tls", "ws", "wss") and not (
        host.strip("[]") and port.isdigit() and 0 < int(port) < 65536
    ):
        raise malformed
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise CampaignError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None


def on_cluster(
    spec: CampaignSpec,
    batches: list[int],
    client: Any,
    *,
    batch_runner: BatchRunner = run_batch,
    push_runner: PushRunner = run_push,
) -> Iterator[tuple[int, list[dict]]]:
    """Run ``batches`` on the cluster; a batch whose worker died goes on push by push.

    Dask itself gives a task whose worker died to another worker, up to its
    ``distributed.scheduler.allowed-failures``, then fails it with ``KilledWorker``. Such a
    batch is sent again one push per task: the push that kills its worker once more is an
    ``error`` row, every other push is simulated. ``batch_runner`` and ``push_runner`` are
    :func:`run_batch` and :func:`run_push` (replaceable for tests). The arguments are checked
    at the call (:func:`~pushrecovery.campaign.isolation.check_batches`).
    """
    batches = check_batches(spec, batches, batch_runner, push_runner)
    if not callable(getattr(client, "submit", None)):
        raise ParameterTypeError(f"client must be a dask.distributed Client, got {client!r:.40}")
    return _on_cluster(spec, batches, client, batch_runner, push_runner)


def _on_cluster(
    spec: CampaignSpec,
    batches: list[int],
    client: Any,
    batch_runner: BatchRunner,
    push_runner: PushRunner,
) -> Iterator[tuple[int, list[dict]]]:
    from distributed import as_completed

    # pure=False: every batch runs, even if an identical task ran before on the cluster.
    futures = {client.submit(batch_runner, spec, batch, pure=False): batch for batch in batches}
    try:
        for future in as_completed(list(futures), loop=client.loop):
            try:
                result = future.result()
            except Exception as exc:  # a lost worker's KilledWorker, a failed task
                if not _killed(exc):
                    raise _cluster_error(exc) from None
                result = _dask_pushes(spec, futures[future], client, push_runner)
            yield result
    finally:
        client.cancel(list(futures))


def _dask_pushes(
    spec: CampaignSpec, batch: int, client: Any, push_runner: PushRunner
) -> tuple[int, list[dict]]:
    """Batch ``batch`` one push per task; a push whose worker died is an ``error`` row.

    The pushes run in parallel first. A worker's death fails every task it held, so each push
    that failed then runs again alone: the one that kills its worker by itself is the error.
    """
    pushes = spec.pushes(batch)
    rows: list[dict | None] = list(_dask_rows(spec, pushes, client, push_runner))
    for k, push in enumerate(pushes):
        if rows[k] is None:
            (row,) = _dask_rows(spec, [push], client, push_runner)
            rows[k] = row or error_row(spec, push, "its worker process died")
    return batch, [row for row in rows if row is not None]


def _dask_rows(
    spec: CampaignSpec, pushes: list[Any], client: Any, push_runner: PushRunner
) -> list[dict | None]:
    """Rows of ``pushes`` run as one task each; None where the task's worker died."""
    futures = [client.submit(push_runner, spec, push, pure=False) for push in pushes]
    rows: list[dict | None] = []
    try:
        for future in futures:
            try:
                rows.append(future.result())
            except Exception as exc:
                if not _killed(exc):
                    raise _cluster_error(exc) from None
                rows.append(None)
    finally:
        client.cancel(futures)
    return rows


def _killed(exc: BaseException) -> bool:
    from distributed.scheduler import KilledWorker

    return isinstance(exc, KilledWorker)


def _cluster_error(exc: Exception) -> Exception:
    """Return the error to raise for a failed task: ours as it is, else a CampaignError."""
    if isinstance(exc, PushRecoveryError):
        return exc
    return CampaignError(
        f"a batch failed on the Dask cluster ({type(exc).__name__}: {exc}); the finished "
        "batches are saved, rerun with --resume"
    )
