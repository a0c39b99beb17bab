"""The options of `pianobot train` and their help (the command itself: :mod:`pianobot.cli.commands.train`).

Every default is its config dataclass's (:class:`~pianobot.learn.config.TrainConfig`,
:class:`~pianobot.learn.config.DaggerConfig`, ...)."""

from __future__ import annotations

import typer

from pianobot.agent.config import ACTORS, SACConfig
from pianobot.env.piano import EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.learn.config import DaggerConfig, TrainConfig
from pianobot.learn.explore import EXPLORATIONS
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.tasks import GIVEN_SHARE, MELODY, PARTS, TASKS
from pianobot.sim.world import WorldConfig

SONG_OPTION = typer.Argument(
    None,
    help="A .mid file or MusicXML score with fingering (a two-hand file, as play plays it: each hand's part); leave out with --task.",
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
DAGGER_HOLD_GUARD_OPTION = typer.Option(
    DaggerConfig.hold_guard,
    "--dagger-hold-guard",
    help="With --learner dagger: the policy plays its episodes through the hold guard, as `play` plays a general "
    "policy of hands' parts (needs policies that observe their finger targets, e.g. --task parts).",
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
FINISH_OPTION = typer.Option(
    TrainConfig.finish,
    "--finish",
    help="End interrupted runs at their checkpoints instead of training on: each stores the best policy it "
    "evaluated so far, its manifest saying the steps it took (give the interrupted command's other options). "
    "A run without a checkpoint (said), or one cut before its first learning step, trains as usual.",
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
FORCE_OPTION = typer.Option(
    False,
    "--force",
    help="Retrain phrases that already have a stored policy (it stays, and plays, until its new run has "
    "finished; interrupted, the same command goes on with the phrases not yet retrained).",
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
