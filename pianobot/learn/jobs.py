"""Training a whole piece: one job per distinct phrase (or one for a task family), run one after
another or in parallel worker processes, each skipped when its policy is already stored; every
phrase begins from the general policy when there is one (:func:`general_start`)."""

from __future__ import annotations

import os
import threading
import time
import warnings
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import torch

from pianobot.agent import store
from pianobot.agent.general import NETWORK_FIELDS, find_general
from pianobot.agent.policy import policy_configs
from pianobot.agent.tasks import GivenParts, Target
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError, PianobotWarning, SettingError, quote
from pianobot.learn import forced
from pianobot.learn.dagger import dagger_policy
from pianobot.learn.train import Progress, TrainConfig, train_policy
from pianobot.music.instrument import check_playable
from pianobot.music.load import LoadOptions
from pianobot.music.phrases import Phrase
from pianobot.music.tasks import GIVEN_SHARE, PARTS, VERSIONS
from pianobot.pianist.parts import prepare_part
from pianobot.pianist.reading import two_hands


@dataclass
class PhraseJob:
    """One policy to train: a phrase (by content hash) or a task family, and the phrases that use it."""

    key: str
    target: Target
    folder: Path
    phrases: list[int]
    piece: str = ""
    given: dict = field(default_factory=dict)
    """Where a task family's given parts came from (:class:`~pianobot.agent.tasks.GivenParts`'s ``about``)."""

    def about(self) -> dict:
        return {"key": self.key, "piece": self.piece, "phrases": self.phrases} | (
            {"given": self.given} if self.given else {}
        )


def _exit_with_parent(parent: int, stop=None, every: float = 0.5) -> None:
    """Worker initializer: end this process when the process that started it is gone, or sets ``stop``
    (an event of its multiprocessing context).

    Ctrl-C reaches every process in the terminal's group, but a parent killed on its own
    (``kill PID``, a closed session) would leave its workers training on unseen. Checkpoints
    are written atomically, so ending a worker at any moment loses at most the steps since its
    last checkpoint, which the same command trains again."""

    def watch() -> None:
        while os.getppid() == parent and not (stop is not None and stop.is_set()):
            time.sleep(every)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="exit-with-parent").start()


_PROGRESS = None
"""In a worker process of :func:`worker_pool`: the queue its runs report their progress on."""


def _start_worker(parent: int, queue, stop) -> None:
    global _PROGRESS
    _PROGRESS = queue
    _exit_with_parent(parent, stop)


@contextmanager
def worker_pool(workers: int, context, queue) -> Iterator[ProcessPoolExecutor]:
    """``workers`` processes of ``context`` that end with this one (:func:`_exit_with_parent`) and report
    progress on ``queue``, a queue of the same context: no manager process, so a parent killed outright
    leaves nothing running behind it. An exception that leaves the block (Ctrl-C, or SIGTERM, which
    reaches this process alone) ends the workers at once, rather than waiting for their runs to finish."""
    stop = context.Event()
    initargs = (os.getpid(), queue, stop)
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_start_worker, initargs=initargs) as pool:
        try:
            yield pool
        except BaseException:
            stop.set()
            raise


def learner(config: TrainConfig) -> Callable[..., dict]:
    """The training loop of ``config.learner``: :func:`~pianobot.learn.train.train_policy` (SAC)
    or :func:`~pianobot.learn.dagger.dagger_policy`; both take the same arguments."""
    return dagger_policy if config.learner == "dagger" else train_policy


def _run_job(
    job: PhraseJob, config: TrainConfig, queue=None, threads: int | None = None, start: Path | None = None
) -> dict:
    if threads is not None:
        torch.set_num_threads(threads)

    queue = queue if queue is not None else _PROGRESS

    def report(progress: Progress) -> None:
        if queue is not None:
            queue.put((job.key, progress))

    return learner(config)(job.target, config, job.folder, report, about=job.about(), start=start)


def general_start(
    config: TrainConfig, models: Path, path: Path | None = None, networks_given: bool = False
) -> tuple[TrainConfig, Path | None]:
    """Where a piece's phrases begin: (``config``, the general policy's folder) when
    ``config.from_general`` asks for it and there is one (``path``, else the newest ``task-melody`` or ``task-parts``
    policy in ``models`` whose environment is the run's); else (``config`` with ``from_general``
    off, None): from scratch. A run that starts from a policy takes its networks
    (:data:`~pianobot.agent.general.NETWORK_FIELDS`), unless ``networks_given`` (an option set them):
    then they must be the policy's. A general policy that does not fit is a one-line error naming
    the option that differs."""
    if not config.from_general:
        return config, None
    folder = find_general(
        models,
        config.env,
        config.sac if networks_given else None,
        path,
        ours="this run",
        remedy="give the same option to start from it, or --no-from-general to train from scratch",
    )
    if folder is None:
        return replace(config, from_general=False), None
    _, theirs = policy_configs(folder)
    networks = {name: getattr(theirs, name) for name in NETWORK_FIELDS}
    return replace(config, sac=replace(config.sac, **networks)), folder


def phrase_jobs(phrases: list[Phrase], config: TrainConfig, root: Path, piece: str = "") -> list[PhraseJob]:
    """One job per distinct phrase (identical phrases share one policy)."""
    by_hash: dict[str, PhraseJob] = {}
    for phrase in phrases:
        if phrase.hash in by_hash:
            by_hash[phrase.hash].phrases.append(phrase.index)
        else:
            folder = store.model_dir(root, phrase.hash, config)
            by_hash[phrase.hash] = PhraseJob(phrase.hash, phrase.piece(), folder, [phrase.index], piece)
    return list(by_hash.values())


def task_job(task: str, config: TrainConfig, root: Path, given: GivenParts | None = None) -> PhraseJob:
    """The one job of a task family; ``given``: the ``parts`` family with these parts given, in
    folders of their own (``task-parts-v3-pieces-<digest of the parts>-<config hash>``)."""
    key = store.task_key(task, VERSIONS.get(task, 1))
    if given is None:
        return PhraseJob(key, task, store.model_dir(root, key, config), [0], f"task {task}")
    if task != PARTS:
        raise SettingError(
            f"train.pieces gives hands' parts to the {PARTS} family only: drop it for {task}", "train.pieces"
        )
    key = f"{key}-pieces-{given.digest}"
    about = given.about | {"digest": given.digest}
    return PhraseJob(key, given, store.model_dir(root, key, config), [0], f"task {task}", about)


PIECE_SUFFIXES = (".mid", ".midi")
"""The files of a folder of pieces (:func:`given_parts`) that are read."""


def given_parts(folder: Path, env: EnvConfig, share: float = GIVEN_SHARE) -> GivenParts:
    """The ``parts`` family's given parts from a folder of two-hand files (``pianobot train --task
    parts --pieces DIR``): each hand's part of every .mid file in ``folder`` (sorted by name) that
    ``pianobot play`` plays with both hands, read as ``play`` reads it (the hands named by its
    tracks or given by the fingering planner, for ``env``'s hand), and given to a player as
    :func:`~pianobot.perform.together.prepare_part` gives it: the left hand's mirrored, moved by
    octaves onto ``env``'s keys (notes still off them left out), what the hand cannot reach reduced,
    fingered by the planner, from the part's own first note. Unlike ``play``, each hand is fingered
    alone (``play`` plans both hands' fingerings together to keep the wrists apart) and a part wider
    than the keys is not given its own octaves; like ``play``, a part the planner reports problems
    with (a passage still faster than the hand) is kept. Files that play one hand, that the reading
    refuses (the first three named), and parts the hand cannot play as given, are left out, said in
    one warning line; none left is a one-line error. The readings' own warnings are not said: a
    file's reductions are the part it gives. The parts are the policy's data, so a later reader or
    planner that gives other parts of the same files names another folder (:func:`task_job`)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise SettingError(
            f"train.pieces {quote(str(folder))}: not a folder: give a folder of two-hand .mid files", "train.pieces"
        )
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in PIECE_SUFFIXES)
    if not files:
        raise SettingError(
            f"train.pieces {quote(str(folder))}: no .mid files in it: give a folder of two-hand .mid files",
            "train.pieces",
        )
    keyboard, fingers = env.world.keyboard.spec, env.world.hand.spec
    parts, one_hand, refused, unplayable = [], 0, [], 0
    for file in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                reading = two_hands(file, LoadOptions(), fingers, keyboard)
            except PianobotError:
                refused.append(file.name)
                continue
            if reading is None:
                one_hand += 1
                continue
            for hand in reading.piece.hands:
                try:
                    _, part, _, _ = prepare_part(reading.piece, hand, keyboard, fingers)
                    check_playable(part, keyboard, fingers)
                except PianobotError:
                    unplayable += 1
                    continue
                parts.append(part)
    left_out = [
        f"{count} {what}"
        for count, what in (
            (one_hand, "file(s) that play one hand"),
            (
                len(refused),
                f"file(s) the reading refuses ({', '.join(refused[:3])}{', ...' * (len(refused) > 3)}: pianobot inspect FILE says why)",
            ),
            (unplayable, "part(s) the hand cannot play as given"),
        )
        if count
    ]
    if not parts:
        raise SettingError(
            f"train.pieces {quote(str(folder))}: none of its {len(files)} .mid files gives a part to train on "
            f"({', '.join(left_out)}): give two-hand files",
            "train.pieces",
        )
    if left_out:
        warnings.warn(PianobotWarning(f"{folder}: left out {', '.join(left_out)}; {len(parts)} parts are given"))
    about = {"folder": str(folder), "files": len(files), "parts": len(parts), "share": share}
    return GivenParts(tuple(parts), share, about)


def plan_jobs(
    jobs: list[PhraseJob], force: bool, run: str = "", resuming: bool = False
) -> tuple[list[PhraseJob], list[PhraseJob]]:
    """(jobs to train, jobs already done: a stored policy, a run that kept its start policy, or the
    store's index says the general policy plays the phrase).

    ``force`` trains every job again: each folder is marked as replaced by the run ``run``
    (:func:`~pianobot.learn.forced.mark_replacing`), and what it stored stays, and plays as it did,
    until the job's new run has finished. ``resuming`` (:func:`~pianobot.learn.forced.forced_run`: the same forced run was
    interrupted) trains only the jobs that run had not finished. Without ``force``, a job an
    interrupted forced run had not finished is trained on (from its checkpoint)."""
    todo, done = [], []
    for job in jobs:
        root = job.folder.parent
        mark = forced.replacing(job.folder)
        if force and resuming and mark is not None and mark["run"] == run:
            (done if mark["finished"] else todo).append(job)
        elif force:
            forced.mark_replacing(job.folder, run)
            todo.append(job)
        elif mark is not None and not mark["finished"]:
            todo.append(job)
        elif (
            store.is_trained(job.folder) or store.kept_start(job.folder) or job.folder.name in store.general_plays(root)
        ):
            done.append(job)
        else:
            todo.append(job)
    return todo, done


def run_jobs(
    jobs: list[PhraseJob],
    config: TrainConfig,
    workers: int,
    on_progress: Callable[[str, Progress], None],
    threads: int = 1,
    start: Path | None = None,
) -> dict[str, dict]:
    """Train every job, ``workers`` at a time in separate processes (1: in this process), each with
    ``threads`` torch threads (more threads than cores makes torch's thread pools spin against each
    other), each from the policy ``start`` when given (:func:`general_start`)."""
    results: dict[str, dict] = {}
    if workers <= 1 or len(jobs) <= 1:
        torch.set_num_threads(threads)
        for job in jobs:
            results[job.key] = learner(config)(
                job.target,
                config,
                job.folder,
                lambda p, key=job.key: on_progress(key, p),
                about=job.about(),
                start=start,
            )
        return results
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    with worker_pool(workers, context, queue) as pool:
        futures = {pool.submit(_run_job, job, config, None, threads, start): job for job in jobs}
        pending = set(futures)
        while pending:
            while not queue.empty():
                key, progress = queue.get()
                on_progress(key, progress)
            finished = {f for f in pending if f.done()}
            for future in finished:
                results[futures[future].key] = future.result()
            pending -= finished
            time.sleep(0.2)
        while not queue.empty():
            key, progress = queue.get()
            on_progress(key, progress)
    return results


RAY_RETRIES = 3
"""Times Ray runs a phrase again when its worker dies (a process killed, a node lost): each run
resumes from the phrase's last checkpoint, so what was trained before it is kept."""


def run_jobs_on_ray(
    jobs: list[PhraseJob],
    config: TrainConfig,
    on_progress: Callable[[str, Progress], None],
    threads: int = 1,
    start: Path | None = None,
) -> dict[str, dict]:
    """Train every job as a Ray task: on the cluster ``RAY_ADDRESS`` names (Ray's own convention),
    or on a local Ray runtime when it is unset. Each task asks for ``threads`` CPUs (or
    ``config.envs``, when more: its environment workers) and trains with ``threads`` torch threads; progress comes back through a Ray queue. Every node must see the model
    folders at the same path (a shared file system): checkpoints are written and resumed there.
    A task whose worker dies is run again (:data:`RAY_RETRIES`) from its phrase's last checkpoint."""
    try:
        import ray
        from ray.util.queue import Queue
    except ImportError:
        raise PianobotError("training on Ray needs Ray installed: pip install 'pianobot[ray]'") from None
    started_here = not ray.is_initialized()
    if started_here:
        ray.init(include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        queue = Queue()
        task = ray.remote(num_cpus=max(threads, config.envs), max_retries=RAY_RETRIES)(_run_job)
        refs = {task.remote(job, config, queue, threads, start): job for job in jobs}
        pending, results = list(refs), {}

        def drain() -> None:
            while not queue.empty():
                key, progress = queue.get()
                on_progress(key, progress)

        while pending:
            done, pending = ray.wait(pending, num_returns=1, timeout=0.2)
            drain()
            for ref in done:
                try:
                    results[refs[ref].key] = ray.get(ref)
                except ray.exceptions.RayTaskError as e:  # a PianobotError in a task stays one line
                    raise (e.cause if isinstance(e.cause, PianobotError) else e) from None
        drain()
        return results
    finally:
        if started_here:
            ray.shutdown()
