"""Training: one SAC policy per phrase (or per task family), with evaluation, checkpoints and resume.

:func:`train_policy` is the loop, to be read top to bottom: explore, then act with the policy
and learn from the replay buffer at ``update_ratio`` gradient steps per environment step;
evaluate every ``eval_every`` steps; at the first episode end after every
``checkpoint_every`` steps, write a checkpoint that holds everything (networks, optimisers,
buffer, random generators), so that running the same command again continues exactly where an
interrupted run stopped. The policy stored at the end is the best one evaluated (SAC's
evaluations swing by tenths of F1 from one to the next; the last is not always the best).
Every episode is logged beside the policy (:mod:`pianobot.learn.log`: CSV, TensorBoard, a plot).
Training a whole piece (one job per phrase, parallel workers) is :mod:`pianobot.learn.jobs`.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import torch

from pianobot.agent import store
from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.policy import make_agent
from pianobot.agent.sac import SAC, vector_size
from pianobot.config import to_dict
from pianobot.env.piano import EnvConfig, PianoEnv
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


def make_env(target: Piece | str, env_config: EnvConfig) -> PianoEnv:
    return (
        PianoEnv(task=target, config=env_config)
        if isinstance(target, str)
        else PianoEnv(piece=target, config=env_config)
    )


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
    """The best evaluated policy's tensors in a checkpoint, under their own names."""
    return {k[len(BEST_PREFIX) :]: v for k, v in checkpoint_tensors.items() if k.startswith(BEST_PREFIX)}


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
) -> dict:
    """Train one policy for a phrase (a Piece) or a task family (its name); store it in ``folder``.

    ``stop_after`` ends the run after that many steps as an interruption would (tests);
    ``about`` goes into the manifest (piece, phrase hash, ...). One run at a time may train
    into a folder (a second one is refused while the first holds it).
    """
    with store.training_lock(folder), TrainingLog(folder) as log:
        store.remove_temporary_files(folder)
        return _train(target, config, folder, report, stop_after, about, log)


def _train(
    target, config: TrainConfig, folder: Path, report, stop_after: int | None, about: dict | None, log: TrainingLog
) -> dict:
    torch.manual_seed(config.seed)  # before the networks are made: their first weights come from it
    env_config = config.env
    env = make_env(target, env_config)
    agent = make_agent(env, config.sac)
    space = env.observation_space
    tactile_shape = space["tactile"].shape if "tactile" in space.spaces else None
    buffer = ReplayBuffer(
        min(config.sac.buffer_size, config.steps),
        vector_size(space, config.sac.score_input),
        tactile_shape,
        env.action_space.shape[0],
    )
    rng = np.random.default_rng(config.seed)
    explorer = Explorer(config.explore, env.action_space.shape[0], env_config, rng)
    step, episode, update_debt, evaluations = 0, 0, 0.0, []
    best, best_tensors = None, None  # the best evaluation so far and its policy's tensors
    seconds_before = 0.0  # wall-clock time spent before an interruption

    checkpoint = store.load_checkpoint(folder)
    if checkpoint is not None:  # continue an interrupted run exactly
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
        env.reset(seed=config.seed)  # creates the env's generator, then restore its state
        env.np_random.bit_generator.state = state["env_rng"]
        observation, _ = env.reset()
        report(Progress(step, config.steps, resumed=True))
    else:
        observation, _ = env.reset(seed=config.seed)
        state = {}
    log.start(resumed_at=step if checkpoint is not None else None)
    explorer.reset()
    # an evaluation that was due (but waited for exploration to end) stays due
    next_eval = state.get("next_eval", (step // config.eval_every + 1) * config.eval_every)
    next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
    episode_return, losses, final = 0.0, None, None
    started = time.perf_counter()

    while step < config.steps:
        vector, tactile = agent.split(observation)
        taught = explorer.teach(observation)  # the scripted pianist's action here, or None
        if step < config.sac.exploration_steps:
            action = explorer.act(observation, taught)
        else:
            action = agent.sample(vector, tactile)
        observation, reward, terminated, truncated, _ = env.step(action)
        next_vector, next_tactile = agent.split(observation)
        buffer.add(vector, tactile, action, reward, terminated, next_vector, next_tactile, expert=taught)
        episode_return += reward
        step += 1

        if step > config.sac.exploration_steps:  # learn
            update_debt += config.sac.update_ratio
            while update_debt >= 1.0:
                losses = agent.update(buffer.sample(config.sac.batch_size, rng))
                update_debt -= 1.0

        if terminated or truncated:
            episode += 1
            report(Progress(step, config.steps, episode_return=episode_return, losses=losses))
            figures = None
            if step >= next_eval and step > config.sac.exploration_steps:
                figures = evaluate(agent, target, env_config, config.eval_episodes)
                temperature = {k: round(losses[k], 4) for k in ("alpha", "entropy")} if losses else {}
                evaluations.append({"step": step, **figures, **temperature})
                if better(figures, best):
                    best, best_tensors = {"step": step, **figures}, agent.tensors(with_training_state=False)
                report(Progress(step, config.steps, eval_f1=figures["f1"]))
                next_eval = (step // config.eval_every + 1) * config.eval_every
            seconds = seconds_before + time.perf_counter() - started
            log.row(step, episode, seconds, episode_return, losses, figures)
            episode_return = 0.0
            if figures is not None and config.until_f1 is not None and figures["f1"] >= config.until_f1:
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
                    "env_rng": env.np_random.bit_generator.state,
                    "buffer_size": buffer.size,
                    "buffer_cursor": buffer.cursor,
                    "best": best,
                    "next_eval": next_eval,
                    "seconds": seconds,
                }
                kept = {BEST_PREFIX + k: v for k, v in (best_tensors or {}).items()}
                store.save_checkpoint(
                    folder, {**agent.tensors(), "torch_rng": torch.get_rng_state(), **kept}, state, buffer
                )
                next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
            if stop_after is not None and step >= stop_after:
                env.close()
                return {"interrupted_at": step}
            observation, _ = env.reset()
            explorer.reset()
        elif step % 200 == 0:
            report(Progress(step, config.steps))
    env.close()

    tensors = agent.tensors(with_training_state=False)
    if final is None:
        final = {"step": step, **evaluate(agent, target, env_config, config.eval_episodes)}
        evaluations.append(final)
        if best is not None and better(best, final):  # an earlier policy played better: keep that one
            final, tensors = best, best_tensors
    manifest = {
        **(about or {}),
        "target": target if isinstance(target, str) else [asdict(n) for n in target.notes],
        "steps": step,
        "updates": agent.updates,
        "seconds": round(seconds_before + time.perf_counter() - started, 1),  # across interruptions
        "evaluation": final,
        "evaluations": evaluations,
        "config": to_dict(config),
    }
    store.save_policy(folder, tensors, manifest)
    store.drop_checkpoint(folder)
    log.plot()
    report(Progress(step, config.steps, finished=True))
    return manifest
