"""What both learners share: one training run's set-up, beginning, evaluations, checkpoints and end.

The learners, :func:`~pianobot.learn.train.train_policy` (SAC) and
:func:`~pianobot.learn.dagger.dagger_policy` (DAgger), each keep only their loop, to be read top
to bottom; a :class:`Run` does the rest for them, in this order:

- :func:`open_run`: hold the model folder (one run at a time trains into it), open the log
  (:mod:`pianobot.learn.log`), make the environments (:func:`make_envs`), pick the device;
- :meth:`Run.setup`: the agent (its first weights seeded), the replay buffer, the random generator;
- :meth:`Run.begin`: afresh, from the start policy when there is one (fine-tuning from the general
  policy, :mod:`pianobot.agent.general`), or where an interrupted run's checkpoint left off;
- :meth:`Run.evaluate_start`: a fresh fine-tuning run evaluates its start before the first step,
  and that evaluation counts: the stored policy is never worse than the start;
- :meth:`Run.keep_if_best`: the best policy evaluated so far is kept (evaluations swing by tenths
  of F1 from one to the next; the last is not always the best);
- :meth:`Run.checkpoint`: everything a run needs to go on (networks, optimisers, buffer, random
  generators, the best policy, and the learner's own counters and tensors), so that the same
  command continues an interrupted run exactly where it stopped;
- :meth:`Run.finish`: the manifest, and the policy stored with it. A run whose start policy
  already reaches :attr:`~pianobot.learn.config.TrainConfig.stop_f1` at step 0 stores nothing:
  its manifest says ``"kept": "start"`` (the start policy plays the target), and the run removes
  its log, and its folder when nothing else is in it. A run none of whose evaluations beat its
  start's stores no policy either (``"kept": "start"``): it keeps its log and writes its
  manifest alone. Every other run stores its policy (``"kept": "trained"``).

Beside it, what else both share: :func:`evaluate`, :func:`make_envs` and the checkpoint's
environment generators, and the tensors a stored policy keeps.
"""

from __future__ import annotations

import contextlib
import shutil
import time
from dataclasses import asdict, dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import Callable, Iterator

import gymnasium as gym
import numpy as np
import torch
from gymnasium.vector import AutoresetMode

from pianobot.agent import general, store
from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.policy import make_agent
from pianobot.agent.sac import SAC, resolve_device, vector_size
from pianobot.agent.tasks import GivenParts, Target, make_env
from pianobot.config import to_dict
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError
from pianobot.learn import forced
from pianobot.learn.config import TrainConfig
from pianobot.learn.log import LOG_FILE, PLOT_FILE, TENSORBOARD_DIR, TrainingLog
from pianobot.perform.rollout import rollout

EVAL_SEED = 10_000
"""Evaluation episodes use seeds EVAL_SEED, EVAL_SEED + 1, ...: the same hand starts for every evaluation."""


TASK_EVAL_EPISODES = 20
"""Evaluation episodes when training on a task family: every instance differs, and 3 or 5 of
them stopped runs on a lucky evaluation (5 instances at F1 0.90 played 30 others at 0.58)."""


@dataclass
class Progress:
    """What the loop reports to whoever displays it."""

    step: int
    steps: int
    episode_return: float | None = None
    eval_f1: float | None = None
    losses: dict | None = None
    resumed: bool = False
    """True once, when an interrupted run continues from its checkpoint at ``step``."""
    finished: bool = False
    """True once, when the run ends (``step``: the steps it took)."""


def make_envs(target: Target, env_config: EnvConfig, count: int) -> gym.vector.VectorEnv:
    """``count`` environments of a phrase or task family (:func:`~pianobot.agent.tasks.make_env`),
    stepped together: one in this process (the run is exactly what it always was), more each in a
    worker process of its own (spawned: they import the simulator, never torch). None resets by
    itself: the loop begins an environment's next episode once the last one is logged and checkpointed."""
    factories = [partial(make_env, target, env_config)] * count
    if count == 1:
        return gym.vector.SyncVectorEnv(factories, autoreset_mode=AutoresetMode.DISABLED)
    return gym.vector.AsyncVectorEnv(factories, context="spawn", autoreset_mode=AutoresetMode.DISABLED)


def env_generators(envs: gym.vector.VectorEnv) -> list[dict]:
    """The state of each environment's generator (the hand starts and task instances still to come)."""
    return [generator.bit_generator.state for generator in envs.get_attr("np_random")]


def resume_envs(envs: gym.vector.VectorEnv, states: list[dict] | dict, seed: int, step: int) -> dict:
    """Begin new episodes where a checkpoint's generators (:func:`env_generators`) left off; the
    first observations. With one environment a resumed run goes on exactly as an uninterrupted one;
    with more, the episodes under way at the checkpoint begin anew (docs/training.md). A checkpoint
    of another number of environments gives generators seeded afresh from ``seed`` and ``step``."""
    states = states if isinstance(states, list) else [states]  # (checkpoints from before --envs held one)
    same = len(states) == envs.num_envs
    envs.reset(seed=seed if same else seed + step)  # makes the generators ...
    if same:  # ... and sets them where they were
        generators = [np.random.default_rng() for _ in states]
        for generator, state in zip(generators, states):
            generator.bit_generator.state = state
        envs.set_attr("np_random", generators)
    observations, _ = envs.reset()
    return observations


def evaluate(agent: SAC, target: Target, env_config: EnvConfig, episodes: int, first_seed: int = EVAL_SEED) -> dict:
    """Deterministic policy on fixed hand starts (and task instances), seeds ``first_seed``,
    ``first_seed + 1``, ...: mean note F1, velocity error and return."""
    env = make_env(target, env_config)
    f1s, errors, returns = [], [], []
    for i in range(episodes):
        episode = rollout(env, agent, seed=first_seed + i)
        report = episode.report()
        f1s.append(report.f1)
        returns.append(episode.total_reward)
        if report.velocity_mae is not None:
            errors.append(report.velocity_mae)
    env.close()
    return {
        "f1": float(np.mean(f1s)),
        "velocity_mae": float(np.mean(errors)) if errors else None,
        "return": float(np.mean(returns)),
    }


BEST_PREFIX = "best."
"""Checkpoint tensors of the best policy evaluated so far are stored under this prefix."""


def best_policy_tensors(checkpoint_tensors: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """The best evaluated policy's tensors in a checkpoint, under their own names (its critic's
    too, ``critic.*`` and ``log_alpha``, in SAC checkpoints written since policies keep one)."""
    return {k[len(BEST_PREFIX) :]: v for k, v in checkpoint_tensors.items() if k.startswith(BEST_PREFIX)}


def kept_tensors(agent: SAC, critic: bool = True) -> dict[str, torch.Tensor]:
    """What a stored policy keeps of the agent: actor and encoder, and (``critic``) Q heads and temperature."""
    return {**agent.tensors(with_training_state=False), **(agent.critic_tensors() if critic else {})}


def split_kept(tensors: dict[str, torch.Tensor]) -> tuple[dict[str, torch.Tensor], dict[str, torch.Tensor]]:
    """:func:`kept_tensors` as (policy file, critic file) tensors."""
    policy = {k: v for k, v in tensors.items() if k.startswith(("actor.", "encoder."))}
    return policy, {k: v for k, v in tensors.items() if k not in policy}


def better(figures: dict, than: dict | None) -> bool:
    """Whether an evaluation beats another: higher note F1 first, then higher return."""
    if than is None:
        return True
    return (figures["f1"], figures["return"]) > (than["f1"], than["return"])


@contextlib.contextmanager
def open_run(
    target: Target,
    config: TrainConfig,
    folder: Path,
    report: Callable[[Progress], None],
    about: dict | None,
    start: Path | None,
    evaluator: Callable[..., dict],
    critic: bool,
) -> Iterator[Run]:
    """A :class:`Run` into ``folder``, holding it (a second run on it is refused) with its log and
    environments open; when the start reached ``stop_f1`` at step 0 (nothing stored, nothing
    trained), what it wrote goes once they are closed. The arguments are the learners' and the :class:`Run`'s."""
    if start is not None and not config.from_general:
        raise ValueError("a start policy was given to a run with from_general=False")
    with store.training_lock(folder), TrainingLog(folder) as log:
        store.remove_temporary_files(folder)
        device = resolve_device(config.device)
        with contextlib.closing(make_envs(target, config.env, config.envs)) as envs:
            run = Run(target, config, folder, report, about, start, log, envs, device, evaluator, critic)
            yield run
    if run.kept_start:
        _remove_log(folder)


def _remove_log(folder: Path) -> None:
    """Remove what a run that stored no policy leaves in ``folder``: its log, and the folder itself
    when nothing but the lock is left in it."""
    for name in (LOG_FILE, PLOT_FILE):
        (folder / name).unlink(missing_ok=True)
    shutil.rmtree(folder / TENSORBOARD_DIR, ignore_errors=True)
    if {path.name for path in folder.iterdir()} <= {store.LOCK_FILE}:
        (folder / store.LOCK_FILE).unlink(missing_ok=True)
        with contextlib.suppress(OSError):  # (another run began in it meanwhile)
            folder.rmdir()


def target_record(target: Target) -> str | list[dict]:
    """What a manifest's ``target`` holds: a task family's name (also one given parts:
    :class:`~pianobot.agent.tasks.GivenParts`, which the job's ``about`` describes), or a phrase's notes."""
    if isinstance(target, GivenParts):
        return target.name
    return target if isinstance(target, str) else [asdict(note) for note in target.notes]


@dataclass
class Run:
    """One training run: what it trains, where, and the bookkeeping every learner needs (see the
    module's docstring for the order of its calls). ``config`` is the run's; once :meth:`begin`
    knows how the run began, its ``from_general`` says so (and with it :attr:`TrainConfig.stop_f1`)."""

    target: Target
    config: TrainConfig
    folder: Path
    report: Callable[[Progress], None]
    about: dict | None
    start: Path | None
    log: TrainingLog
    envs: gym.vector.VectorEnv
    device: torch.device
    evaluator: Callable[..., dict]
    """:func:`evaluate`, or what a test puts in its place."""
    critic: bool
    """Whether a stored policy keeps its Q heads and temperature (SAC's; DAgger learns none)."""
    began: dict | None = None
    """Where the run began: the start policy (:func:`~pianobot.agent.general.describe`), None from scratch."""
    resumed: bool = False
    kept_start: bool = False
    """True when the start policy reached ``stop_f1`` at step 0: nothing is stored."""
    evaluations: list[dict] = field(default_factory=list)
    best: dict | None = None
    """The best evaluation so far (``step`` and figures); its policy's tensors are :attr:`best_tensors`."""
    best_tensors: dict[str, torch.Tensor] | None = None
    seconds_before: float = 0.0
    """Wall-clock time spent before an interruption."""
    started: float = field(default_factory=time.perf_counter)

    def setup(self, buffer_size: int) -> tuple[SAC, ReplayBuffer, np.random.Generator]:
        """The agent, seeded from ``config.seed``; a replay buffer of ``buffer_size`` steps (no more
        than the run takes); and the run's random generator, seeded from ``config.seed`` too."""
        torch.manual_seed(self.config.seed)  # before the networks are made: their first weights come from it
        agent = make_agent(self.envs, self.config.sac, self.device)
        space, action_size = self.envs.single_observation_space, self.envs.single_action_space.shape[0]
        tactile_shape = space["tactile"].shape if "tactile" in space.spaces else None
        buffer = ReplayBuffer(
            min(buffer_size, self.config.steps),
            vector_size(space, self.config.sac.score_input),
            tactile_shape,
            action_size,
        )
        return agent, buffer, np.random.default_rng(self.config.seed)

    def begin(self, agent: SAC, buffer: ReplayBuffer, rng: np.random.Generator) -> tuple[dict, dict, dict]:
        """Continue an interrupted run from its checkpoint (exactly, with one environment), else
        begin afresh: with the start policy's weights when there is one (its actor, encoder and,
        where it has them, Q heads and temperature). Opens the log. Returns the first observations,
        the checkpoint's state (``step`` and ``episode`` 0 afresh) and its tensors ({} afresh), in
        which the learner finds its own counters and optimiser."""
        checkpoint = store.load_checkpoint(self.folder)
        if checkpoint is not None:
            tensors, state, buffer_folder = checkpoint
            agent.load_tensors({k: v for k, v in tensors.items() if not k.startswith(BEST_PREFIX)})
            self.best = state.get("best")
            self.best_tensors = best_policy_tensors(tensors) if self.best is not None else None
            torch.set_rng_state(tensors["torch_rng"])
            buffer.load(buffer_folder, state["buffer_size"], state["buffer_cursor"])
            rng.bit_generator.state = state["rng"]
            self.evaluations, agent.updates = state["evaluations"], state["updates"]
            self.seconds_before = state.get("seconds", 0.0)
            observations = resume_envs(self.envs, state["env_rng"], self.config.seed, state["step"])
            self.began = state.get("start")  # (checkpoints from before fine-tuning began from scratch)
            self.resumed = True
            self.report(Progress(state["step"], self.config.steps, resumed=True))
        else:
            tensors, state = {}, {"step": 0, "episode": 0}
            if self.start is not None:
                self.began = general.describe(self.start)
                try:
                    agent.load_start(*general.start_tensors(self.start))
                except ValueError as e:
                    raise PianobotError(
                        f"the policy {self.start} does not fit this run's networks ({e}): train with its options, or from scratch"
                    ) from None
            observations, _ = self.envs.reset(seed=self.config.seed)
        self.config = replace(self.config, from_general=self.began is not None)  # what the manifest records
        self.started = time.perf_counter()
        self.log.start(resumed_at=state["step"] if self.resumed else None)
        return observations, state, tensors

    @property
    def finishing(self) -> bool:
        """True when an interrupted run ends at its checkpoint (:attr:`TrainConfig.finish`)."""
        return self.resumed and self.config.finish

    def seconds(self) -> float:
        """Wall-clock seconds the run has taken, across interruptions."""
        return self.seconds_before + time.perf_counter() - self.started

    def evaluate(self, agent: SAC) -> dict:
        """The policy's figures on the run's evaluation episodes (:func:`evaluate`)."""
        return self.evaluator(agent, self.target, self.config.env, self.config.eval_episodes)

    def reached(self, figures: dict) -> bool:
        """Whether an evaluation ends the run (:attr:`TrainConfig.stop_f1`)."""
        return self.config.stop_f1 is not None and figures["f1"] >= self.config.stop_f1

    def policy_tensors(self, agent: SAC) -> dict[str, torch.Tensor]:
        """What a stored policy keeps of the agent: actor and encoder, and, with ``critic``, its
        Q heads and temperature once learnt or passed on by the start policy (a start without a
        critic, kept before any update, passes on none)."""
        learnt = agent.updates > 0 or bool(self.began and self.began["critic"])
        return kept_tensors(agent, self.critic and learnt)

    def keep_if_best(self, step: int, figures: dict, agent: SAC) -> None:
        """Keep the agent's policy when its evaluation (``figures`` at ``step``) is the best so far."""
        if better(figures, self.best):
            self.best, self.best_tensors = {"step": step, **figures}, self.policy_tensors(agent)

    def evaluate_start(self, agent: SAC) -> dict | None:
        """A fresh fine-tuning run evaluates its start policy before any step: a row of its own in
        the log, the first of the evaluations, the best so far. Its figures (``step`` 0) when they
        already reach ``stop_f1``: the run ends there, storing nothing. None otherwise (and when
        resumed, or from scratch)."""
        if self.began is None or self.resumed:
            return None
        figures = self.evaluate(agent)
        self.evaluations.append({"step": 0, **figures})
        self.keep_if_best(0, figures, agent)
        self.log.evaluation(0, self.seconds(), figures)
        self.report(Progress(0, self.config.steps, eval_f1=figures["f1"]))
        self.kept_start = self.reached(figures)
        return {"step": 0, **figures} if self.kept_start else None

    def checkpoint(
        self,
        agent: SAC,
        buffer: ReplayBuffer,
        rng: np.random.Generator,
        step: int,
        episode: int,
        state: dict,
        tensors: dict[str, torch.Tensor] | None = None,
    ) -> None:
        """Write a checkpoint: the agent, buffer, generators, evaluations and best policy, with the
        learner's own ``state`` (JSON) and ``tensors`` (an optimiser's)."""
        state = {
            "step": step,
            "episode": episode,
            **state,
            "updates": agent.updates,
            "evaluations": self.evaluations,
            "rng": rng.bit_generator.state,
            "env_rng": env_generators(self.envs),
            "buffer_size": buffer.size,
            "buffer_cursor": buffer.cursor,
            "best": self.best,
            "seconds": self.seconds(),
            "start": self.began,
        }
        kept = {BEST_PREFIX + k: v for k, v in (self.best_tensors or {}).items()}
        tensors = {**agent.tensors(), **(tensors or {}), "torch_rng": torch.get_rng_state(), **kept}
        store.save_checkpoint(self.folder, tensors, state, buffer)

    def finish(self, agent: SAC, step: int, final: dict, tensors: dict[str, torch.Tensor]) -> dict:
        """End the run after ``step`` steps: its manifest, with ``final`` the evaluation of the
        policy kept (``tensors``, stored with it), and draw the learning curves; the checkpoint
        goes. When the policy kept is the start (``final`` is its step-0 evaluation) nothing is
        stored: a copy of the start would play no better, and would stand in the store as a
        policy of its own; the run that trained keeps its log and writes its manifest alone
        (:func:`~pianobot.agent.store.kept_start`), so that it is not trained again (a start that
        reached ``stop_f1`` at step 0 leaves nothing: :func:`open_run` removes its log)."""
        start_kept = self.kept_start or (self.began is not None and final.get("step") == 0)
        manifest = {
            **(self.about or {}),
            "target": target_record(self.target),
            "steps": step,
            "updates": agent.updates,
            "seconds": round(self.seconds(), 1),  # across interruptions
            "device": self.device.type,
            "start": self.began,
            "kept": "start" if start_kept else "trained",
            "evaluation": final,
            "evaluations": self.evaluations,
            "config": to_dict(self.config),
        }
        # what a forced run replaces (forced.mark_replacing) stayed, and played, until now; its mark
        # says the phrase is finished only once the new manifest is written
        if not start_kept:
            policy, critic = split_kept(tensors)
            store.save_policy(self.folder, policy, manifest, critic=critic)
        elif not self.kept_start:  # trained, and kept its start: the manifest alone says the run is done
            store.save_manifest(self.folder, manifest)
        elif forced.replacing(self.folder) is not None:  # (the start played well enough: what was stored goes)
            (self.folder / store.MANIFEST_FILE).unlink(missing_ok=True)
        forced.replaced(self.folder, policy_kept=not start_kept)
        if not self.kept_start:  # (a run that trained keeps its learning curves, also when it kept its start)
            store.drop_checkpoint(self.folder)
            self.log.plot()
        self.report(Progress(step, self.config.steps, finished=True))
        return manifest
