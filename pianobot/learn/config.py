"""One training run's settings (:class:`TrainConfig`), and reading them back from a stored model."""

from __future__ import annotations

from dataclasses import dataclass, field

from pianobot.agent.config import DEVICES, SACConfig
from pianobot.config import ConfigError, check_ranges, from_dict
from pianobot.env.piano import EnvConfig
from pianobot.errors import SettingError
from pianobot.learn.explore import EXPLORATIONS

MAX_ENVS = 256
"""Most environments one run steps at once (``TrainConfig.envs``)."""
LEARNERS = ("sac", "dagger")
"""How a policy learns (``TrainConfig.learner``): Soft Actor-Critic from rewards (the paper), or
DAgger, imitating the scripted pianist (:mod:`pianobot.learn.dagger`)."""


@dataclass(frozen=True)
class DaggerConfig:
    """The settings of DAgger (``TrainConfig.learner = 'dagger'``), with their defaults."""

    round_steps: int = 20_000
    """Environment steps gathered in a round, before the policy learns from all gathered so far."""
    updates_per_step: float = 0.5
    """Gradient steps of behaviour cloning at a round's end, per environment step of the round."""
    batch_size: int = 256
    learning_rate: float = 1e-3
    """Adam's step size, over the actor (and the encoder it reads), at the run's start; it falls along a
    cosine to ``final_learning_rate`` at its last step (a cloned policy must be precise: docs/training.md)."""
    final_learning_rate: float = 3e-5
    teacher_share: float = 0.5
    """In round r an episode is played by the teacher with probability ``teacher_share ** r``
    (round 0: every one), else by the policy; the teacher labels every step either way."""
    dataset_size: int = 500_000
    """Steps kept to learn from (the oldest go first); at most the run's steps are held in memory."""
    hold_guard: bool = False
    """The policy's episodes are played through the hold guard (:class:`~pianobot.perform.guard.HoldGuard`),
    as `pianobot play` plays a general policy of hands' parts: the policy learns in the states the guard
    leads it to (the teacher labels every step either way; the evaluation plays the policy alone)."""

    def __post_init__(self) -> None:
        check_ranges(self, round_steps=(1, 10**9), batch_size=(1, 1 << 16), dataset_size=(1, 10**8))
        if not (self.updates_per_step > 0 and 0 < self.final_learning_rate <= self.learning_rate):
            raise ValueError("updates_per_step must be above 0, and 0 < final_learning_rate <= learning_rate")
        if not 0 <= self.teacher_share <= 1:
            raise ValueError(f"teacher_share must lie in [0, 1]; got {self.teacher_share}")


@dataclass(frozen=True)
class TrainConfig:
    """One training run of one policy. Its hash (with the phrase's) names the model folder."""

    steps: int = 50_000
    """Environment steps, exploration included."""
    seed: int = 0
    learner: str = "sac"
    """'sac' (the paper: Soft Actor-Critic, :mod:`pianobot.learn.train`) or 'dagger' (imitating
    the scripted pianist, :mod:`pianobot.learn.dagger`; ``explore`` and ``sac``'s learning
    settings then go unused, its networks' shape still counts)."""
    explore: str = "scripted"
    """'uniform', 'repeat', 'prior' (the paper's best) or 'scripted' (ours)."""
    eval_every: int = 5_000
    eval_episodes: int = 3
    checkpoint_every: int = 5_000
    until_f1: float | None = None
    """Stop early once an evaluation reaches this note F1 (None: train ``steps`` steps; a run
    fine-tuned from the general policy stops at ``finetune_until_f1``). See :attr:`stop_f1`."""
    from_general: bool = field(default=True, metadata={"start": True})
    """Start each phrase from the general policy (the ``melody`` family's, found in the model store,
    :mod:`pianobot.agent.general`) when there is one: its actor, encoder, Q heads and temperature,
    evaluated before the first step. A run without one trains from scratch, and its manifest
    says ``from_general: false``. Where a run begins, not what it trains: left out of the hash, so
    a phrase has one folder, fine-tuned or not (the manifest's ``start`` names the policy)."""
    finetune_until_f1: float | None = field(default=1.0, metadata={"start": True})
    """When fine-tuning and ``until_f1`` is None: stop once an evaluation reaches this note F1. At
    1.0, once the policy plays the phrase perfectly from every evaluation hand start, so a phrase
    the general policy already plays costs one evaluation. Left out of the hash with ``from_general``."""
    sac: SACConfig = field(default_factory=SACConfig)
    dagger: DaggerConfig = field(default_factory=DaggerConfig)
    env: EnvConfig = field(default_factory=EnvConfig)
    envs: int = field(default=1, metadata={"runtime": True})
    """Environments stepped at once: 1 in the training process (the run is exactly what it always
    was); more, each in a worker process of its own, all stepping together while the learner waits.
    How a run executes, not what it trains: left out of the configuration's hash (the model folder)."""
    finish: bool = field(default=False, metadata={"runtime": True})
    """End an interrupted run at its checkpoint instead of training on: the best policy it evaluated
    so far is stored (a SAC run's checkpointed policy is evaluated too, and kept where it plays
    better), and the manifest's ``steps`` say how many it took. A run without a checkpoint, or whose
    checkpoint came before its first learning step (SAC's exploration), trains as usual: it has
    learnt nothing to keep. When to stop a run, not what it trains: left out of the hash, so the same command
    with it finds the run's folder."""
    device: str = field(default="auto", metadata={"runtime": True})
    """Where the learner (networks, updates, replay batches) runs: 'auto' (cuda when torch sees a
    GPU, else cpu), 'cpu' or 'cuda'. Left out of the hash too: a run may resume on another device."""

    def __post_init__(self) -> None:
        if self.device not in DEVICES:
            raise ValueError(f"device must be one of {', '.join(DEVICES)}; got {self.device!r}")
        if self.learner not in LEARNERS:
            raise ValueError(f"learner must be one of {', '.join(LEARNERS)}; got {self.learner!r}")
        if self.learner == "dagger" and self.env.world.control == "torque":
            raise ValueError(
                "the dagger learner needs velocity or position control (the scripted pianist has no torques)"
            )
        if self.explore not in EXPLORATIONS:
            raise ValueError(f"exploration must be one of {', '.join(EXPLORATIONS)}; got {self.explore!r}")
        if self.learner == "sac" and self.explore == "scripted" and self.env.world.control == "torque":
            raise ValueError(
                "scripted exploration needs velocity or position control (the scripted pianist has no torques)"
            )
        if self.learner == "sac" and not 0 <= self.sac.exploration_steps < self.steps:
            raise ValueError(
                f"train.steps {self.steps}: SAC learns only after its {self.sac.exploration_steps} exploration steps: give "
                "more train.steps, fewer train.sac.exploration_steps, or train.learner dagger (which learns from the first)"
            )
        for stop in (self.until_f1, self.finetune_until_f1):
            if stop is not None and not 0.0 < stop <= 1.0:
                raise ValueError(f"the note F1 to stop at must lie in (0, 1]; got {stop}")
        check_ranges(
            self,
            steps=(1, 10**9),
            eval_every=(1, 10**9),
            eval_episodes=(1, 10_000),
            checkpoint_every=(1, 10**9),
            envs=(1, MAX_ENVS),
        )

    @property
    def stop_f1(self) -> float | None:
        """The note F1 at which an evaluation ends the run: ``until_f1``, else, fine-tuning,
        ``finetune_until_f1``; None: never early."""
        if self.until_f1 is not None:
            return self.until_f1
        return self.finetune_until_f1 if self.from_general else None


def config_from_manifest(manifest: dict) -> TrainConfig:
    """The TrainConfig a stored policy was trained with (from :func:`pianobot.agent.store.read_manifest`)."""
    try:
        return from_dict(TrainConfig, manifest["config"])
    except ConfigError as e:
        raise SettingError(f"model manifest: {e}: retrain with jobs.force", "jobs.force") from None
