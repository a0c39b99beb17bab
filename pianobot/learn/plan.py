"""One training run of ``pianobot train``, as a typed plan: what is trained, from where, in which
groups, then the training itself, what it left, and the whole piece judged.

:func:`plan_training` groups a piece's phrases (one group; or, for a two-hand piece, each hand's
phrases, its part as ``play`` gives it to that hand, from the general policy ``play`` gives that
hand; a phrase both hands play is one job, in the right hand's group) or a task family's one job,
and sets aside the jobs already trained (:func:`~pianobot.learn.jobs.plan_jobs`).
:func:`train_groups` trains the rest, group by group; :func:`trained_policies` says what each
job left; :func:`judge_piece` plays the whole piece as ``play`` does, keeping a phrase policy only
where the piece plays better with it (:mod:`pianobot.learn.accept`); :func:`training_summary` is
the run's JSON.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

from pianobot.agent import store
from pianobot.errors import SettingError
from pianobot.learn.config import TrainConfig
from pianobot.learn.forced import forced_run, forget_replacing
from pianobot.learn.jobs import PhraseJob as Job
from pianobot.learn.jobs import general_start, phrase_jobs, plan_jobs, run_jobs, run_jobs_on_ray
from pianobot.learn.log import LOG_FILE, PLOT_FILE
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.phrases import Phrase, split_phrases
from pianobot.music.piece import Piece


@dataclass(frozen=True)
class TrainingGroup:
    """Jobs that train from one start in one configuration: a whole piece's or task's, or one hand's."""

    hand: str | None
    """The hand whose phrases these are (None: a one-hand piece, or a task family)."""
    config: TrainConfig
    start: Path | None
    """The policy its phrases start from (None: from scratch)."""
    jobs: tuple[Job, ...]

    @property
    def whose(self) -> str:
        """Whose phrases, in words: 'every phrase', "the left hand's phrases"."""
        return "every phrase" if self.hand is None else f"the {self.hand} hand's phrases"


@dataclass(frozen=True)
class TrainingPlan:
    """A training run planned: its groups of jobs to train, the jobs already trained, and, for a
    piece, what its judgement needs."""

    label: str
    """What is trained, in words: 'song.mid: 4 phrases', 'task melody'."""
    groups: tuple[TrainingGroup, ...]
    """Each group with every job it holds (trained or not)."""
    todo: tuple[Job, ...] = ()
    """The jobs to train now (all, with ``force``)."""
    done: tuple[Job, ...] = ()
    """The jobs already trained, skipped."""
    piece: Piece | None = None
    """The piece trained on (every note with its hand for a two-hand piece); None for a task."""
    phrases: dict[str | None, list[Phrase]] = field(default_factory=dict)
    """Each hand's phrases (None: a one-hand piece's)."""
    parts: dict[str, tuple] | None = None
    """A two-hand piece: each hand's part as ``play`` gives it (:func:`~pianobot.perform.together.prepare_parts`)."""
    offered: dict[str | None, Path | None] = field(default_factory=dict)
    """The general policy ``play`` gives each hand of a two-hand piece."""
    keyboard: KeyboardSpec | None = None

    def groups_to_train(self) -> tuple[TrainingGroup, ...]:
        """Each group with only its jobs to train now."""
        return tuple(replace(g, jobs=tuple(j for j in g.jobs if j in self.todo)) for g in self.groups)


def plan_piece(
    name: str,
    piece: Piece,
    two_hands: bool,
    config: TrainConfig,
    start: Path | None,
    models: Path,
    *,
    base: TrainConfig,
    general_policy: Path | None,
    phrase_notes: int,
    keyboard: KeyboardSpec,
    fingers: HandSpec,
    networks_given: bool,
    keys_named: bool,
) -> TrainingPlan:
    """A piece's training, before jobs are set aside: one group of its phrases (``config`` from
    ``start``), or a two-hand piece's hand by hand (:func:`hand_groups`, from ``base``)."""
    if not two_hands:
        phrases = {None: split_phrases(piece, phrase_notes)}
        jobs = tuple(phrase_jobs(phrases[None], config, models, piece=name))
        label = f"{name}: {len(phrases[None])} phrases"
        return TrainingPlan(
            label, (TrainingGroup(None, config, start, jobs),), piece=piece, phrases=phrases, keyboard=keyboard
        )
    parts, phrases, offered, groups = hand_groups(
        piece, name, models, base, general_policy, phrase_notes, keyboard, fingers, networks_given, keys_named
    )
    label = f"{name}: " + ", ".join(f"{len(p)} phrases of the {h} hand" for h, p in phrases.items())
    return TrainingPlan(
        label, tuple(groups), piece=piece, phrases=phrases, parts=parts, offered=offered, keyboard=keyboard
    )


def hand_groups(
    piece: Piece,
    name: str,
    models: Path,
    base: TrainConfig,
    general_policy: Path | None,
    phrase_notes: int,
    keyboard: KeyboardSpec,
    fingers: HandSpec,
    networks_given: bool,
    keys_named: bool = False,
) -> tuple[dict, dict, dict, list[TrainingGroup]]:
    """A two-hand piece's training, hand by hand: (each hand's part as ``play`` gives it to that hand
    (:func:`~pianobot.perform.together.prepare_parts`), its phrases, the general policy ``play`` gives
    it, and the groups to train). ``base``: the run's config before a start policy was picked. A
    phrase both hands play is one job, in the right hand's group."""
    from pianobot.agent.general import find_general
    from pianobot.perform.together import hand_players, prepare_parts

    parts = prepare_parts(
        piece, keyboard, fingers, grow=not keys_named
    )  # (as play's default: wider parts on their own octaves)
    named = {"general_policy": general_policy} if general_policy is not None else {}
    players = hand_players(parts, "sac", models, fingers, named)
    phrases, offered, seen, groups = {}, {}, {}, []
    for side, (window, part, *_) in parts.items():
        phrases[side] = split_phrases(part, phrase_notes)
        offered[side] = players[side].get("general_policy")
        world = replace(base.env.world, keyboard=replace(base.env.world.keyboard, spec=window.keyboard))
        side_base = replace(base, env=replace(base.env, world=world))  # (a part wider than 24 keys: its own)
        if offered[side] != general_policy:  # the packaged parts policy, which play offers only where it fits
            try:
                find_general(models, side_base.env, base.sac if networks_given else None, offered[side])
            except SettingError:
                offered[side] = general_policy
        config, start = general_start(side_base, models, offered[side], networks_given=networks_given)
        jobs = []
        for job in phrase_jobs(phrases[side], config, models, piece=f"{name} ({side} hand)"):
            job.phrases = [f"{side} {number}" for number in job.phrases]
            if job.key in seen:  # the other hand's phrase too: one policy (from the right hand's start) plays both
                seen[job.key].phrases += job.phrases
            else:
                seen[job.key] = job
                jobs.append(job)
        groups.append(TrainingGroup(side, config, start, tuple(jobs)))
    return parts, phrases, offered, groups


def plan_task(label: str, job: Job, config: TrainConfig, start: Path | None) -> TrainingPlan:
    """A task family's training: one job, before it is set aside."""
    return TrainingPlan(label, (TrainingGroup(None, config, start, (job,)),))


def plan_training(plan: TrainingPlan, force: bool) -> TrainingPlan:
    """``plan`` with its jobs already trained set aside (all trained again with ``force``,
    :func:`~pianobot.learn.jobs.plan_jobs`)."""
    todo, done = [], []
    run, resuming = forced_run([job.folder for group in plan.groups for job in group.jobs])
    for group in plan.groups:
        train, skip = plan_jobs(list(group.jobs), force, run, resuming)
        todo += train
        done += skip
    return replace(plan, todo=tuple(todo), done=tuple(done))


def forget_forced(plan: TrainingPlan) -> None:
    """The plan's phrases trained and judged: the marks of a forced run (:func:`plan_training`) go."""
    for group in plan.groups:
        for job in group.jobs:
            forget_replacing(job.folder)


def train_groups(
    plan: TrainingPlan, on_progress: Callable, cluster: str = "local", workers: int = 1, threads: int = 1
) -> dict[str, dict]:
    """Train the plan's jobs, group by group (on Ray with ``cluster`` 'ray', else ``workers``
    processes here): each job's manifest by its key."""
    results = {}
    for group in plan.groups_to_train():
        if cluster == "ray":
            results |= run_jobs_on_ray(list(group.jobs), group.config, on_progress, threads=threads, start=group.start)
        else:
            results |= run_jobs(
                list(group.jobs), group.config, workers, on_progress, threads=threads, start=group.start
            )
    return results


def trained_policies(plan: TrainingPlan, results: dict[str, dict], models: Path) -> list[tuple[Job, dict]]:
    """What training left for each job, skipped ones first: a policy's manifest, or the store's
    word that the general policy plays its phrases."""

    def manifest(job) -> dict:
        if job.key in results:
            return results[job.key]
        if store.is_trained(job.folder) or store.kept_start(job.folder):
            return store.read_manifest(job.folder)
        return {"kept": "start", "start": store.general_plays(models).get(job.folder.name, {}), "steps": 0}

    return [(job, manifest(job)) for job in plan.done + plan.todo]


def judges(plan: TrainingPlan, models: Path) -> dict[str | None, Path | None]:
    """The general policy each group's phrases are judged beside: the one they started from, else
    the one ``play`` gives that hand; none where nothing was trained now."""
    from pianobot.learn.accept import judge_for

    if plan.piece is None or not plan.todo:
        return {}
    return {
        g.hand: g.start
        or (plan.offered.get(g.hand) if plan.parts is not None else None)
        or judge_for(models, g.config.env, None)
        for g in plan.groups
    }


def judge_piece(plan: TrainingPlan, trained: list[tuple[Job, dict]], models: Path, beside: dict):
    """The whole piece played as ``play`` plays it, from ``play``'s hand starts, with and without
    the phrase policies trained now (``beside``: :func:`judges`): a verdict
    (:mod:`pianobot.learn.accept`) of which it keeps."""
    from pianobot.learn.accept import settle_hands, settle_piece

    started = {name: {} for name in beside}
    for job, m in trained:
        if job in plan.todo and m.get("kept") == "start":
            hand = next(g.hand for g in plan.groups if job in g.jobs)
            started[hand][job.folder.name] = m["evaluation"]["f1"]
    if plan.parts is None:
        return settle_piece(plan.piece, plan.phrases[None], models, beside[None], started[None], keyboard=plan.keyboard)
    return settle_hands(plan.piece, plan.parts, plan.phrases, models, beside, started)


def training_summary(plan: TrainingPlan, trained: list[tuple[Job, dict]], verdict=None) -> dict:
    """The run's JSON: each policy's figures and files (with the hand, and the hand model, it plays),
    and the piece's verdict."""

    def group_of(job: Job) -> TrainingGroup:
        return next(g for g in plan.groups if job in g.jobs)  # (jobs are not hashable)

    summary = [
        {
            "key": job.key,
            "hand": group_of(job).hand,
            "hand_model": group_of(job).config.env.world.hand.spec.model,
            "phrases": job.phrases,
            "folder": str(job.folder),
            "trained_now": job in plan.todo,
            **{k: manifest.get(k) for k in ("steps", "updates", "seconds", "start", "evaluation", "kept")},
            "log": str(job.folder / LOG_FILE),
            "plot": str(job.folder / PLOT_FILE),
        }
        for job, manifest in trained
    ]
    return {"policies": summary, **({"piece": verdict.to_dict()} if verdict else {})}
