"""Training: one SAC policy per phrase (or per task family), with evaluation, checkpoints and resume.

:func:`train_policy` is the loop, to be read top to bottom: explore, then act with the policy
and learn from the replay buffer at ``update_ratio`` gradient steps per environment step;
evaluate every ``eval_every`` steps; at the first episode end after every
``checkpoint_every`` steps, write a checkpoint that holds everything (networks, optimisers,
buffer, random generators), so that running the same command again continues exactly where an
interrupted run stopped. The policy stored at the end is the best one evaluated (SAC's
evaluations swing by tenths of F1 from one to the next; the last is not always the best).
Given a ``start`` policy (fine-tuning from the general policy, :mod:`pianobot.agent.general`),
the agent begins with its weights, evaluates them before the first step, and that evaluation
counts: the stored policy is never worse than the start (and is the start itself when it
already reaches :attr:`TrainConfig.stop_f1`).
Every episode is logged beside the policy (:mod:`pianobot.learn.log`: CSV, TensorBoard, a plot).
With ``TrainConfig.envs`` > 1 the loop steps that many environments at once, in worker processes
(:func:`make_envs`); with 1, the default, its one environment in this process, as it always did.
Training a whole piece (one job per phrase, parallel workers) is :mod:`pianobot.learn.jobs`.
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import asdict, dataclass, replace
from functools import partial
from pathlib import Path
from typing import Callable

import gymnasium as gym
import numpy as np
import torch
from gymnasium.vector import AutoresetMode

from pianobot.agent import general, store
from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.policy import make_agent
from pianobot.agent.sac import SAC, resolve_device, vector_size
from pianobot.agent.tasks import make_env
from pianobot.config import to_dict
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.learn.explore import Explorer
from pianobot.learn.log import TrainingLog
from pianobot.music.piece import Piece
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
    """True once, when the policy is stored (``step``: the steps it took)."""


def make_envs(target: Piece | str, env_config: EnvConfig, count: int) -> gym.vector.VectorEnv:
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


def evaluate(
    agent: SAC, target: Piece | str, env_config: EnvConfig, episodes: int, first_seed: int = EVAL_SEED
) -> dict:
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
    too, ``critic.*`` and ``log_alpha``, in checkpoints written since policies keep one)."""
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


def train_policy(
    target: Piece | str,
    config: TrainConfig,
    folder: Path,
    report: Callable[[Progress], None] = lambda p: None,
    stop_after: int | None = None,
    about: dict | None = None,
    start: Path | None = None,
) -> dict:
    """Train one policy for a phrase (a Piece) or a task family (its name); store it in ``folder``.

    ``stop_after`` ends the run after that many steps as an interruption would (tests);
    ``about`` goes into the manifest (piece, phrase hash, ...). ``start``: a stored policy's
    folder to begin from (the general policy; ``config.from_general`` must be on): its weights
    are evaluated before the first step and training stops at ``config.stop_f1``. Without one
    the run trains from scratch and its manifest says ``from_general: false``. A resumed run
    goes on from its checkpoint, which knows where it began. One run at a time may train into a
    folder (a second one is refused while the first holds it).
    """
    if start is not None and not config.from_general:
        raise ValueError("a start policy was given to a run with from_general=False")
    with store.training_lock(folder), TrainingLog(folder) as log:
        store.remove_temporary_files(folder)
        device = resolve_device(config.device)
        with contextlib.closing(make_envs(target, config.env, config.envs)) as envs:
            return _train(target, config, folder, report, stop_after, about, log, envs, device, start)


def _train(
    target,
    config: TrainConfig,
    folder: Path,
    report,
    stop_after: int | None,
    about: dict | None,
    log: TrainingLog,
    envs: gym.vector.VectorEnv,
    device: torch.device,
    start: Path | None,
) -> dict:
    torch.manual_seed(config.seed)  # before the networks are made: their first weights come from it
    env_config, n = config.env, config.envs
    agent = make_agent(envs, config.sac, device)
    space, action_size = envs.single_observation_space, envs.single_action_space.shape[0]
    tactile_shape = space["tactile"].shape if "tactile" in space.spaces else None
    buffer = ReplayBuffer(
        min(config.sac.buffer_size, config.steps),
        vector_size(space, config.sac.score_input),
        tactile_shape,
        action_size,
    )
    rng = np.random.default_rng(config.seed)
    explorers = [Explorer(config.explore, action_size, env_config, rng) for _ in range(n)]  # one per environment
    step, episode, update_debt, evaluations = 0, 0, 0.0, []
    best, best_tensors = None, None  # the best evaluation so far and its policy's tensors
    seconds_before = 0.0  # wall-clock time spent before an interruption

    checkpoint = store.load_checkpoint(folder)
    if checkpoint is not None:  # continue an interrupted run (exactly, with one environment)
        tensors, state, buffer_folder = checkpoint
        agent.load_tensors({k: v for k, v in tensors.items() if not k.startswith(BEST_PREFIX)})
        if state.get("best") is not None:
            best = state["best"]
            best_tensors = best_policy_tensors(tensors)
        torch.set_rng_state(tensors["torch_rng"])
        buffer.load(buffer_folder, state["buffer_size"], state["buffer_cursor"])
        rng.bit_generator.state = state["rng"]
        step, episode, update_debt, evaluations = (
            state["step"],
            state["episode"],
            state["update_debt"],
            state["evaluations"],
        )
        agent.updates = state["updates"]
        seconds_before = state.get("seconds", 0.0)
        observations = resume_envs(envs, state["env_rng"], config.seed, step)
        began = state.get("start")  # where the interrupted run began (checkpoints before fine-tuning: scratch)
        report(Progress(step, config.steps, resumed=True))
    else:
        began = None
        if start is not None:  # fine-tuning: the start policy's actor, encoder, Q heads and temperature
            began = general.describe(start)
            try:
                agent.load_start(*general.start_tensors(start))
            except ValueError as e:
                raise PianobotError(
                    f"the policy {start} does not fit this run's networks ({e}): train with its options, or from scratch"
                ) from None
        observations, _ = envs.reset(seed=config.seed)
        state = {}
    config = replace(config, from_general=began is not None)  # what the manifest records: how it began

    def critic_learnt() -> bool:  # (a start policy without a critic, kept before any update, passes on none)
        return agent.updates > 0 or bool(began and began["critic"])

    started = time.perf_counter()
    log.start(resumed_at=step if checkpoint is not None else None)
    for explorer in explorers:
        explorer.reset()
    # an evaluation that was due (but waited for exploration to end) stays due
    next_eval = state.get("next_eval", (step // config.eval_every + 1) * config.eval_every)
    next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
    returns, losses, final = np.zeros(n), None, None

    if began is not None and checkpoint is None:  # evaluate the start before any step: it counts
        figures = evaluate(agent, target, env_config, config.eval_episodes)
        evaluations.append({"step": 0, **figures})
        best, best_tensors = {"step": 0, **figures}, kept_tensors(agent, critic_learnt())
        log.evaluation(0, time.perf_counter() - started, figures)
        report(Progress(0, config.steps, eval_f1=figures["f1"]))
        if config.stop_f1 is not None and figures["f1"] >= config.stop_f1:
            final = {"step": 0, **figures}  # it plays the phrase already: no step taken

    while final is None and step < config.steps:
        # act in every environment: explore (the teacher's action plus noise), then sample the policy
        vectors, tactiles = agent.split_batch(observations)
        each = [{k: v[i] for k, v in observations.items()} for i in range(n)]  # each environment's observation
        taught = [explorer.teach(o) for explorer, o in zip(explorers, each)]  # the scripted pianist's actions, or None
        if step < config.sac.exploration_steps:
            actions = np.stack([explorer.act(o, t) for explorer, o, t in zip(explorers, each, taught)])
        else:
            actions = agent.sample_batch(vectors, tactiles)
        # step them all (with envs > 1, each in its worker process, at the same time) and store what happened
        observations, rewards, terminations, truncations, _ = envs.step(actions)
        next_vectors, next_tactiles = agent.split_batch(observations)
        buffer.add_batch(vectors, tactiles, actions, rewards, terminations, next_vectors, next_tactiles, taught)
        returns += rewards
        step += n

        if step > config.sac.exploration_steps:  # learn
            update_debt += config.sac.update_ratio * n
            while update_debt >= 1.0:
                losses = agent.update(buffer.sample(config.sac.batch_size, rng, agent.device))
                update_debt -= 1.0

        ended = terminations | truncations
        if ended.any():  # episodes ended: evaluate if due, log them, checkpoint if due, begin new ones
            figures = None
            if step >= next_eval and step > config.sac.exploration_steps:
                figures = evaluate(agent, target, env_config, config.eval_episodes)
                temperature = {k: round(losses[k], 4) for k in ("alpha", "entropy")} if losses else {}
                evaluations.append({"step": step, **figures, **temperature})
                if better(figures, best):
                    best, best_tensors = {"step": step, **figures}, kept_tensors(agent, critic_learnt())
                report(Progress(step, config.steps, eval_f1=figures["f1"]))
                next_eval = (step // config.eval_every + 1) * config.eval_every
            seconds = seconds_before + time.perf_counter() - started
            logged = figures  # on the first episode's row
            for i in np.flatnonzero(ended):
                episode += 1
                report(Progress(step, config.steps, episode_return=float(returns[i]), losses=losses))
                log.row(step, episode, seconds, float(returns[i]), losses, logged)
                returns[i], logged = 0.0, None
            if figures is not None and config.stop_f1 is not None and figures["f1"] >= config.stop_f1:
                final = {"step": step, **figures}  # good enough: stop here
                break
            if step >= next_checkpoint and step < config.steps:
                state = {
                    "step": step,
                    "episode": episode,
                    "update_debt": update_debt,
                    "updates": agent.updates,
                    "evaluations": evaluations,
                    "rng": rng.bit_generator.state,
                    "env_rng": env_generators(envs),
                    "buffer_size": buffer.size,
                    "buffer_cursor": buffer.cursor,
                    "best": best,
                    "next_eval": next_eval,
                    "seconds": seconds,
                    "start": began,
                }
                kept = {BEST_PREFIX + k: v for k, v in (best_tensors or {}).items()}
                store.save_checkpoint(
                    folder, {**agent.tensors(), "torch_rng": torch.get_rng_state(), **kept}, state, buffer
                )
                next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
            if stop_after is not None and step >= stop_after:
                return {"interrupted_at": step}
            observations, _ = envs.reset(options={"reset_mask": ended})
            for i in np.flatnonzero(ended):
                explorers[i].reset()
        elif step % 200 < n:
            report(Progress(step, config.steps))

    tensors = kept_tensors(agent, critic_learnt())
    if final is None:
        final = {"step": step, **evaluate(agent, target, env_config, config.eval_episodes)}
        evaluations.append(final)
        if best is not None and better(best, final):  # an earlier policy played better: keep that one
            final, tensors = best, best_tensors
    manifest = {
        **(about or {}),
        "target": target if isinstance(target, str) else [asdict(note) for note in target.notes],
        "steps": step,
        "updates": agent.updates,
        "seconds": round(seconds_before + time.perf_counter() - started, 1),  # across interruptions
        "device": device.type,
        "start": began,
        "evaluation": final,
        "evaluations": evaluations,
        "config": to_dict(config),
    }
    policy, critic = split_kept(tensors)
    store.save_policy(folder, policy, manifest, critic=critic)
    store.drop_checkpoint(folder)
    log.plot()
    report(Progress(step, config.steps, finished=True))
    return manifest
