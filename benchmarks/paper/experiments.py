"""The experiments table: the paper's recipe (its constants, the ``paper`` and ``ours``
settings), each experiment's arms, and the command line's options for every run."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

from pianobot.agent.config import SACConfig
from pianobot.env.piano import EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig

ROOT = Path(__file__).resolve().parents[2]
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
    """One of the paper's seven experiments: what it trains, its arms, and the budget each run gets."""

    number: int
    """The paper's numbering (docs/paper/N-name.json keeps its records)."""
    name: str
    """What ``python -m benchmarks.paper`` calls it (``tasks``, ``rewards``, ...)."""
    title: str
    """The section's title in docs/paper.md."""
    tasks: tuple[str, ...]
    """Task families (or ``compose``'s piece) each arm trains on."""
    variants: tuple[Variant, ...]
    """The arms, each a change to a setting's configuration."""
    steps: int
    """Environment steps per run."""
    steps_source: str
    """Where that budget comes from (the paper's figure, or why ours differs)."""
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
        Experiment(
            9,
            "diagnosis",
            "Why plain SAC does not learn here",
            ("one-note",),
            (
                Variant("paper", lambda c: with_env(c, tactile=False), "", ("paper",)),
                Variant("one-joint", lambda c: with_env(c, tactile=False, actuated=("mcp",)), "", ("paper",)),
                Variant(
                    "no-gate",
                    lambda c: with_reward(with_env(c, tactile=False), fingering_gate=False),
                    "",
                    ("paper",),
                ),
                Variant(
                    "scripted-exploration",
                    lambda c: replace(with_env(c, tactile=False), explore="scripted"),
                    "",
                    ("paper",),
                ),
                Variant(
                    "our-hyperparameters",
                    lambda c: replace(
                        with_env(c, tactile=False),
                        sac=replace(
                            c.sac,
                            learning_rate=SACConfig.learning_rate,
                            discount=SACConfig.discount,
                            target_entropy_scale=SACConfig.target_entropy_scale,
                        ),
                    ),
                    "",
                    ("paper",),
                ),
            ),
            PAPER_TASK_STEPS,
            "experiment 1's 2e5, run time-boxed (--stop-at)",
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
