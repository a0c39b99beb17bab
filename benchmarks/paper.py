"""The paper's seven experiments (issue 21), each in two settings: the paper's recipe and ours;
and an eighth, which takes pianobot's additions away from its own setting one at a time.

    python benchmarks/paper.py EXPERIMENT [--setting paper|ours|both] [--seeds 3] [--steps N] [--workers 2]
    python benchmarks/paper.py EXPERIMENT --list       # the runs, how they differ, the CPU-hours they need
    python benchmarks/paper.py EXPERIMENT --report     # no training: tables and plots from the runs so far
    python benchmarks/paper.py EXPERIMENT --report --check   # and unfinished runs' best policies so far play

EXPERIMENT is a number or a name:

1 ``tasks``         one-note, three-note and six-note tasks; SAC with and without tactile images,
                    the scripted, idle and random controllers beside them (paper, figure "Comparison on
                    different levels of music tasks")
2 ``rhythm-chord``  the rhythmic and chord tasks (figure "Evaluation on tasks with different rhythms and chords")
3 ``rewards``       linear, squared and Wasserstein rewards (Table I)
4 ``exploration``   prior exploration, uniform moves of the hand, no action repeat (Table II)
5 ``control``       velocity against torque control (figure "Comparison of using torque control versus velocity control")
6 ``fingering``     with and without the fingering gate (figure "Qualitative results ... fingering indicators")
7 ``compose``       compositional execution against one end-to-end policy, pieces of growing length,
                    the same total steps (figure "Comparison between compositional execution ...")
8 ``additions``     not the paper's: pianobot's setting with one of its additions taken away at a
                    time (the teacher, the closeness bonus, the finger targets, its hyperparameters)

Settings: ``paper`` is the paper's recipe: plain SAC (no teacher), prior exploration, the linear
reward without our closeness bonus, the score window as observation (no finger targets), the
learning rate 1e-3 and SAC's own values where the paper gives none (:func:`setting_config`).
``ours`` is pianobot's defaults (:class:`~pianobot.learn.config.TrainConfig`). docs/paper.md
says what each choice rests on.

Every policy is trained by :func:`pianobot.learn.train.train_policy` (checkpointed: rerunning the
same command resumes every unfinished run), ``--workers`` at a time in worker processes with one
torch thread each. Runs with the same configuration (the paper setting's linear-reward,
velocity-control, gated run of experiments 3 to 6, say) share one model folder under
``--store`` and are trained once. Each kept policy is then evaluated with the paper's measure,
the accumulated *linear* reward (:data:`EVAL_REWARD`), whatever reward it trained with, plus
note F1, velocity error and fingering accuracy, on ``--check-episodes`` task instances it was
never evaluated on (a piece from as many hand starts, for ``compose``). ``--report`` prints
Markdown tables (mean ± standard deviation over seeds) and draws return and note F1 against
environment steps (the training evaluations, in the reward each run trained with) into
``--plots`` (docs/paper/), from finished and unfinished runs alike. Beside each plot it keeps the
records of every run it has seen (``N-name.json``), and tables those of them the store lacks (a
fresh clone, another machine) from there.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np

if str(Path(__file__).resolve().parent) not in sys.path:  # imported from the tests: find benchmarks/learn.py
    sys.path.append(str(Path(__file__).resolve().parent))

from learn import CHECK_SEED  # noqa: E402

from pianobot.agent import store  # noqa: E402
from pianobot.agent.config import SACConfig  # noqa: E402
from pianobot.agent.tasks import make_env  # noqa: E402
from pianobot.config import to_dict  # noqa: E402
from pianobot.env.piano import EnvConfig  # noqa: E402
from pianobot.env.rewards import RewardConfig  # noqa: E402
from pianobot.errors import PianobotError  # noqa: E402
from pianobot.files import atomic_write  # noqa: E402
from pianobot.learn.config import TrainConfig  # noqa: E402
from pianobot.learn.jobs import PhraseJob, phrase_jobs, task_job  # noqa: E402
from pianobot.learn.train import TASK_EVAL_EPISODES  # noqa: E402
from pianobot.music.load import LoadOptions, load_piece  # noqa: E402
from pianobot.music.phrases import DEFAULT_MAX_NOTES, phrase_hash, split_phrases  # noqa: E402
from pianobot.music.piece import Piece  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SETTINGS = ("paper", "ours")

# -- the paper's recipe ------------------------------------------------------------------------
PAPER_LEARNING_RATE = 1e-3
"""Paper, "Training": Adam with a learning rate of 1e-3 (ours: 3e-4)."""
PAPER_TASK_STEPS = 200_000
"""Paper, "Learning to Play the Piano": "reasonable returns after training 2e5 iterations"."""
SAC_DISCOUNT = 0.99
"""The paper gives no discount; SAC's own (Haarnoja et al., 2018). Ours: 0.9."""
SAC_TARGET_ENTROPY_SCALE = 1.0
"""The paper's "desired entropy" has no value; SAC's own is -1 x action dimensions. Ours: -2.5 x."""
ABLATION_TASK = "three-note"
"""The paper does not say which task its ablations (Tables I, II, the control and fingering
figures) ran on; the middle of its three task levels."""
ABLATION_STEPS = 100_000
"""Not stated for the ablations; our task-family budget (docs/benchmarks.md, "Task families")."""
PHRASE_STEPS = 60_000
"""``compose``: steps per phrase (not stated; the budget docs/benchmarks.md names for twinkle)."""
PAPER_BPM = 60.0
"""Paper, "Music Score Representation": "We freeze the tempo information to 60 beats per minute"."""

EVAL_REWARD = RewardConfig(kind="linear", fingering_gate=False, closeness_weight=0.0)
"""What every kept policy is judged by: the paper's eq. 1 with d = |.|, accumulated over an
episode, whatever reward the policy trained with (paper, Table I: "evaluated with the Linear
reward"): no fingering gate (fingering accuracy is reported on its own) and no closeness bonus."""
EVAL_FILE = "paper-eval.json"
"""A task run's evaluation, beside its policy."""
SO_FAR_DIR = "so-far"
"""Where ``--report --check`` keeps its judgements of unfinished runs' best policies so far
(one file per model folder, under ``--store``)."""
BASELINES = ("scripted", "idle", "random")
"""The controllers that play beside the trained arms: the scripted pianist, a hand that holds
still (``idle``, :class:`~pianobot.perform.controllers.IdleController`: what a policy that
presses nothing earns) and uniform random actions."""

# -- cost, from docs/benchmarks.md ("Trained phrase policies", last paragraph) --------------------
EXPLORE_MINUTES_PER_15K = 4.0
"""About 4 minutes for the 15k exploration steps (scripted pianist, tactile rendering, buffer)."""
LEARN_MINUTES_PER_10K = 10.0
"""About 10 minutes per further 10k steps with one update per step (about 17 updates/s with
tactile images, one core, another run beside it)."""


def run_minutes(steps: int, exploration_steps: int) -> float:
    """Estimated wall-clock minutes of one run on one core (the figures above; evaluations not counted)."""
    exploring = min(steps, exploration_steps)
    return EXPLORE_MINUTES_PER_15K * exploring / 15_000 + LEARN_MINUTES_PER_10K * (steps - exploring) / 10_000


# -- configurations -----------------------------------------------------------------------------
@dataclass(frozen=True)
class Options:
    """What the command line sets for every run of an experiment."""

    settings: tuple[str, ...] = SETTINGS
    seeds: int = 3
    steps: int | None = None
    """Per run (``compose``: per phrase); None: the experiment's default."""
    exploration_steps: int = SACConfig.exploration_steps
    eval_every: int = 5_000
    eval_episodes: int | None = None
    """None: 20 task instances (TASK_EVAL_EPISODES), or a phrase's 3 hand starts (``compose``)."""
    check_episodes: int | None = None
    """None: 30 fresh task instances, or 5 hand starts of the piece (``compose``)."""
    tasks: tuple[str, ...] | None = None
    """Instead of the experiment's tasks."""
    variants: tuple[str, ...] | None = None
    """Only these arms of the experiment (default: all)."""
    store: Path = ROOT / "out" / "paper"
    piece: Path = ROOT / "examples" / "midi" / "mary.mid"
    lengths: tuple[int, ...] = (1, 2, 3, 5)
    """``compose``: the pieces are the first N phrases of ``piece``."""
    tempo: float | None = PAPER_BPM
    stop_at: int | None = None
    """Train each run only to this many steps this time: it checkpoints and stops there, and the
    same command without it goes on to the full budget (a time box; None: the full budget)."""


def setting_config(setting: str, options: Options, seed: int, steps: int, eval_episodes: int) -> TrainConfig:
    """One run's configuration in a setting, before the experiment's variant changes it."""
    common = dict(
        steps=steps,
        seed=seed,
        eval_every=options.eval_every,
        eval_episodes=eval_episodes,
        checkpoint_every=options.eval_every,
        from_general=False,  # from scratch, to the budget (with it on, an F1 1.0 evaluation would end a run early)
    )
    if setting == "ours":
        return TrainConfig(**common, sac=SACConfig(exploration_steps=options.exploration_steps))
    if setting != "paper":
        raise ValueError(f"setting must be one of {', '.join(SETTINGS)}; got {setting!r}")
    return TrainConfig(
        **common,
        explore="prior",  # the paper's best exploration (Table II); no teacher
        sac=SACConfig(
            exploration_steps=options.exploration_steps,
            learning_rate=PAPER_LEARNING_RATE,
            discount=SAC_DISCOUNT,
            target_entropy_scale=SAC_TARGET_ENTROPY_SCALE,
            demo_weight=0.0,  # plain SAC: no behaviour cloning
            score_input=True,  # the paper's observation: the score ...
        ),
        env=EnvConfig(
            reward=RewardConfig(closeness_weight=0.0),  # the paper's reward, no closeness bonus
            target_observations=False,  # ... and not our finger targets
        ),
    )


def with_env(config: TrainConfig, **changes) -> TrainConfig:
    return replace(config, env=replace(config.env, **changes))


def with_reward(config: TrainConfig, **changes) -> TrainConfig:
    return with_env(config, reward=replace(config.env.reward, **changes))


def with_control(config: TrainConfig, control: str) -> TrainConfig:
    return with_env(config, world=replace(config.env.world, control=control))


@dataclass(frozen=True)
class Variant:
    """One arm of an experiment: its label, the paper's name for it, and how it changes a setting's configuration."""

    name: str
    change: Callable[[TrainConfig], TrainConfig]
    paper_name: str = ""
    settings: tuple[str, ...] = SETTINGS


def _same(config: TrainConfig) -> TrainConfig:
    return config


def _no_teacher(config: TrainConfig) -> TrainConfig:
    """The scripted pianist plays no torques: experiment 5 explores with the paper's prior in both settings."""
    return replace(config, explore="prior")


@dataclass(frozen=True)
class Experiment:
    number: int
    name: str
    title: str
    tasks: tuple[str, ...]
    variants: tuple[Variant, ...]
    steps: int
    steps_source: str
    adjust: Callable[[TrainConfig], TrainConfig] = _same
    """Applied to the ``ours`` setting before the variant (``control``: no teacher)."""
    baselines: tuple[str, ...] = ()
    fingering: bool = False
    """Report fingering accuracy."""


EXPERIMENTS = {
    e.name: e
    for e in (
        Experiment(
            1,
            "tasks",
            "Task levels",
            ("one-note", "three-note", "six-note"),
            (
                Variant("tactile", _same, "SAC with tactile"),
                Variant("no-tactile", lambda c: with_env(c, tactile=False), "SAC without tactile"),
            ),
            PAPER_TASK_STEPS,
            "paper: 2e5 iterations",
            baselines=BASELINES,
        ),
        Experiment(
            2,
            "rhythm-chord",
            "Rhythmic and chord tasks",
            ("rhythmic", "chord"),
            (Variant("tactile", _same, "SAC"),),
            PAPER_TASK_STEPS,
            "not stated; experiment 1's 2e5",
            baselines=BASELINES,
        ),
        Experiment(
            3,
            "rewards",
            "Rewards (Table I)",
            (ABLATION_TASK,),
            tuple(
                Variant(kind, lambda c, kind=kind: with_reward(c, kind=kind), kind.capitalize())
                for kind in ("linear", "squared", "wasserstein")
            ),
            ABLATION_STEPS,
            "not stated",
            baselines=BASELINES,
        ),
        Experiment(
            4,
            "exploration",
            "Exploration (Table II)",
            (ABLATION_TASK,),
            (
                Variant("prior", lambda c: replace(c, explore="prior"), "Prior Explore"),
                Variant("repeat", lambda c: replace(c, explore="repeat"), "Uniform Move Hand"),
                Variant("uniform", lambda c: replace(c, explore="uniform"), "No Action Repeat"),
                Variant("scripted", lambda c: replace(c, explore="scripted"), "(ours: the teacher)", ("ours",)),
            ),
            ABLATION_STEPS,
            "not stated",
            baselines=BASELINES,
        ),
        Experiment(
            5,
            "control",
            "Velocity against torque control",
            (ABLATION_TASK,),
            (
                Variant("velocity", lambda c: with_control(c, "velocity"), "velocity control"),
                Variant("torque", lambda c: with_control(c, "torque"), "torque control"),
            ),
            ABLATION_STEPS,
            "not stated",
            baselines=BASELINES,
            adjust=_no_teacher,
        ),
        Experiment(
            6,
            "fingering",
            "Fingering indicator",
            (ABLATION_TASK,),
            (
                Variant("gate", lambda c: with_reward(c, fingering_gate=True), "with fingering indicator"),
                Variant("no-gate", lambda c: with_reward(c, fingering_gate=False), "without fingering indicator"),
            ),
            ABLATION_STEPS,
            "not stated",
            baselines=BASELINES,
            fingering=True,
        ),
        Experiment(
            7,
            "compose",
            "Compositional against end-to-end",
            (),
            (Variant("compositional", _same, "compositional"), Variant("end-to-end", _same, "end-to-end RL")),
            PHRASE_STEPS,
            "not stated; per phrase",
        ),
        Experiment(
            8,
            "additions",
            "What pianobot's additions change",
            (ABLATION_TASK,),
            (
                Variant("ours", _same, "", ("ours",)),
                Variant("no-teacher", lambda c: replace(c, explore="prior"), "", ("ours",)),
                Variant("no-closeness", lambda c: with_reward(c, closeness_weight=0.0), "", ("ours",)),
                Variant(
                    "score-window",
                    lambda c: replace(with_env(c, target_observations=False), sac=replace(c.sac, score_input=True)),
                    "",
                    ("ours",),
                ),
                Variant(
                    "paper-hyperparameters",
                    lambda c: replace(
                        c,
                        sac=replace(
                            c.sac,
                            learning_rate=PAPER_LEARNING_RATE,
                            discount=SAC_DISCOUNT,
                            target_entropy_scale=SAC_TARGET_ENTROPY_SCALE,
                        ),
                    ),
                    "",
                    ("ours",),
                ),
            ),
            ABLATION_STEPS,
            "experiments 3-6's",
            baselines=BASELINES,
        ),
    )
}


def experiment_named(name: str) -> Experiment:
    for experiment in EXPERIMENTS.values():
        if name in (experiment.name, str(experiment.number)):
            return experiment
    known = ", ".join(f"{e.number} {e.name}" for e in EXPERIMENTS.values())
    raise PianobotError(f"no experiment {name!r}: choose one of {known}")


@dataclass(frozen=True)
class Run:
    """One trained arm for one seed: the policies it trains (one job for a task; one per phrase
    for compositional execution), and how it is evaluated."""

    experiment: str
    setting: str
    task: str
    """The task family, or (``compose``) which piece: "N phrases"."""
    variant: str
    seed: int
    config: TrainConfig
    jobs: tuple[PhraseJob, ...]
    result: Path
    """Where its evaluation (JSON) goes."""
    piece: Piece | None = None
    """``compose``: the whole piece the run plays ..."""
    phrase_notes: int = DEFAULT_MAX_NOTES
    """... split into phrases of at most this many notes (end-to-end: the whole piece, one phrase)."""

    @property
    def label(self) -> str:
        return f"{self.experiment} {self.setting} {self.task} {self.variant} seed {self.seed}"

    @property
    def group(self) -> tuple[str, str, str]:
        return self.setting, self.task, self.variant


def expand(name: str, options: Options = Options()) -> list[Run]:
    """Every run of an experiment, in the settings and seeds ``options`` asks for."""
    experiment = experiment_named(name)
    names = [variant.name for variant in experiment.variants]
    for variant in options.variants or ():
        if variant not in names:
            raise PianobotError(f"{experiment.name} has no arm {variant!r}: choose from {', '.join(names)}")
    if experiment.name == "compose":
        return _compose_runs(experiment, options)
    steps = options.steps or experiment.steps
    episodes = options.eval_episodes or TASK_EVAL_EPISODES
    root = options.store / "runs"  # shared by every experiment: equal configurations train once
    runs = []
    for setting in options.settings:
        for task in options.tasks or experiment.tasks:
            for variant in experiment.variants:
                if setting not in variant.settings or not wanted(variant, options):
                    continue
                for seed in range(options.seeds):
                    config = setting_config(setting, options, seed, steps, episodes)
                    if setting == "ours":
                        config = experiment.adjust(config)
                    config = variant.change(config)
                    job = task_job(task, config, root)
                    runs.append(
                        Run(experiment.name, setting, task, variant.name, seed, config, (job,), job.folder / EVAL_FILE)
                    )
    return runs


def wanted(variant: Variant, options: Options) -> bool:
    return options.variants is None or variant.name in options.variants


def compose_pieces(options: Options) -> list[tuple[int, Piece]]:
    """``compose``'s pieces: the first N phrases of ``options.piece`` for each N of ``options.lengths``."""
    whole = load_piece(options.piece, LoadOptions(tempo=options.tempo))
    phrases = split_phrases(whole)
    pieces = []
    for length in options.lengths:
        if not 1 <= length <= len(phrases):
            raise PianobotError(f"--lengths {length}: {options.piece} has {len(phrases)} phrases")
        notes = tuple(note for phrase in phrases[:length] for note in phrase.notes)
        pieces.append((length, Piece(notes, bpm=whole.bpm).shift(-notes[0].onset)))
    return pieces


def _compose_runs(experiment: Experiment, options: Options) -> list[Run]:
    """Compositional: one policy per phrase of the piece (``steps`` each). End-to-end: one policy
    on the whole piece, a "phrase" as long as the piece, with as many steps as all the phrase
    policies together. The phrase policies of a seed and setting share one model folder, so a
    phrase that two pieces share is trained once (the piece of one phrase is its own end-to-end run)."""
    steps = options.steps or experiment.steps
    episodes = options.eval_episodes or TrainConfig.eval_episodes
    runs = []
    for setting in options.settings:
        for seed in range(options.seeds):
            config = setting_config(setting, options, seed, steps, episodes)
            root = options.store / "compose" / setting / f"{options.piece.stem}-{store.config_hash(config)}"
            for length, piece in compose_pieces(options):
                task, about = f"{length} phrase{'s' if length > 1 else ''}", piece_label(options, length)
                parts = tuple(phrase_jobs(split_phrases(piece), config, root, piece=about))
                whole = replace(config, steps=steps * len(parts))  # the same total steps
                single = tuple(phrase_jobs(split_phrases(piece, len(piece)), whole, root, piece=about))
                notes = phrase_hash(piece.notes)  # another piece or tempo: another result
                arms = (
                    Run(experiment.name, setting, task, "compositional", seed, config, parts,
                        root / f"compositional-{length}-{notes}.json", piece),
                    Run(experiment.name, setting, task, "end-to-end", seed, whole, single,
                        root / f"end-to-end-{length}-{notes}.json", piece, len(piece)),
                )  # fmt: skip
                runs += [run for run in arms if options.variants is None or run.variant in options.variants]
    return runs


def piece_label(options: Options, length: int) -> str:
    return f"{options.piece.name}, first {length} phrases"


# -- training -----------------------------------------------------------------------------------
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
    ready = [run for run in runs if trained(run) and not _evaluated(run, options)]
    print(f"{len(runs)} runs, {len(jobs)} policies: {len(todo)} to train, {len(ready)} runs to evaluate", flush=True)
    if workers <= 1:
        for job, config, label in todo:
            train_job(job, config, label, options.stop_at)
        for run in runs:
            if trained(run) and not _evaluated(run, options):
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
                if run.result not in evaluated and trained(run) and not _evaluated(run, options):
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


# -- evaluation ---------------------------------------------------------------------------------
def eval_env_config(config: EnvConfig) -> EnvConfig:
    """The environment a policy trained in ``config`` is judged in: the same, with the linear reward."""
    return replace(config, reward=EVAL_REWARD)


def play_instances(factory, target: Piece | str, env_config: EnvConfig, episodes: int, first_seed: int) -> dict:
    """``factory(env)`` makes a controller that plays ``episodes`` episodes of ``target`` (task
    instances or hand starts, seeds ``first_seed``, ...) with the linear reward: each figure's mean."""
    from pianobot.perform.rollout import rollout

    env = make_env(target, eval_env_config(env_config))
    try:
        controller = factory(env)
        episodes_played = [rollout(env, controller, seed=first_seed + i) for i in range(episodes)]
    finally:
        env.close()
    return _figures([(e.total_reward, e.report()) for e in episodes_played])


def _figures(played: list) -> dict:
    def mean(values):
        values = [v for v in values if v is not None]
        return float(np.mean(values)) if values else None

    return {
        "episodes": len(played),
        "return": mean(r for r, _ in played),
        "f1": mean(report.f1 for _, report in played),
        "velocity_mae": mean(report.velocity_mae for _, report in played),
        "fingering_accuracy": mean(report.fingering_accuracy for _, report in played),
    }


def check_episodes(run: Run, options: Options) -> int:
    if options.check_episodes is not None:
        return options.check_episodes
    return 5 if run.piece is not None else 30


def _evaluated(run: Run, options: Options) -> bool:
    found = _read_json(run.result)
    return found is not None and found.get("episodes") == check_episodes(run, options)


def evaluate_run(run: Run, options: Options) -> dict:
    """Judge a finished run's kept policy (or, ``compose``, its policies playing the whole piece)
    with the linear reward; written to ``run.result``."""
    import torch

    from pianobot.agent.policy import load_policy

    torch.set_num_threads(1)
    episodes = check_episodes(run, options)
    if run.piece is None:
        folder = run.jobs[0].folder
        figures = play_instances(lambda env: load_policy(folder, env), run.task, run.config.env, episodes, CHECK_SEED)
    else:
        figures = perform_piece(run, episodes)
    manifests = [store.read_manifest(job.folder) for job in run.jobs]
    figures = {
        **figures,
        "reward": to_dict(EVAL_REWARD),
        "trained_steps": sum(m["steps"] for m in manifests),
        "seconds": sum(m["seconds"] for m in manifests),
        "kept_steps": [m["evaluation"]["step"] for m in manifests],
    }
    atomic_write(run.result, json.dumps(figures) + "\n")
    return figures


def perform_piece(run: Run, hand_starts: int) -> dict:
    """``compose``: the run's phrase policies (or its one end-to-end policy) play the whole piece
    in one continuous simulation, as `pianobot play` does, with the linear reward."""
    from pianobot.perform.compose import CompositionalController
    from pianobot.perform.perform import perform

    phrases = split_phrases(run.piece, run.phrase_notes)
    models = run.jobs[0].folder.parent
    config = eval_env_config(run.config.env)
    played = []
    for seed in range(hand_starts):
        episode = perform(
            run.piece, lambda env: CompositionalController(env, phrases, models, fallback=False), config, seed=seed
        )
        played.append((episode.total_reward, episode.report()))
    return _figures(played)


def baseline_figures(controller: str, task: str, seed: int, options: Options) -> dict:
    """A baseline controller (:data:`BASELINES`) on the task's check instances, cached."""
    path = options.store / "baselines" / f"{task}-{controller}-seed{seed}.json"
    episodes = options.check_episodes or 30
    found = _read_json(path)
    if found is not None and found.get("episodes") == episodes:
        return found
    from pianobot.perform.controllers import make_controller

    env_config = EnvConfig(tactile=False)  # none reads touch; the reward is EVAL_REWARD either way
    figures = play_instances(lambda env: make_controller(controller, env, seed), task, env_config, episodes, CHECK_SEED)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, json.dumps(figures) + "\n")
    return figures


def best_so_far(run: Run, options: Options) -> dict | None:
    """An unfinished task run's best policy so far (from its checkpoint), judged as a finished
    one is; None when it has none yet. The figures are kept under ``store/so-far/`` (outside
    the model folder, which its training process owns) and judged again only when the kept
    policy (its whole evaluation record) or how it is judged changes."""
    if run.piece is not None:
        return None
    folder = run.jobs[0].folder
    state = store.checkpoint_state(folder)
    if state is None or state.get("best") is None:
        return None
    judging = {"episodes": check_episodes(run, options), "first_seed": CHECK_SEED, "reward": to_dict(EVAL_REWARD)}
    path = options.store / SO_FAR_DIR / f"{folder.name}.json"
    cached = _read_json(path)
    if cached is not None and cached.get("best") == state["best"] and cached.get("judging") == judging:
        return cached
    import torch

    from pianobot.agent.policy import make_agent
    from pianobot.learn.train import best_policy_tensors

    torch.set_num_threads(1)
    found = store.load_checkpoint(folder)
    if found is None or found[1].get("best") is None:
        return None
    tensors, best = best_policy_tensors(found[0]), found[1]["best"]

    def factory(env):
        agent = make_agent(env, run.config.sac)
        agent.load_tensors(tensors, with_training_state=False)
        return agent

    figures = play_instances(factory, run.task, run.config.env, judging["episodes"], CHECK_SEED)
    figures = {**figures, "kept_steps": [best["step"]], "so_far": True, "best": best, "judging": judging}
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, json.dumps(figures) + "\n")
    return figures


def _read_json(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None


def _print_evaluation(run: Run, figures: dict) -> None:
    print(
        f"{run.label}: linear return {figures['return']:.2f}, note F1 {figures['f1']:.3f} "
        f"({figures['episodes']} episodes)",
        flush=True,
    )


# -- report -------------------------------------------------------------------------------------
@dataclass
class Progress:
    """What one run has so far."""

    run: Run
    state: str
    """'not started', 'at N steps', 'finished'."""
    steps: int = 0
    curves: list[list[dict]] = field(default_factory=list)
    """Each policy's training evaluations (step, f1, return in the training reward)."""
    figures: dict | None = None
    """The linear-reward evaluation (finished runs; unfinished ones with --check)."""
    seconds: dict[str, float] = field(default_factory=dict)
    """Each policy's training time so far, by its model folder (relative to the store)."""
    recorded: bool = False
    """Read from the experiment's records (:func:`records_path`), not from the store."""


def progress(run: Run, options: Options, check: bool = False) -> Progress:
    curves, steps, seconds, started, finished = [], 0, {}, False, True
    for job in run.jobs:
        name = job.folder.relative_to(options.store).as_posix()
        if store.is_trained(job.folder):
            manifest = store.read_manifest(job.folder)
            curves.append(manifest["evaluations"])
            steps += manifest["steps"]
            seconds[name] = manifest["seconds"]
            started = True
            continue
        finished = False
        state = store.checkpoint_state(job.folder)
        if state is not None:
            curves.append(state["evaluations"])
            steps += state["step"]
            seconds[name] = state.get("seconds", 0.0)
            started = True
    if finished:  # judged now if the training command was cut off before it judged the run
        figures = _read_json(run.result) if _evaluated(run, options) else evaluate_run(run, options)
        return Progress(run, "finished", steps, curves, figures, seconds)
    if not started:
        return Progress(run, "not started")
    figures = best_so_far(run, options) if check else None
    return Progress(run, f"at {_steps(steps)} steps", steps, curves, figures, seconds)


# -- records: what the report saw, kept beside its plot -------------------------------------------
def records_path(experiment: Experiment, plots: Path) -> Path:
    """``N-name.json`` beside the plot: every run the experiment's reports have seen (its state,
    steps, training time, training evaluations and judged figures), so that a report on another
    machine, or after the store is gone, still tables and plots them. Checkpoints and policies
    stay in the store: a recorded run can be reported, not resumed or judged again."""
    return plots / f"{experiment.number}-{experiment.name}.json"


def record_key(run: Run, options: Options) -> str:
    """A run's name in the records: where its evaluation goes, relative to the store (the name
    holds the configuration's hash, and for ``compose`` the piece's, so another configuration or
    piece is another run)."""
    return run.result.relative_to(options.store).as_posix()


RECORD_FIELDS = ("label", "state", "steps", "seconds", "curves", "figures")


def read_records(path: Path) -> dict[str, dict]:
    """The records in ``path`` (none if it does not exist). A file that is there but cannot be
    read stops the report, which would otherwise write the store's runs over it."""
    if not path.exists():
        return {}
    try:
        runs = json.loads(path.read_text())["runs"]
        if not all(set(RECORD_FIELDS) <= record.keys() for record in runs.values()):
            raise ValueError
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        raise PianobotError(
            f"{path} is not a records file this report can read (a merge conflict?): "
            "mend it from git, or move it away to start new records"
        ) from None
    return runs


def _rank(state: str, steps: int, figures: dict | None) -> tuple:
    """How far along a run is: finished first, then more steps, then judged on more episodes."""
    return state == "finished", steps, (figures or {}).get("episodes", 0)


def with_records(found: list[Progress], records: dict[str, dict], options: Options, check: bool) -> list[Progress]:
    """The runs the store lacks, as the records have them (the store's own are its). A recorded
    judgement counts only if it was judged as this report judges (the same number of episodes)
    and, for an unfinished run's best policy so far, only with ``--check``."""
    out = []
    for p in found:
        kept = records.get(record_key(p.run, options))
        if p.state == "not started" and kept is not None:
            figures = kept["figures"]
            if figures is not None and (
                figures.get("episodes") != check_episodes(p.run, options) or (figures.get("so_far") and not check)
            ):
                figures = None
            p = Progress(p.run, kept["state"], kept["steps"], kept["curves"], figures, kept["seconds"], recorded=True)
        out.append(p)
    return out


def write_records(path: Path, records: dict[str, dict], found: list[Progress], options: Options) -> None:
    """The records updated with the runs this report read from the store, where the store has
    the run at least as far along as the record (a run started afresh, or judged on fewer
    episodes, does not replace what was recorded); the other records kept."""
    for p in found:
        if p.recorded or p.state == "not started":
            continue
        key = record_key(p.run, options)
        kept = records.get(key)
        if kept is not None and _rank(p.state, p.steps, p.figures) < _rank(
            kept["state"], kept["steps"], kept["figures"]
        ):
            continue
        records[key] = {
            "label": p.run.label,
            "state": p.state,
            "steps": p.steps,
            "seconds": p.seconds,
            "curves": p.curves,
            "figures": p.figures,
        }
    if not records:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, json.dumps({"runs": records}, indent=1, sort_keys=True) + "\n")


def mean_std(values: list[float], digits: int = 2) -> str:
    """Mean ± standard deviation (NumPy's, over the values given: 0 for one value)."""
    values = [v for v in values if v is not None]
    if not values:
        return "—"
    return f"{np.mean(values):.{digits}f} ± {np.std(values):.{digits}f}"


def _steps(steps: float) -> str:
    return f"{steps / 1000:.0f}k" if steps >= 10_000 else f"{steps:.0f}"


def table(experiment: Experiment, found: list[Progress], baselines: dict | None = None) -> str:
    """A Markdown table: one row per setting, task and variant, mean ± standard deviation over seeds."""
    fingering = experiment.fingering
    head = "| setting | task | variant | seeds judged / finished / started / planned | steps (mean) | linear return | note F1 | velocity MAE"
    head += " | fingering accuracy |" if fingering else " |"
    head += " latest training evaluation: note F1 |"
    lines = [head, "| " + " | ".join(["---"] * (head.count("|") - 1)) + " |"]
    groups: dict[tuple, list[Progress]] = {}
    for p in found:
        groups.setdefault(p.run.group, []).append(p)
    for (setting, task, variant), members in groups.items():
        judged = [p.figures for p in members if p.figures is not None]
        started = [p for p in members if p.state != "not started"]
        finished = [p for p in members if p.state == "finished"]
        latest = [np.mean([c[-1]["f1"] for c in p.curves if c]) for p in started if any(p.curves)]
        cells = [
            setting,
            task,
            variant,
            f"{len(judged)} / {len(finished)} / {len(started)} / {len(members)}",
            _steps(np.mean([p.steps for p in started])) if started else "—",
            mean_std([f["return"] for f in judged]),
            mean_std([f["f1"] for f in judged], 3),
            mean_std([f["velocity_mae"] for f in judged], 1),
        ]
        if fingering:
            cells.append(mean_std([f["fingering_accuracy"] for f in judged], 3))
        cells.append(mean_std(latest, 3))
        lines.append("| " + " | ".join(cells) + " |")
    for (task, controller), figures in (baselines or {}).items():
        cells = ["—", task, f"{controller} controller", f"{len(figures)} / — / — / —", "—"]
        cells += [mean_std([f["return"] for f in figures]), mean_std([f["f1"] for f in figures], 3)]
        cells += [mean_std([f["velocity_mae"] for f in figures], 1)]
        cells += [mean_std([f["fingering_accuracy"] for f in figures], 3)] if fingering else []
        cells.append("—")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def by_seed(found: list[Progress]) -> str:
    """Each row's judged note F1 seed by seed (the figures behind the table's mean ± std)."""
    groups: dict[tuple, list[Progress]] = {}
    for p in found:
        if p.figures is not None:
            groups.setdefault(p.run.group, []).append(p)
    return "\n".join(
        f"- {' '.join(group)}: " + ", ".join(f"seed {p.run.seed} {p.figures['f1']:.3f}{_so_far(p)}" for p in members)
        for group, members in groups.items()
    )


def _so_far(p: Progress) -> str:
    return f" (so far: best at {p.figures['kept_steps'][0]} steps)" if p.figures.get("so_far") else ""


def report(experiment: Experiment, runs: list[Run], options: Options, plots: Path | None, check: bool) -> str:
    """The tables (and plot) of an experiment from its runs so far, in the store or in the
    records beside the plot (which it then updates); trains nothing."""
    found = [progress(run, options, check) for run in runs]
    if plots is not None:
        records = read_records(records_path(experiment, plots))
        found = with_records(found, records, options, check)
        write_records(records_path(experiment, plots), records, found, options)
    baselines = {}
    for task in options.tasks or experiment.tasks:
        for controller in experiment.baselines:
            baselines[task, controller] = [
                baseline_figures(controller, task, seed, options) for seed in range(options.seeds)
            ]
    text = (
        f"{experiment.number}. {experiment.title}: judged with the linear reward on "
        f"{check_episodes(runs[0], options) if runs else 0} "
        f"{'hand starts of the piece' if experiment.name == 'compose' else 'fresh task instances'}; "
        "mean ± standard deviation over seeds\n\n" + table(experiment, found, baselines)
    )
    seeds = by_seed(found)
    if seeds:
        text += "\n\nnote F1 by seed:\n" + seeds
    hours, policies = training_hours(found)
    text += (
        f"\n\ntraining so far: {hours:.1f} CPU-hours, {policies} polic{'y' if policies == 1 else 'ies'} (each on one core; "
        "a policy that several experiments share counts in each)"
    )
    recorded = [p for p in found if p.recorded]
    if recorded:
        text += (
            f"\n\nfrom the records ({records_path(experiment, plots)}), not in the store "
            f"{options.store}: {len(recorded)} run{'s' if len(recorded) > 1 else ''}"
        )
    unfinished = [p for p in found if p.state.startswith("at ")]
    if unfinished:
        text += "\n\nunfinished: " + ", ".join(f"{p.run.label} ({p.state})" for p in unfinished)
        if check:
            text += "\n(their rows' judged figures include their best policies so far)"
    if plots is not None and any(p.curves for p in found):
        text += f"\n\nplot: {plot(experiment, found, baselines, plots)}"
    return text


def training_hours(found: list[Progress]) -> tuple[float, int]:
    """The training time so far of the runs' distinct policies, in hours (the manifests' seconds,
    or the newest checkpoint's for an unfinished policy), and how many have begun."""
    seconds: dict[str, float] = {}
    for p in found:
        for folder, spent in p.seconds.items():  # a policy two runs share counts once
            seconds[folder] = max(spent, seconds.get(folder, 0.0))
    return sum(seconds.values()) / 3600, len(seconds)


def _binned(curves: list[list[dict]], key: str, every: int) -> tuple[list[int], list[float], list[float]]:
    """Mean and standard deviation over runs at each evaluation (steps rounded to ``every``)."""
    at: dict[int, list[float]] = {}
    for curve in curves:
        for point in curve:
            if point.get(key) is not None:
                at.setdefault(round(point["step"] / every) * every, []).append(point[key])
    steps = sorted(at)
    return steps, [float(np.mean(at[s])) for s in steps], [float(np.std(at[s])) for s in steps]


def plot(experiment: Experiment, found: list[Progress], baselines: dict, folder: Path) -> Path:
    """Return and note F1 against environment steps (``compose``: against the piece's length),
    one row per setting, mean and one standard deviation over seeds; a colour per task (per
    variant when there is one task), a line style per variant; the baselines as level lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    settings = [s for s in SETTINGS if any(p.run.setting == s and p.curves for p in found)]  # a row per setting run
    fig, axes = plt.subplots(len(settings), 2, figsize=(11, 3.6 * len(settings)), squeeze=False)
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    tasks = list(dict.fromkeys(p.run.task for p in found))
    variants = list(dict.fromkeys(p.run.variant for p in found))
    by_task = len(tasks) > 1 and experiment.name != "compose"

    def style(task: str, variant: str) -> dict:
        if by_task:
            return dict(
                color=cycle[tasks.index(task) % len(cycle)],
                linestyle=("-", "--", "-.", ":")[variants.index(variant) % 4],
            )
        return dict(color=cycle[variants.index(variant) % len(cycle)], linestyle="-")

    for row, setting in zip(axes, settings):
        mine = [p for p in found if p.run.setting == setting]
        if experiment.name == "compose":
            _plot_lengths(row, mine, style)
        else:
            _plot_curves(row, mine, style)
        for (task, controller), figures in baselines.items():
            look = {"scripted": ":", "idle": (0, (1, 4)), "random": "-."}[controller]
            level = dict(color=style(task, variants[0])["color"], linestyle=look)
            row[1].axhline(np.mean([f["f1"] for f in figures]), linewidth=1, **level, label=f"{task}, {controller}")
            if setting == "paper":  # its training reward is the linear one (gated: the baselines' fingers pass)
                row[0].axhline(np.mean([f["return"] for f in figures]), linewidth=1, **level)
        row[0].set_title(f"{setting} setting: return")
        row[1].set_title(f"{setting} setting: note F1")
        row[1].set_ylim(-0.02, 1.02)
        for ax in row:
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
    fig.suptitle(f"{experiment.number}. {experiment.title}")
    fig.tight_layout()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{experiment.number}-{experiment.name}.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _plot_curves(row, found: list[Progress], style) -> None:
    groups: dict[tuple, list[Progress]] = {}
    for p in found:
        groups.setdefault(p.run.group, []).append(p)
    for (_, task, variant), members in groups.items():
        curves = [c for p in members for c in p.curves if c]
        if not curves:
            continue
        every = members[0].run.config.eval_every
        look = style(task, variant)
        for ax, key in zip(row, ("return", "f1")):
            steps, mean, std = _binned(curves, key, every)
            label = f"{task}, {variant}, n={len(curves)}" if key == "return" else None
            ax.plot(steps, mean, marker=".", label=label, **look)
            ax.fill_between(steps, np.subtract(mean, std), np.add(mean, std), color=look["color"], alpha=0.15)
            ax.set_xlabel("environment steps")
    row[0].set_ylabel("evaluation return\n(in the reward trained with)")
    row[1].set_ylabel("evaluation note F1")


def _plot_lengths(row, found: list[Progress], style) -> None:
    for variant in ("compositional", "end-to-end"):
        by_length: dict[int, list[dict]] = {}
        for p in found:
            if p.run.variant == variant and p.figures is not None:
                by_length.setdefault(len(p.run.piece), []).append(p.figures)
        lengths = sorted(by_length)
        for ax, key in zip(row, ("return", "f1")):
            values = [[f[key] for f in by_length[n]] for n in lengths]
            ax.errorbar(
                lengths,
                [np.mean(v) for v in values],
                yerr=[np.std(v) for v in values],
                marker="o",
                capsize=3,
                label=variant if key == "return" else None,
                **style("", variant),
            )
            ax.set_xlabel("notes in the piece")
    row[0].set_ylabel("linear return, whole piece")
    row[1].set_ylabel("note F1, whole piece")


# -- listing ------------------------------------------------------------------------------------
def _flat(data: dict, prefix: str = "") -> dict:
    out = {}
    for key, value in data.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def differences(config: TrainConfig, than: TrainConfig) -> dict:
    """The fields (dotted paths) where ``config`` differs from ``than``."""
    mine, theirs = _flat(to_dict(config)), _flat(to_dict(than))
    return {k: v for k, v in mine.items() if theirs.get(k) != v}


def listing(experiment: Experiment, runs: list[Run]) -> str:
    """Every run, what it changes from pianobot's defaults, and the CPU-hours the training needs."""
    lines = ["| setting | task | variant | seed | steps | policies | differs from pianobot's defaults |"]
    lines.append("| --- | --- | --- | ---: | ---: | ---: | --- |")
    for run in runs:
        base = TrainConfig(
            steps=run.config.steps,
            seed=run.seed,
            eval_every=run.config.eval_every,
            eval_episodes=run.config.eval_episodes,
            checkpoint_every=run.config.checkpoint_every,
            sac=SACConfig(exploration_steps=run.config.sac.exploration_steps),
        )
        changed = ", ".join(f"{k}={v}" for k, v in differences(run.config, base).items()) or "—"
        lines.append(
            f"| {run.setting} | {run.task} | {run.variant} | {run.seed} | {run.config.steps} | {len(run.jobs)} | {changed} |"
        )
    hours, policies = estimate(runs)
    lines.append(
        f"\n{len(runs)} runs, {policies} policies to train (equal configurations once): about {hours:.0f} CPU-hours "
        "of training, estimated from docs/benchmarks.md's 4 minutes per 15k exploration steps and 10 minutes per "
        "further 10k learning steps (tactile images, one core); evaluations not counted"
    )
    return "\n".join(lines)


def estimate(runs: list[Run]) -> tuple[float, int]:
    """Estimated CPU-hours to train every distinct policy of ``runs``, and how many there are."""
    policies = {}
    for run in runs:
        for job in run.jobs:
            policies[job.folder] = run_minutes(run.config.steps, run.config.sac.exploration_steps)
    return sum(policies.values()) / 60, len(policies)


# -- command line -------------------------------------------------------------------------------
def parse(argv: list[str] | None = None) -> tuple[argparse.Namespace, Options]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "experiment", help="1-8 or tasks, rhythm-chord, rewards, exploration, control, fingering, compose, additions"
    )
    parser.add_argument("--setting", choices=(*SETTINGS, "both"), default="both")
    parser.add_argument("--seeds", type=int, default=Options.seeds, help="seeds 0 .. N-1 (the paper used 5)")
    parser.add_argument(
        "--steps", type=int, default=None, help="steps per run (compose: per phrase); default: the experiment's"
    )
    parser.add_argument("--exploration-steps", type=int, default=Options.exploration_steps)
    parser.add_argument("--eval-every", type=int, default=Options.eval_every)
    parser.add_argument("--eval-episodes", type=int, default=None, help="training evaluations' episodes")
    parser.add_argument("--check-episodes", type=int, default=None, help="episodes of the linear-reward judgement")
    parser.add_argument("--tasks", nargs="+", default=None, help="instead of the experiment's tasks")
    parser.add_argument("--variants", nargs="+", default=None, help="only these arms (default: all)")
    parser.add_argument("--piece", type=Path, default=Options.piece, help="compose: the piece")
    parser.add_argument(
        "--lengths", nargs="+", type=int, default=list(Options.lengths), help="compose: first N phrases"
    )
    parser.add_argument("--tempo", type=float, default=Options.tempo, help="compose: re-time the piece (bpm)")
    parser.add_argument(
        "--stop-at",
        type=int,
        default=None,
        help="train each run only to this many steps this time (it checkpoints there; rerun without it to go on); "
        "--report --check then judges each run's best policy so far",
    )
    parser.add_argument("--workers", type=int, default=1, help="runs in parallel, one torch thread each")
    parser.add_argument("--store", type=Path, default=Options.store)
    parser.add_argument(
        "--plots",
        type=Path,
        default=ROOT / "docs" / "paper",
        help="where --report draws N-name.png and keeps N-name.json, the records of every run it has seen",
    )
    parser.add_argument("--report", action="store_true", help="train nothing: tables and plots of the runs so far")
    parser.add_argument(
        "--check", action="store_true", help="with --report: judge unfinished runs' best policies so far"
    )
    parser.add_argument("--list", action="store_true", help="train nothing: the runs and the CPU-hours they need")
    args = parser.parse_args(argv)
    for name in ("seeds", "workers", "check_episodes", "eval_episodes", "steps", "stop_at"):
        if getattr(args, name) is not None and getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1")
    if args.stop_at is not None and args.stop_at % args.eval_every:
        parser.error(f"--stop-at must be a multiple of --eval-every ({args.eval_every}): runs checkpoint only there")
    options = Options(
        settings=SETTINGS if args.setting == "both" else (args.setting,),
        seeds=args.seeds,
        steps=args.steps,
        exploration_steps=args.exploration_steps,
        eval_every=args.eval_every,
        eval_episodes=args.eval_episodes,
        check_episodes=args.check_episodes,
        tasks=tuple(args.tasks) if args.tasks else None,
        variants=tuple(args.variants) if args.variants else None,
        store=args.store,
        piece=args.piece,
        lengths=tuple(args.lengths),
        tempo=args.tempo,
        stop_at=args.stop_at,
    )
    return args, options


def main(argv: list[str] | None = None) -> None:
    args, options = parse(argv)
    try:
        experiment = experiment_named(args.experiment)
        runs = expand(experiment.name, options)
        if not args.list:  # before any training: its closing report writes them
            read_records(records_path(experiment, args.plots))
    except (PianobotError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        raise SystemExit(2) from None
    if args.list:
        print(listing(experiment, runs))
    elif args.report:
        print(report(experiment, runs, options, args.plots, args.check))
    else:
        execute(runs, options, args.workers)
        print()
        print(report(experiment, runs, options, args.plots, check=False))


if __name__ == "__main__":
    main()
