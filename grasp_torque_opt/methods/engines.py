# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Batch scoring over engines: this process, a pool of processes, or a Dask cluster.

:func:`score_batch` cuts the candidate lines (:mod:`.score`'s format) into chunks and
scores each chunk in a worker with the job's
:class:`~grasp_torque_opt.methods.batch.BatchScorer` (the batch stages, the single path
for the rest), bound once per process.

Parallel over processes (``engine="processes"``, the default, a
:class:`concurrent.futures.ProcessPoolExecutor` of ``workers`` spawned processes:
a worker that dies raises :class:`BrokenProcessPool`, never a hang) or over a Dask
distributed cluster (``engine="dask"``: a scheduler address, or a local cluster),
with the same chunk function; each worker binds the base scenario once, reuses one
solver and runs BLAS on one thread.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
import os
from pathlib import Path
from typing import Any

from grasp_torque_opt.backends import single_threaded_math
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.methods.batch import BatchScorer
from grasp_torque_opt.methods.ranking import rank_key, ranked_records
from grasp_torque_opt.methods.score import ScoreJob, Scorer

#: Engines: this process, a multiprocessing pool, or a Dask distributed cluster.
ENGINES = ('serial', 'processes', 'dask')
#: Candidates per task sent to a worker (the batch stages run over a task at once).
CHUNK = 256


_SCORERS: dict[str, Any] = {}


def batch_scorer(job: ScoreJob):
    """Return this process's :class:`~.batch.BatchScorer` of the job, bound on first use."""
    scorer = _SCORERS.get(job.key)
    if scorer is None:
        single_threaded_math()
        scorer = _SCORERS[job.key] = BatchScorer(Scorer(job))
    return scorer


def score_chunk(job: ScoreJob, chunk: Sequence[tuple[int, Any]]) -> list[dict[str, Any]]:
    """
    Score a chunk in this process, binding the job's hand on first use (any engine's task).

    The batch stages (:mod:`.batch`) score what they take, the single path the rest.
    """
    return batch_scorer(job).score_lines(chunk)


def read_candidates(path: str | Path) -> list[tuple[int, str]]:
    """
    (line number, text) of every non-blank line of a JSON Lines file (1-based).

    Raises:
        InputError: the file cannot be read (field ``candidates``).
    """
    path = Path(path)
    try:
        with path.open(encoding='utf-8', errors='replace') as fh:
            return [(i, line) for i, line in enumerate(fh, 1) if line.strip()]
    except OSError as e:
        raise InputError('candidates', f'cannot read {path}: {e.strerror}') from e


def numbered(candidates: Iterable[Any]) -> list[tuple[int, Any]]:
    """
    Return (line number, candidate) pairs.

    (line number, text) pairs are kept; a mapping or a :class:`GraspSetup` is
    numbered by its position, from 1.
    """
    out = []
    for i, c in enumerate(candidates, 1):
        if isinstance(c, tuple) and len(c) == 2 and isinstance(c[0], int):
            out.append(c)
        else:
            out.append((i, c))
    return out


def chunks(lines: Sequence[tuple[int, Any]], size: int = CHUNK) -> list[list[tuple[int, Any]]]:
    """Cut the lines into tasks of ``size``."""
    return [list(lines[i:i + size]) for i in range(0, len(lines), size)]


#: Thread variables set to 1 in spawned workers (two workers with a multi-threaded
#: BLAS each oversubscribe two cores).
THREAD_VARS = ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS')


@contextmanager
def thread_env(value: str | None) -> Iterator[None]:
    """
    Set every :data:`THREAD_VARS` to ``value`` in this process's environment, then restore.

    Spawned workers read these at import, so a pool is created inside the block;
    ``value`` None changes nothing (the library's default thread count).
    """
    saved = {k: os.environ.get(k) for k in THREAD_VARS}
    if value is not None:
        os.environ.update(dict.fromkeys(THREAD_VARS, value))
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def score_batch(job: ScoreJob, lines: Iterable[Any], *, workers: int | None = None,
                engine: str = 'processes', scheduler: str | None = None,
                progress: Callable[[int, int], None] | None = None,
                chunk: int = CHUNK, rank_by: str = 'capacity') -> list[dict[str, Any]]:
    """
    Score every candidate line, in parallel; records in input order, each with its rank.

    Args:
        job: the base scenario and options.
        lines: the candidates: (line number, text) pairs (:func:`read_candidates`),
            or in memory mappings (partial scenarios, as a line's JSON object) or
            :class:`GraspSetup` objects of the base hand, numbered from 1.
        workers: processes (``processes``; a local Dask cluster's workers); default
            the machine's cores.
        engine: one of :data:`ENGINES`.
        scheduler: a Dask scheduler address (``tcp://host:8786``); None starts a
            local cluster (``dask`` only).
        progress: called with (candidates done, total) as chunks finish.
        chunk: candidates per task.
        rank_by: the key of each record's ``rank`` (:func:`.ranking.rank`).

    Raises:
        InputError: the base scenario is bad (the batch cannot start).
        ValueError: an unknown engine or rank key.
        BrokenProcessPool: a worker process died (``processes``); the message says
            why it may have (a script without ``if __name__ == "__main__":``).
    """
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    rank_key([], rank_by)  # an unknown key fails before the work
    Scorer(job)  # a bad base scenario fails here, once, in this process
    workers = max(1, workers or os.cpu_count() or 1)
    lines = numbered(lines)
    tasks = chunks(lines, chunk)
    total = len(lines)
    results: list[list[dict] | None] = [None] * len(tasks)
    done = 0

    def finished(i: int, records: list[dict]) -> None:
        nonlocal done
        results[i] = records
        done += len(records)
        if progress is not None:
            progress(done, total)

    if engine == 'serial' or (engine == 'processes' and (workers == 1 or len(tasks) <= 1)):
        for i, t in enumerate(tasks):
            finished(i, score_chunk(job, t))
    elif engine == 'processes':
        _pool_map(job, tasks, workers, finished)
    else:
        _dask_map(job, tasks, workers, scheduler, finished)
    records = [r for records in results for r in records]
    ranked_records(records, rank_by)
    return records


def _pool_map(job: ScoreJob, tasks: list, workers: int, finished) -> None:
    from concurrent.futures import as_completed, ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool
    import multiprocessing as mp

    ctx = mp.get_context('spawn')  # fork after Pinocchio and BLAS threads is not safe
    # The pool starts its processes as tasks arrive: the thread variables stay set
    # until every task is submitted, and each worker limits BLAS itself as well.
    with thread_env('1'), ProcessPoolExecutor(min(workers, len(tasks)), mp_context=ctx,
                                              initializer=single_threaded_math) as pool:
        futures = {pool.submit(score_chunk, job, t): i for i, t in enumerate(tasks)}
        try:
            for fut in as_completed(futures):
                finished(futures[fut], fut.result())
        except BrokenProcessPool as e:
            for fut in futures:
                fut.cancel()
            raise BrokenProcessPool(
                f'{e} A scoring worker died: its error is on stderr above. Run from a '
                'script, score_batch must be called under `if __name__ == "__main__":` '
                '(each spawned worker imports the script); else the worker ran out of '
                'memory or was killed.') from e


def _dask_map(job: ScoreJob, tasks: list, workers: int, scheduler: str | None,
              finished) -> None:
    try:
        from dask.distributed import as_completed, Client, LocalCluster
    except ImportError as e:
        raise InputError('engine', "dask needs the optional extra 'distributed' "
                         "(pip install 'grasp_torque_opt[distributed]')") from e
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None,
                               env=dict.fromkeys(THREAD_VARS, '1'))
    try:
        with Client(scheduler or cluster) as client:
            job_ref = client.scatter(job, broadcast=True)
            futures = [client.submit(score_chunk, job_ref, t, pure=False) for t in tasks]
            index = {f.key: i for i, f in enumerate(futures)}
            for fut in as_completed(futures):
                finished(index[fut.key], fut.result())
    finally:
        if cluster is not None:
            cluster.close()
