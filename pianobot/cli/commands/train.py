"""The `pianobot train` command."""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path
from typing import Optional

import typer

from pianobot.agent.config import ACTORS, SACConfig
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
from pianobot.errors import PianobotError, PianobotWarning, SettingError
from pianobot.files import check_writable
from pianobot.learn.config import MAX_ENVS, DaggerConfig, TrainConfig
from pianobot.learn.explore import EXPLORATIONS
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.tasks import GIVEN_SHARE, MELODY, PARTS, TASKS
from pianobot.sim.world import WorldConfig

SONG_OPTION = typer.Argument(
    None,
    help="A .mid file with fingering (a two-hand file, as play plays it: each hand's part); leave out with --task.",
)
TASK_OPTION = typer.Option(
    None,
    "--task",
    help=f"Train on a task family instead, a fresh random instance each episode: the paper's {', '.join(TASKS)}, "
    f"or {MELODY} (random one-hand phrases of up to {DEFAULT_MAX_NOTES} notes in every key, fingered by the "
    f"planner; docs/training.md) or {PARTS} (either hand's whole part of random two-hand pieces).",
)
PIECES_OPTION = typer.Option(
    None,
    "--pieces",
    help=f"With --task {PARTS}: a folder of two-hand .mid files; {GIVEN_SHARE:.0%} of the instances are then one "
    "hand's part of one of them (each file read as play reads it, each hand's part moved onto the run's keys, "
    "reduced and fingered as play does), the rest the family's own. Files that play one hand are left out.",
)
STEPS_OPTION = typer.Option(
    TrainConfig.steps,
    "--steps",
    help="Environment steps per phrase (of all --envs together), exploration included.",
    min=1,
)
SEED_OPTION = typer.Option(
    TrainConfig.seed,
    "--seed",
    help="Seed of the simulation, the exploration and the networks.",
    min=0,
)
LEARNER_OPTION = typer.Option(
    TrainConfig.learner,
    "--learner",
    help="How policies learn: sac (Soft Actor-Critic from the rewards, the paper's) or dagger (imitating the "
    f"scripted pianist in rounds of {DaggerConfig.round_steps} steps, every step labelled with its action; "
    "needs --control velocity or position; docs/training.md).",
)
ROUND_STEPS_OPTION = typer.Option(
    DaggerConfig.round_steps,
    "--round-steps",
    help="With --learner dagger: environment steps gathered in a round, after which the policy learns from every "
    "step gathered so far and is evaluated (a round ends at the first episode end after them).",
)
DAGGER_LEARNING_RATE_OPTION = typer.Option(
    DaggerConfig.learning_rate,
    "--dagger-learning-rate",
    help="With --learner dagger: Adam's step size at the run's first step; it falls along a cosine to "
    f"{DaggerConfig.final_learning_rate:g} (or to this, if lower) at the last.",
)
UNTIL_F1_OPTION = typer.Option(
    TrainConfig.until_f1,
    "--until-f1",
    help="Stop a phrase early once an evaluation reaches this note F1 (e.g. 0.95); default: train every step, "
    f"or, starting from the general policy, stop at {TrainConfig.finetune_until_f1}.",
)
FROM_GENERAL_OPTION = typer.Option(
    TrainConfig.from_general,
    "--from-general/--no-from-general",
    help="Start every phrase from the general policy (the newest `pianobot train --task melody` or `--task parts` policy in --models "
    "whose options are this run's, or --general-policy): load its actor, encoder, critic and temperature (Adam "
    "starts afresh), evaluate it before any training step, and stop the phrase at the first evaluation that "
    f"reaches note F1 {TrainConfig.finetune_until_f1} (--until-f1 sets another), keeping the best evaluated "
    "policy: a phrase the general policy already plays costs one evaluation, and none ends worse than the "
    "general policy plays it. Without a general policy, or with --no-from-general, phrases train from scratch. "
    "With --task: on only when --general-policy is given.",
)
GENERAL_POLICY_OPTION = typer.Option(
    None,
    "--general-policy",
    help="The policy to start from (any trained policy; default: the newest `pianobot train --task melody` or `--task parts` "
    "policy in --models whose options fit). With --task there is no default: a task family trains from scratch, "
    "or, given this, that policy's training goes on, on the family.",
)
THREADS_OPTION = typer.Option(
    1, "--threads", help="Torch threads per training process (workers x threads should not exceed the cores)."
)
ENVS_OPTION = typer.Option(
    TrainConfig.envs,
    "--envs",
    help="Environments each policy's training steps at once: 1 in the training process, more each in a worker "
    "process of its own.",
)
DEVICE_OPTION = typer.Option(
    TrainConfig.device,
    "--device",
    help="Where the learner's networks and updates run: auto (cuda when torch sees a GPU, else cpu), cpu or cuda.",
)
CONTROL_OPTION = typer.Option(
    WorldConfig.control,
    "--control",
    help="Finger control: velocity (joint speeds), position (joint angle targets) or torque.",
)
EXPLORE_OPTION = typer.Option(
    TrainConfig.explore, "--explore", help=f"Exploration before learning: {', '.join(EXPLORATIONS)}."
)
EXPLORATION_STEPS_OPTION = typer.Option(
    SACConfig.exploration_steps, "--exploration-steps", help="Steps of exploration before learning starts."
)
ACTOR_OPTION = typer.Option(
    None,
    "--actor",
    help=f"The actor's networks: {' or '.join(ACTORS)} (one MLP shared by the fingers; docs/training.md). "
    f"Default: the start policy's when training from one, else {SACConfig.actor}.",
)
TACTILE_OPTION = typer.Option(
    EnvConfig.tactile, "--tactile/--no-tactile", help="Observe the fingertips' tactile images."
)
JOINTS_OPTION = typer.Option(
    ",".join(EnvConfig.actuated),
    "--joints",
    help="Finger joints the policy moves, from abd,mcp,pip,dip; the others hold still.",
)
FINGERING_GATE_OPTION = typer.Option(
    RewardConfig.fingering_gate,
    "--fingering-gate/--no-fingering-gate",
    help="Reward a key only when the score's finger pressed it (the paper's fingering indicator).",
)
CLUSTER_OPTION = typer.Option(
    "local",
    "--cluster",
    help="Where phrases train: 'local' (--workers processes here) or 'ray' (Ray tasks on the cluster RAY_ADDRESS "
    "names, or a local Ray runtime; needs pianobot[ray]).",
)
JSON_PATH_OPTION = typer.Option(
    None, "--json", help="Also write each policy's figures and files to this JSON file ('-': standard output)."
)


@reads()
def train(
    song: Optional[Path] = SONG_OPTION,
    task: Optional[Task] = TASK_OPTION,
    pieces: Optional[Path] = PIECES_OPTION,
    steps: int = STEPS_OPTION,
    seed: int = SEED_OPTION,
    learner: Learner = LEARNER_OPTION,
    round_steps: int = ROUND_STEPS_OPTION,
    dagger_learning_rate: float = DAGGER_LEARNING_RATE_OPTION,
    until_f1: Optional[float] = UNTIL_F1_OPTION,
    from_general: bool = FROM_GENERAL_OPTION,
    general_policy: Optional[Path] = GENERAL_POLICY_OPTION,
    workers: int = typer.Option(1, "--workers", help="Train this many phrases at once, in separate processes."),
    threads: int = THREADS_OPTION,
    envs: int = ENVS_OPTION,
    device: Device = DEVICE_OPTION,
    control: Control = CONTROL_OPTION,
    reward: Reward = typer.Option(RewardConfig.kind, "--reward", help="Reward: linear, squared or wasserstein."),
    explore: Explore = EXPLORE_OPTION,
    exploration_steps: int = EXPLORATION_STEPS_OPTION,
    actor: Optional[Actor] = ACTOR_OPTION,
    tactile: bool = TACTILE_OPTION,
    joints: str = JOINTS_OPTION,
    fingering_gate: bool = FINGERING_GATE_OPTION,
    force: bool = typer.Option(False, "--force", help="Retrain phrases that already have a stored policy."),
    models: Path = typer.Option(DEFAULT_STORE, "--models", help="Folder of the model store."),
    cluster: Cluster = CLUSTER_OPTION,
    json_path: Optional[Path] = JSON_PATH_OPTION,
    phrase_notes: int = PhraseNotes,
    reading: Reading = None,
):
    """Train one Soft Actor-Critic policy per phrase of a piece (each hand's, for a two-hand file; or one for a task family) and store them."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from pianobot.agent import store
    from pianobot.agent.general import find_general
    from pianobot.agent.sac import resolve_device
    from pianobot.cli import display
    from pianobot.learn.accept import JUDGE_SEEDS, judge_for, settle_hands, settle_piece
    from pianobot.learn.jobs import (
        general_start,
        given_parts,
        phrase_jobs,
        plan_jobs,
        run_jobs,
        run_jobs_on_ray,
        task_job,
    )
    from pianobot.learn.log import LOG_FILE, PLOT_FILE
    from pianobot.learn.train import TASK_EVAL_EPISODES
    from pianobot.music.phrases import split_phrases
    from pianobot.sim.hand import hand_config
    from pianobot.sim.keyboard import KeyboardConfig

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
    check_files({"the input": song, "the fingering file": reading.options.fingering}, {"--json": json_path})
    if json_path is not None and str(json_path) != "-":
        check_writable(json_path)
    console = err if json_path is not None and str(json_path) == "-" else out  # standard output carries the JSON
    if models.exists() and not models.is_dir():
        raise PianobotError(f"--models {models} is a file: give a folder")
    read = read_file(song, reading, finger=False) if song is not None else None  # (fingered below)
    hands = None if read is None else read.hands
    keyboard, hand = (reading.keyboard, reading.hand) if read is None else (read.keyboard, read.fingers)
    with option("--control", control):
        world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=hand_config(hand), control=control.value)
    with option("--reward", reward):
        rewards = RewardConfig(kind=reward.value, fingering_gate=fingering_gate)
    with option("--joints", joints):
        env = EnvConfig(
            world=world,
            reward=rewards,
            tactile=tactile,
            actuated=tuple(j.strip() for j in joints.split(",") if j.strip()),
        )
    with option("--round-steps", round_steps):
        DaggerConfig(round_steps=round_steps)
    with option("--dagger-learning-rate", dagger_learning_rate):
        if not 0 < dagger_learning_rate < math.inf:
            raise ValueError("a step size must be a number above 0")
        final = min(DaggerConfig.final_learning_rate, dagger_learning_rate)
        dagger = DaggerConfig(round_steps=round_steps, learning_rate=dagger_learning_rate, final_learning_rate=final)
    with option("--exploration-steps", exploration_steps):
        sac = SACConfig(exploration_steps=exploration_steps, actor=value(actor) or SACConfig.actor)
    with option():
        config = TrainConfig(
            steps=steps,
            seed=seed,
            learner=learner.value,
            dagger=dagger,
            explore=explore.value,
            until_f1=until_f1,
            # a task family trains from scratch, or continues the policy --general-policy names
            from_general=from_general and (task is None or general_policy is not None),
            sac=sac,
            env=env,
            eval_episodes=TASK_EVAL_EPISODES if task is not None else TrainConfig.eval_episodes,
            envs=envs,
            device=device.value,
        )
    if general_policy is not None and not from_general:
        raise PianobotError(
            f"--general-policy {general_policy} and --no-from-general ask for opposite things: give one of them"
        )
    if general_policy is not None:
        find_general(models, path=general_policy)  # a folder that holds no policy: said before any work
    # where the run begins, before its folders are named: a run from a policy takes its networks
    base = config
    config, start = general_start(config, models, general_policy, networks_given=actor is not None)
    groups = []  # (hand or None, its config, the policy its phrases start from, its jobs)
    if task is not None:
        given = None
        if pieces is not None:
            if pieces.is_dir():  # (else given_parts says what is wrong)
                console.print(f"reading the two-hand files in {said(pieces)}", soft_wrap=True)
            given = given_parts(pieces, config.env)
        job = task_job(task.value, config, models, given)
        refuse_training_into(general_policy, [job])
        todo, done = plan_jobs([job], force)
        label = f"task {task}"
        if given is not None:
            label += f", {given.share:.0%} of it {len(given.parts)} parts of {given.about['files']} files in {pieces}"
        if start is not None and todo and store.checkpoint_state(job.folder) is None:  # (else it resumes, and says so)
            console.print(f"continuing the policy {said(start)} on {said(label)}: evaluated first", soft_wrap=True)
        groups = [(None, config, start, todo)]
    else:
        if hands is None:
            piece = finger_file(read, reading).piece
            phrases = {None: split_phrases(piece, phrase_notes)}
            groups = [(None, config, start, phrase_jobs(phrases[None], config, models, piece=song.name))]
            label = f"{song.name}: {len(phrases[None])} phrases"
        else:  # each hand's part as `play` gives it to its player, from the general policy play gives that hand
            piece = hands.piece
            parts, phrases, offered, groups = _hand_groups(
                piece,
                song.name,
                models,
                base,
                general_policy,
                phrase_notes,
                keyboard,
                hand,
                actor is not None,
                reading.keyboard_named,
            )
            label = f"{song.name}: " + ", ".join(f"{len(p)} phrases of the {h} hand" for h, p in phrases.items())
        every_job = [job for *_, jobs in groups for job in jobs]
        refuse_training_into(general_policy, every_job)
        if force or not all(store.is_trained(job.folder) for job in every_job):  # (before --force removes a policy)
            for name, group_config, group_start, _ in groups:
                whose = "every phrase" if name is None else f"the {name} hand's phrases"
                if group_start is not None:
                    console.print(
                        f"starting {whose} from the general policy {said(group_start)}: evaluated first, a phrase "
                        f"stops at note F1 {group_config.stop_f1} (--no-from-general trains from scratch)",
                        soft_wrap=True,
                    )
                elif from_general:
                    console.print(
                        f"[dim]no general policy in {said(models)} for {whose} (`pianobot train --task parts` trains "
                        "one): training from scratch[/dim]"
                    )
        planned = [(name, c, s, *plan_jobs(jobs, force)) for name, c, s, jobs in groups]
        groups = [(name, c, s, todo) for name, c, s, todo, _ in planned]
        todo = [job for *_, jobs in groups for job in jobs]
        done = [job for *_, jobs in planned for job in jobs]
    models.mkdir(parents=True, exist_ok=True)
    for job in done:
        where = (
            f"already trained in {said(job.folder)}"
            if store.is_trained(job.folder)
            else f"played by the general policy, as {said(models)}'s index ({store.GENERAL_INDEX}) says"
        )
        console.print(
            f"phrase {job.key} ({', '.join(map(str, job.phrases))}) {where}: skipped (--force retrains)", soft_wrap=True
        )
    console.print(f"training {len(todo)} polic{'y' if len(todo) == 1 else 'ies'} for {said(label)}, {steps} steps each")
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
            job.key: bar.add_task(f"phrase {job.key[:8]}" if task is None else job.key, total=steps, status="")
            for job in todo
        }

        def on_progress(key: str, progress) -> None:
            if progress.resumed:
                bar.console.print(
                    f"{bar.tasks[rows[key]].description}: resuming from its checkpoint at step {progress.step}"
                )
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

        results = {}
        for _, group_config, group_start, jobs in groups:  # (one group, or each hand's phrases in turn)
            if cluster == "ray":
                results |= run_jobs_on_ray(jobs, group_config, on_progress, threads=threads, start=group_start)
            else:
                results |= run_jobs(jobs, group_config, workers, on_progress, threads=threads, start=group_start)

    def manifest(job) -> dict:  # what training left: a policy, or the store's word that the general policy plays it
        if job.key in results:
            return results[job.key]
        if store.is_trained(job.folder) or store.kept_start(job.folder):
            return store.read_manifest(job.folder)
        return {"kept": "start", "start": store.general_plays(models).get(job.folder.name, {}), "steps": 0}

    trained = [(job, manifest(job)) for job in done + todo]
    console.print(display.training_table(trained))
    if any((job.folder / LOG_FILE).exists() for job, _ in trained):
        console.print(f"learning curves: {LOG_FILE} and {PLOT_FILE} in each policy's folder")
    verdict = None
    judges = {}  # the general policy each hand's phrases are judged beside: the one they started from, else play's
    if task is None and todo:
        for name, group_config, group_start, _ in groups:
            named = offered[name] if hands is not None else None
            judges[name] = group_start or named or judge_for(models, group_config.env, None)
    if judges and all(
        judges.values()
    ):  # the whole piece, as play performs it: no phrase policy trained now makes it worse
        started = {name: {} for name in judges}
        for job, m in trained:
            if job in todo and m.get("kept") == "start":
                started[next(name for name, *_, jobs in groups if job in jobs)][job.folder.name] = m["evaluation"]["f1"]
        seeds = ", ".join(map(str, JUDGE_SEEDS))
        console.print(
            f"playing {said(song.name)} whole{' (both hands)' if hands is not None else ''} from hand starts {seeds}, "
            "as `pianobot play` does, to judge its phrase policies"
        )
        if hands is None:
            verdict = settle_piece(piece, phrases[None], models, judges[None], started[None], keyboard=keyboard)
        else:
            verdict = settle_hands(piece, parts, phrases, models, judges, started)
        before, after = sum(verdict.before) / len(JUDGE_SEEDS), sum(verdict.after) / len(JUDGE_SEEDS)
        console.print(
            f"{said(song.name)}: note F1 {before:.3f} with the general polic{'y' if hands is None else 'ies'} alone, "
            f"{after:.3f} as it plays now ("
            + (
                f"own policies for phrases {', '.join(map(str, verdict.used))}"
                if verdict.used
                else "no phrase policy of its own"
            )
            + ")"
        )
        if not verdict.used and after < 1.0 and all(m.get("kept") == "start" for job, m in trained if job in todo):
            console.print(
                "[yellow]every phrase played well enough from a fresh start, so none was trained; played whole, the "
                "hand goes on from where each phrase left it, which the phrase-by-phrase evaluation does not see[/yellow]",
                soft_wrap=True,
            )
        for number, why in verdict.dropped.items():
            console.print(f"[yellow]phrase {number}'s own policy is not used: {said(why)}[/yellow]")
    if json_path is not None:
        summary = [
            {
                "key": job.key,
                "phrases": job.phrases,
                "folder": str(job.folder),
                "trained_now": job in todo,
                **{k: manifest.get(k) for k in ("steps", "updates", "seconds", "start", "evaluation", "kept")},
                "log": str(job.folder / LOG_FILE),
                "plot": str(job.folder / PLOT_FILE),
            }
            for job, manifest in trained
        ]
        write_json(json_path, {"policies": summary, **({"piece": verdict.to_dict()} if verdict else {})})


def _hand_groups(
    piece,
    name: str,
    models: Path,
    base,
    general_policy,
    phrase_notes,
    keyboard,
    hand,
    networks_given: bool,
    keys_named: bool = False,
):
    """A two-hand piece's training, hand by hand: (each hand's part as ``play`` gives it to that hand
    (:func:`~pianobot.perform.hands.prepare_parts`), its phrases, the general policy ``play`` gives
    it, and the groups to train: (hand, config, start policy, jobs)). ``base``: the run's config
    before a start policy was picked. A phrase both hands play is one job, in the right hand's group."""
    from dataclasses import replace

    from pianobot.agent.general import find_general
    from pianobot.learn.jobs import general_start, phrase_jobs
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.hands import hand_players, prepare_parts

    parts = prepare_parts(
        piece, keyboard, hand, grow=not keys_named
    )  # (as play's default: wider parts on their own octaves)
    named = {"general_policy": general_policy} if general_policy is not None else {}
    players = hand_players(parts, "sac", models, hand, named)
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
        groups.append((side, config, start, jobs))
    return parts, phrases, offered, groups
