"""Detection and evaluation of a BOP dataset spread over the workers of a Dask cluster.

::

    from dask.distributed import Client, LocalCluster
    import vkpose.distributed

    client = Client(LocalCluster(n_workers=2, threads_per_worker=1))   # or Client("tcp://host:8786")
    report = vkpose.distributed.evaluate(client, "lmo", {5: "can.vkpb"}, methods=["vkpose"])

The frames go to the workers in batches. Each worker process builds the run's estimators once
(it reads the bank files itself, so every worker must see them and the dataset at the same
paths, e.g. on a shared folder) and keeps them for every batch it is given; on a machine with
several GPUs each worker takes one (VKPOSE_DEVICE set for a worker wins). A worker that dies
mid-run loses nothing: Dask gives its batches to another. An image that cannot be read is
skipped and named in the report; the run goes on. The results are those of one process: the
same BOP CSV and report, times aside.

`vkpose eval --workers N` (a cluster on this machine) and `vkpose eval --dask ADDRESS` run this
module (`python3 -m vkpose.distributed`).
"""

import argparse
import math
import os
import sys
import zlib

from . import _ProgressBar, _vkpose

__all__ = ["detect_dataset", "evaluate", "run_job"]


def _distributed():
    try:
        import distributed
    except ImportError:
        raise ImportError(
            "vkpose.distributed needs Dask's distributed scheduler for this Python (%s): on Debian "
            "apt-get install python3-distributed (scripts/install-deps.sh installs it)" % sys.executable
        ) from None
    return distributed


# ---- on the workers ------------------------------------------------------------------------

_EVALUATORS = {}  # job text -> _vkpose._Evaluator: one per job and worker process


def _worker_device():
    """None (the default choice) unless the machine has several GPUs: then the worker's own one."""
    if os.environ.get("VKPOSE_DEVICE"):
        return None
    gpus = [d.index for d in _vkpose.devices() if d.usable and d.type in ("discrete", "integrated")]
    if len(gpus) <= 1:
        return None
    try:
        name = _distributed().get_worker().name
    except ValueError:  # not on a worker
        return None
    number = name if isinstance(name, int) else zlib.crc32(str(name).encode())
    return gpus[number % len(gpus)]


def _run_batch(job, first, count):
    """Images [first, first + count) of a job on this worker: their report, as text."""
    evaluator = _EVALUATORS.get(job)
    if evaluator is None:
        evaluator = _EVALUATORS[job] = _vkpose._Evaluator(job, device=_worker_device())
    return evaluator.run(first, count)


# ---- on the client -------------------------------------------------------------------------


def _progress_of(progress):
    if progress is True:
        return _ProgressBar("evaluating")
    return progress or None


def run_job(client, job, batch=None, progress=None):
    """Runs a job (the text `vkpose eval --workers` writes, or _vkpose._eval_job's) on the client's
    workers and returns the run's report as text (_vkpose._finish_report writes its files).

    batch: images per task (default: about four tasks per worker, at most 8 images each).
    progress: callable(done, total) in images, or True for a bar on stderr."""
    distributed = _distributed()
    first, end = _vkpose._job_images(job)
    total = end - first
    if batch is None:
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        batch = max(1, min(8, math.ceil(total / (4 * workers))))
    if batch < 1:
        raise ValueError("batch: %d is not a positive number of images" % batch)
    progress = _progress_of(progress)
    starts = list(range(first, end, batch))
    futures = {}
    for start in starts:
        count = min(batch, end - start)
        futures[client.submit(_run_batch, job, start, count, pure=False)] = (start, count)
    parts = {}
    done = 0
    try:
        for future in distributed.as_completed(list(futures)):
            start, count = futures[future]
            parts[start] = future.result()
            done += count
            if progress:
                progress(done, total)
    finally:
        for future in futures:
            future.cancel()
    return _vkpose._merge_reports([parts[s] for s in starts])


def evaluate(client, dataset, banks, *, methods=("vkpose", "linemod", "ppf"), split="test", config=None, images=0,
             k_m=0.15, min_visib=0.0, out=None, report=None, pr_curve=None, overwrite=False, batch=None,
             progress=None):
    """vkpose.evaluate() with the frames spread over a dask.distributed Client's workers: the same
    arguments (banks as files: {obj_id: path}), files and returned report, times aside."""
    job = _vkpose._eval_job(dataset, dict(banks), methods=list(methods), split=split, config=config, images=images,
                            k_m=k_m, min_visib=min_visib, out=out, report=report, pr_curve=pr_curve,
                            overwrite=overwrite)
    state = run_job(client, job, batch=batch, progress=progress)
    return _vkpose._finish_report(state, out=out, report=report, pr_curve=pr_curve)


def detect_dataset(client, banks, dataset, *, split="test", config=None, images=0, out=None, overwrite=False,
                   batch=None, progress=None):
    """vkpose's detections on every image of a BOP dataset's split, spread over the Client's workers:
    rows as read_bop_results gives them (scene_id, im_id, obj_id, score, R, t, time), in image order;
    out: also write them as a BOP results CSV (vkpose_ put before its file name, as evaluate does).
    The detections are scored against the dataset's ground truth on the way (evaluate() returns
    those scores)."""
    result = evaluate(client, dataset, banks, methods=["vkpose"], split=split, config=config, images=images,
                      out=out, overwrite=overwrite, batch=batch, progress=progress)
    return result["results"]["vkpose"]


# ---- `python3 -m vkpose.distributed`: what `vkpose eval --workers/--dask` runs ----------------


def _client(distributed, args):
    if args.scheduler:
        return distributed.Client(args.scheduler, timeout=args.connect_timeout), None
    import logging

    cluster = distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
    return distributed.Client(cluster), cluster


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m vkpose.distributed",
                                     description="Runs a vkpose evaluation job on Dask workers (vkpose eval --workers)")
    parser.add_argument("--job", required=True, help="the job file vkpose eval wrote")
    parser.add_argument("--result", required=True, help="where the run's report (as text) goes")
    parser.add_argument("--error", help="where a failure's message goes (else stderr)")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--workers", type=int, help="worker processes of a cluster on this machine")
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    parser.add_argument("--batch", type=int, default=None, help="images per task (default: about 4 tasks a worker)")
    parser.add_argument("--connect-timeout", default="30s", help="how long to wait for the scheduler")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    try:
        distributed = _distributed()
        with open(args.job) as f:
            job = f.read()
        client, cluster = _client(distributed, args)
        try:
            state = run_job(client, job, batch=args.batch, progress=None if args.quiet else _ProgressBar("evaluating"))
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        with open(args.result, "w") as f:
            f.write(state)
        return 0
    except (Exception, KeyboardInterrupt) as error:  # the CLI prints it as its own error
        message = str(error) or type(error).__name__
        if isinstance(error, OSError) and "scheduler" not in message and args.scheduler:
            message = "cannot reach the Dask scheduler at %s: %s" % (args.scheduler, message)
        if args.error:
            with open(args.error, "w") as f:
                f.write(message)
        else:
            print("vkpose: error: %s" % message, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
