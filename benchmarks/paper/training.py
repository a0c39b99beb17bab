"""Training: every run's policies, each model folder once, in worker processes; each run
judged as soon as its policies are trained."""

from __future__ import annotations

import os
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path

from benchmarks.paper.evaluation import evaluate_run, has_evaluation
from benchmarks.paper.experiments import Options
from benchmarks.paper.runs import Run
from pianobot.agent import store
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.learn.jobs import PhraseJob


def train_job(job: PhraseJob, config: TrainConfig, label: str = "", stop_after: int | None = None) -> dict:
    """Train one policy (resuming its checkpoint), one torch thread. ``stop_after`` interrupts
    it as a kill would (tests). Returns its state: 'trained', 'interrupted' or 'busy'."""
    import torch

    from pianobot.learn.train import train_policy

    torch.set_num_threads(1)
    if store.is_trained(job.folder):
        return {"state": "trained", "folder": str(job.folder)}
    state = store.checkpoint_state(job.folder)
    if stop_after is not None and state is not None and state["step"] >= stop_after:
        print(f"{label}: at {state['step']} steps, already past --stop-at {stop_after}", flush=True)
        return {"state": "interrupted", "folder": str(job.folder)}

    def report(progress) -> None:
        if progress.resumed:
            print(f"{label}: resuming from its checkpoint at step {progress.step}", flush=True)
        elif progress.finished:
            print(f"{label}: trained, {progress.step} steps", flush=True)

    try:
        out = train_policy(job.target, config, job.folder, report, stop_after=stop_after, about=job.about())
    except PianobotError as e:  # another process trains the same folder (a run two experiments share)
        print(f"{label}: {e}", flush=True)
        return {"state": "busy", "folder": str(job.folder)}
    if "interrupted_at" in out:
        print(f"{label}: stopped at step {out['interrupted_at']} (--stop-at; rerun without it to go on)", flush=True)
        return {"state": "interrupted", "folder": str(job.folder)}
    return {"state": "trained", "folder": str(job.folder)}


def trained(run: Run) -> bool:
    return all(store.is_trained(job.folder) for job in run.jobs)


def execute(runs: list[Run], options: Options, workers: int) -> None:
    """Train every run's policies (each folder once), ``workers`` at a time, longest first, and
    evaluate each run as soon as its policies are all trained."""
    jobs: dict[Path, tuple[PhraseJob, TrainConfig, str]] = {}
    for run in runs:
        for job in run.jobs:
            jobs.setdefault(job.folder, (job, run.config, f"{run.label} [{job.key[:16]}]"))
    todo = sorted((j for j in jobs.values() if not store.is_trained(j[0].folder)), key=lambda j: -j[1].steps)
    ready = [run for run in runs if trained(run) and not has_evaluation(run, options)]
    print(f"{len(runs)} runs, {len(jobs)} policies: {len(todo)} to train, {len(ready)} runs to evaluate", flush=True)
    if workers <= 1:
        for job, config, label in todo:
            train_job(job, config, label, options.stop_at)
        for run in runs:
            if trained(run) and not has_evaluation(run, options):
                _print_evaluation(run, evaluate_run(run, options))
        return
    import multiprocessing

    from pianobot.learn.jobs import _exit_with_parent  # workers end with this process

    evaluated: set[Path] = set()
    failed: list[str] = []
    with ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_exit_with_parent,
        initargs=(os.getpid(),),
    ) as pool:
        pending = {pool.submit(train_job, job, config, label, options.stop_at): label for job, config, label in todo}

        def submit_evaluations() -> None:
            for run in runs:
                if run.result not in evaluated and trained(run) and not has_evaluation(run, options):
                    evaluated.add(run.result)
                    pending[pool.submit(evaluate_run, run, options)] = run

        submit_evaluations()
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                what = pending.pop(future)
                try:
                    result = future.result()
                except Exception as e:  # the other runs go on; this one is named at the end
                    label = what.label if isinstance(what, Run) else what
                    print(f"{label}: failed: {type(e).__name__}: {e}", flush=True)
                    failed.append(label)
                    continue
                if isinstance(what, Run):
                    _print_evaluation(what, result)
            submit_evaluations()
    if failed:
        raise SystemExit(f"{len(failed)} failed (rerun the same command to retry): {'; '.join(failed)}")


def _print_evaluation(run: Run, figures: dict) -> None:
    print(
        f"{run.label}: linear return {figures['return']:.2f}, note F1 {figures['f1']:.3f} "
        f"({figures['episodes']} episodes)",
        flush=True,
    )
