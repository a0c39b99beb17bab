"""The `pianobot train` command (its options and their help: :mod:`pianobot.cli.commands.train_options`)."""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Optional

import typer

from pianobot.agent.config import SACConfig
from pianobot.cli.commands import train_options as o
from pianobot.cli.options import (
    DEFAULT_STORE,
    Actor,
    Cluster,
    Control,
    Device,
    Explore,
    Learner,
    PhraseNotes,
    Reading,
    Reward,
    Task,
    check_files,
    finger_file,
    option,
    read_file,
    reads,
    refuse_training_into,
    value,
)
from pianobot.cli.terminal import err, out, said, write_json
from pianobot.env.piano import EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.errors import PianobotError, PianobotWarning
from pianobot.files import check_writable
from pianobot.learn.config import MAX_ENVS, DaggerConfig, TrainConfig
from pianobot.music.tasks import PARTS
from pianobot.sim.world import WorldConfig


@reads()
def train(
    song: Optional[Path] = o.SONG_OPTION,
    task: Optional[Task] = o.TASK_OPTION,
    pieces: Optional[Path] = o.PIECES_OPTION,
    steps: int = o.STEPS_OPTION,
    seed: int = o.SEED_OPTION,
    learner: Learner = o.LEARNER_OPTION,
    round_steps: int = o.ROUND_STEPS_OPTION,
    dagger_learning_rate: float = o.DAGGER_LEARNING_RATE_OPTION,
    dagger_hold_guard: bool = o.DAGGER_HOLD_GUARD_OPTION,
    until_f1: Optional[float] = o.UNTIL_F1_OPTION,
    from_general: bool = o.FROM_GENERAL_OPTION,
    general_policy: Optional[Path] = o.GENERAL_POLICY_OPTION,
    workers: int = typer.Option(1, "--workers", help="Train this many phrases at once, in separate processes."),
    threads: int = o.THREADS_OPTION,
    envs: int = o.ENVS_OPTION,
    finish: bool = o.FINISH_OPTION,
    device: Device = o.DEVICE_OPTION,
    control: Control = o.CONTROL_OPTION,
    reward: Reward = typer.Option(RewardConfig.kind, "--reward", help="Reward: linear, squared or wasserstein."),
    explore: Explore = o.EXPLORE_OPTION,
    exploration_steps: int = o.EXPLORATION_STEPS_OPTION,
    actor: Optional[Actor] = o.ACTOR_OPTION,
    tactile: bool = o.TACTILE_OPTION,
    joints: str = o.JOINTS_OPTION,
    fingering_gate: bool = o.FINGERING_GATE_OPTION,
    force: bool = o.FORCE_OPTION,
    models: Path = typer.Option(DEFAULT_STORE, "--models", help="Folder of the model store."),
    cluster: Cluster = o.CLUSTER_OPTION,
    json_path: Optional[Path] = o.JSON_PATH_OPTION,
    phrase_notes: int = PhraseNotes,
    reading: Reading = None,
):
    """Train one Soft Actor-Critic policy per phrase of a piece (each hand's, for a two-hand file; or one for a task family) and store them."""
    from pianobot.agent.general import find_general
    from pianobot.learn import plan as training
    from pianobot.learn.jobs import general_start

    _check_run(song, task, pieces, workers, threads, envs, device, cluster)
    check_files({"the input": song, "the fingering file": reading.options.fingering}, {"--json": json_path})
    if json_path is not None and str(json_path) != "-":
        check_writable(json_path)
    console = err if json_path is not None and str(json_path) == "-" else out  # standard output carries the JSON
    if models.exists() and not models.is_dir():
        raise PianobotError(f"--models {models} is a file: give a folder")
    read = read_file(song, reading, finger=False, models=models, policy=general_policy) if song else None
    hands = None if read is None else read.hands
    keyboard, hand = (reading.keyboard, reading.hand) if read is None else (read.keyboard, read.fingers)
    settings = dict(steps=steps, seed=seed, learner=learner, round_steps=round_steps, until_f1=until_f1, envs=envs)
    settings |= dict(dagger_learning_rate=dagger_learning_rate, from_general=from_general, device=device)
    settings |= dict(dagger_hold_guard=dagger_hold_guard)
    settings |= dict(control=control, reward=reward, explore=explore, exploration_steps=exploration_steps)
    settings |= dict(actor=actor, tactile=tactile, joints=joints, fingering_gate=fingering_gate, task=task)
    settings |= dict(finish=finish)
    config = _config(keyboard, hand, general_policy=general_policy, **settings)
    if general_policy is not None and not from_general:
        raise PianobotError(
            f"--general-policy {general_policy} and --no-from-general ask for opposite things: give one of them"
        )
    if general_policy is not None:
        find_general(models, path=general_policy)  # a folder that holds no policy: said before any work
    # where the run begins, before its folders are named: a run from a policy takes its networks
    base = config
    config, start = general_start(config, models, general_policy, networks_given=actor is not None)
    if task is not None:
        plan = _plan_task(console, task, pieces, config, start, models, general_policy, force)
    else:
        piece = hands.piece if hands is not None else finger_file(read, reading).piece
        plan = training.plan_piece(
            song.name, piece, hands is not None, config, start, models, base=base, general_policy=general_policy,
            phrase_notes=phrase_notes, keyboard=keyboard, fingers=hand, networks_given=actor is not None,
            keys_named=reading.keyboard_named,
        )  # fmt: skip
        _say_starts(console, plan, general_policy, models, force, from_general)
        plan = training.plan_training(plan, force)
    models.mkdir(parents=True, exist_ok=True)
    _say_skipped(console, plan, models)
    todo = plan.todo
    if finish:
        from pianobot.agent import store

        for job in todo:
            if store.checkpoint_state(job.folder) is None:
                console.print(
                    f"--finish: {job.folder} holds no checkpoint of this run (were all the interrupted command's "
                    "options given?): it trains as usual",
                    soft_wrap=True,
                )
    console.print(
        f"training {len(todo)} polic{'y' if len(todo) == 1 else 'ies'} for {said(plan.label)}, {steps} steps each"
    )
    with _progress(console, todo, steps, task is not None, finish) as on_progress:
        results = training.train_groups(plan, on_progress, cluster.value, workers, threads)
    trained = training.trained_policies(plan, results, models)
    verdict = _judge(console, plan, trained, models, song)
    if json_path is not None:
        write_json(json_path, training.training_summary(plan, trained, verdict))


def _check_run(song, task, pieces, workers: int, threads: int, envs: int, device, cluster) -> None:
    """The run's options together, before any work: one line where they cannot go together, a
    warning where they will run slowly."""
    from pianobot.agent.sac import resolve_device

    if (song is None) == (task is None):
        raise PianobotError("give a .mid file to train on, or --task NAME (not both)")
    if pieces is not None and task != PARTS:
        raise PianobotError(f"--pieces gives hands' parts to --task {PARTS}: drop it, or train --task {PARTS}")
    if workers < 1 or threads < 1:
        raise PianobotError(f"--workers {workers} --threads {threads}: give 1 or more of each")
    if not 1 <= envs <= MAX_ENVS:
        raise PianobotError(f"--envs {envs}: give 1 to {MAX_ENVS} environments")
    resolve_device(device.value)  # a GPU asked for and missing: say so before any work
    cores = os.cpu_count() or 1
    # the environment workers step while the learner waits for them, and the learner updates while they wait
    busy = workers * max(threads, envs)
    if cluster == "local" and busy > cores:
        asked = f"--workers {workers} x --{'threads' if threads >= envs else 'envs'} {max(threads, envs)}"
        warnings.warn(
            PianobotWarning(
                f"{asked} asks for {busy} busy threads on {cores} cores: torch's thread pools then spin against each "
                f"other (measured up to 20x slower); keep workers x threads (and workers x envs) <= {cores}"
            )
        )
    if task is not None and workers > 1:
        warnings.warn(
            PianobotWarning(
                f"--task trains one policy: --workers {workers} has nothing to share out (--envs steps several environments)"
            )
        )


def _config(keyboard, hand, *, general_policy, task, **given) -> TrainConfig:
    """The run's :class:`~pianobot.learn.config.TrainConfig` from the options (``given``, by their
    parameter names), each value refused in the words of its option."""
    from pianobot.learn.train import TASK_EVAL_EPISODES
    from pianobot.perform.guard import HoldGuard
    from pianobot.sim.hand import hand_config
    from pianobot.sim.keyboard import KeyboardConfig

    g = dict(given)
    control, reward, joints, round_steps = g["control"], g["reward"], g["joints"], g["round_steps"]
    dagger_learning_rate, exploration_steps, actor = g["dagger_learning_rate"], g["exploration_steps"], g["actor"]
    with option("--control", control):
        world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=hand_config(hand), control=control.value)
    with option("--reward", reward):
        rewards = RewardConfig(kind=reward.value, fingering_gate=g["fingering_gate"])
    with option("--joints", joints):
        env = EnvConfig(
            world=world,
            reward=rewards,
            tactile=g["tactile"],
            actuated=tuple(j.strip() for j in joints.split(",") if j.strip()),
        )
    with option("--round-steps", round_steps):
        DaggerConfig(round_steps=round_steps)
    with option("--dagger-learning-rate", dagger_learning_rate):
        if not 0 < dagger_learning_rate < math.inf:
            raise ValueError("a step size must be a number above 0")
        final = min(DaggerConfig.final_learning_rate, dagger_learning_rate)
        dagger = DaggerConfig(round_steps=round_steps, learning_rate=dagger_learning_rate, final_learning_rate=final)
    if g["dagger_hold_guard"]:
        if not HoldGuard.fits(env):
            raise PianobotError(
                "--dagger-hold-guard: the hold guard reads which finger holds a note from the finger targets: train a "
                "policy that observes them with their holds (--task parts does), driven by --control velocity or position"
            )
        dagger = replace(dagger, hold_guard=True)
    with option("--exploration-steps", exploration_steps):
        sac = SACConfig(exploration_steps=exploration_steps, actor=value(actor) or SACConfig.actor)
    with option():
        config = TrainConfig(
            steps=g["steps"],
            seed=g["seed"],
            learner=g["learner"].value,
            dagger=dagger,
            explore=g["explore"].value,
            until_f1=g["until_f1"],
            # a task family trains from scratch, or continues the policy --general-policy names
            from_general=g["from_general"] and (task is None or general_policy is not None),
            sac=sac,
            env=env,
            eval_episodes=TASK_EVAL_EPISODES if task is not None else TrainConfig.eval_episodes,
            envs=g["envs"],
            device=g["device"].value,
            finish=g["finish"],
        )
    return config


def _plan_task(console, task, pieces, config, start, models: Path, general_policy, force: bool):
    """A task family's training plan (``--pieces``: its given parts read first), said in a line
    where it continues a policy."""
    from pianobot.agent import store
    from pianobot.learn import plan as training
    from pianobot.learn.jobs import given_parts, task_job

    given = None
    if pieces is not None:
        if pieces.is_dir():  # (else given_parts says what is wrong)
            console.print(f"reading the two-hand files in {said(pieces)}", soft_wrap=True)
        given = given_parts(pieces, config.env)
    job = task_job(task.value, config, models, given)
    refuse_training_into(general_policy, [job])
    label = f"task {task}"
    if given is not None:
        label += f", {given.share:.0%} of it {len(given.parts)} parts of {given.about['files']} files in {pieces}"
    plan = training.plan_training(training.plan_task(label, job, config, start), force)
    if start is not None and plan.todo and store.checkpoint_state(job.folder) is None:  # (else it resumes, and says so)
        console.print(f"continuing the policy {said(start)} on {said(label)}: evaluated first", soft_wrap=True)
    return plan


def _say_starts(console, plan, general_policy, models: Path, force: bool, from_general: bool) -> None:
    """Where each group's phrases start, before any is trained."""
    from pianobot.agent import store

    every_job = [job for group in plan.groups for job in group.jobs]
    refuse_training_into(general_policy, every_job)
    if not force and all(store.is_trained(job.folder) for job in every_job):
        return
    for group in plan.groups:
        if group.start is not None:
            console.print(
                f"starting {group.whose} from the general policy {said(group.start)}: evaluated first, a phrase "
                f"stops at note F1 {group.config.stop_f1} (--no-from-general trains from scratch)",
                soft_wrap=True,
            )
        elif from_general:
            console.print(
                f"[dim]no general policy in {said(models)} for {group.whose} (`pianobot train --task parts` trains "
                "one): training from scratch[/dim]"
            )


def _say_skipped(console, plan, models: Path) -> None:
    """One line per job already trained (or played by the general policy): skipped."""
    from pianobot.agent import store
    from pianobot.learn import forced

    for job in plan.done:
        where = (
            f"already trained in {said(job.folder)}"
            if store.is_trained(job.folder)
            else f"played by the general policy, as {said(models)}'s index ({store.GENERAL_INDEX}) says"
        )
        why = "skipped (--force retrains)"
        if forced.replacing(job.folder) is not None:  # (finished by an interrupted forced run: it goes on)
            where, why = f"trained anew in {said(job.folder)}", "skipped: the interrupted --force run finished it"
        console.print(f"phrase {job.key} ({', '.join(map(str, job.phrases))}) {where}: {why}", soft_wrap=True)


@contextlib.contextmanager
def _progress(console, todo, steps: int, task: bool, finish: bool = False):
    """A progress bar per job while it trains; yields the ``on_progress(key, progress)`` that moves them."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    returns: dict[str, float] = {}
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} steps"),
        TextColumn("{task.fields[status]}"),
        TimeRemainingColumn(),
        console=console,
    ) as bar:
        rows = {
            job.key: bar.add_task(f"phrase {job.key[:8]}" if not task else job.key, total=steps, status="")
            for job in todo
        }

        def on_progress(key: str, progress) -> None:
            if progress.resumed:
                what = "ending at its checkpoint (--finish)" if finish else "resuming from its checkpoint"
                bar.console.print(f"{bar.tasks[rows[key]].description}: {what} at step {progress.step}")
            if progress.finished:  # stopped early (--until-f1) or at its last step: the bar ends full
                bar.update(rows[key], total=progress.step, completed=progress.step)
                return
            status = bar.tasks[rows[key]].fields.get("status", "")
            if progress.episode_return is not None:
                returns[key] = progress.episode_return
            if progress.eval_f1 is not None:
                status = f"eval F1 {progress.eval_f1:.2f}"
            elif key in returns:
                status = f"return {returns[key]:.1f}" + (f" | {status.split(' | ')[-1]}" if "eval" in status else "")
            bar.update(rows[key], completed=progress.step, status=status)

        yield on_progress


def _judge(console, plan, trained, models: Path, song):
    """:func:`_verdict`, then a forced run's marks go: given again, it trains every phrase anew."""
    from pianobot.learn import plan as training

    verdict = _verdict(console, plan, trained, models, song)
    training.forget_forced(plan)
    return verdict


def _verdict(console, plan, trained, models: Path, song):
    """The training table, then the whole piece judged as ``play`` plays it (where phrase
    policies were trained now and a general policy plays beside them), said; the verdict or None."""
    from pianobot.cli import display
    from pianobot.learn import plan as training
    from pianobot.learn.accept import JUDGE_SEEDS
    from pianobot.learn.log import LOG_FILE, PLOT_FILE

    console.print(display.training_table(trained))
    if any((job.folder / LOG_FILE).exists() for job, _ in trained):
        console.print(f"learning curves: {LOG_FILE} and {PLOT_FILE} in each policy's folder")
    beside = training.judges(plan, models)
    if not beside or not all(beside.values()):  # the whole piece, as play performs it: no phrase policy makes it worse
        return None
    two = plan.parts is not None
    seeds = ", ".join(map(str, JUDGE_SEEDS))
    console.print(
        f"playing {said(song.name)} whole{' (both hands)' if two else ''} from hand starts {seeds}, "
        "as `pianobot play` does, to judge its phrase policies"
    )
    verdict = training.judge_piece(plan, trained, models, beside)
    before, after = sum(verdict.before) / len(JUDGE_SEEDS), sum(verdict.after) / len(JUDGE_SEEDS)
    used = (
        f"own policies for phrases {', '.join(map(str, verdict.used))}"
        if verdict.used
        else "no phrase policy of its own"
    )
    console.print(
        f"{said(song.name)}: note F1 {before:.3f} with the general polic{'ies' if two else 'y'} alone, "
        f"{after:.3f} as it plays now ({used})"
    )
    ran = [m for job, m in trained if job in plan.todo]
    if not verdict.used and after < 1.0 and ran and all(m.get("kept") == "start" for m in ran):
        if all(not m.get("steps") for m in ran):
            said_why = "every phrase played well enough from a fresh start, so none was trained"
        else:  # (trained, but no evaluation beat the start's)
            said_why = (
                "no phrase's training played better than its start in the phrase's own evaluation, so the "
                "general policy plays every phrase (more --steps may help)"
            )
        console.print(
            f"[yellow]{said_why}; played whole, the hand goes on from where each phrase left it, which the "
            "phrase-by-phrase evaluation does not see[/yellow]",
            soft_wrap=True,
        )
    for number, why in verdict.dropped.items():
        console.print(f"[yellow]phrase {number}'s own policy is not used: {said(why)}[/yellow]")
    return verdict
