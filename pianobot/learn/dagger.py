"""Training by imitation: DAgger (Ross, Gordon and Bagnell, 2011) from the scripted pianist.

Not in the paper, and not the default learner (``TrainConfig.learner``): the paper trains SAC
from rewards. The scripted pianist (:mod:`pianobot.pianist.scripted`) plays random melodies at
note F1 0.999 (docs/benchmarks.md), and it can say what it would do in any state, also in those
it never leads to itself; a policy that copies it learns a task family in a fraction of SAC's
steps, which is how the general policy is trained (docs/training.md).

:func:`dagger_policy` is the loop, to be read top to bottom. It runs in rounds of
``DaggerConfig.round_steps`` environment steps:

1. gather: every step is labelled with the teacher's noise-free action. In round 0 the teacher
   plays every episode, with the scripted exploration's per-episode noise (the noisy episodes
   show the learner the states a mistake leads to, as in DART); in round r an episode is the
   teacher's with probability ``teacher_share ** r`` and the policy's otherwise;
2. learn: ``updates_per_step`` gradient steps of behaviour cloning per step gathered
   (:class:`~pianobot.agent.imitation.Imitation`), on batches drawn from everything gathered
   so far (up to ``dataset_size`` steps, the oldest dropped first), with a step size that falls
   along a cosine from ``learning_rate`` at the run's first step to ``final_learning_rate`` at
   its last;
3. evaluate the policy as :func:`~pianobot.learn.train.train_policy` does (same hand starts,
   same instances), keep the best, and write a checkpoint: the same command resumes there.

A round ends at the first episode end after its steps, so the last one may run past ``steps``
by part of an episode. The run stops after its last round, or at an evaluation reaching ``TrainConfig.stop_f1``
(fine-tuning from the general policy evaluates the start first, as SAC's loop does). The stored
policy is the best evaluated one, with the files of a SAC policy (actor and encoder); it has no
critic, so SAC fine-tuning from it begins with fresh Q heads.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Callable

import numpy as np
import torch

from pianobot.agent import general, store
from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.imitation import Imitation
from pianobot.agent.policy import make_agent
from pianobot.agent.sac import resolve_device, vector_size
from pianobot.config import to_dict
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.learn.explore import Explorer
from pianobot.learn.log import TrainingLog
from pianobot.learn.train import (
    BEST_PREFIX,
    Progress,
    better,
    env_generators,
    evaluate,
    make_envs,
    resume_envs,
    split_kept,
)
from pianobot.music.piece import Piece


def dagger_policy(
    target: Piece | str,
    config: TrainConfig,
    folder: Path,
    report: Callable[[Progress], None] = lambda p: None,
    stop_after: int | None = None,
    about: dict | None = None,
    start: Path | None = None,
) -> dict:
    """Train one policy for a phrase or a task family by DAgger; store it in ``folder``. The
    arguments are :func:`~pianobot.learn.train.train_policy`'s; ``stop_after`` interrupts the
    run at the first round end after that many steps."""
    if start is not None and not config.from_general:
        raise ValueError("a start policy was given to a run with from_general=False")
    with store.training_lock(folder), TrainingLog(folder) as log:
        store.remove_temporary_files(folder)
        device = resolve_device(config.device)
        with contextlib.closing(make_envs(target, config.env, config.envs)) as envs:
            return _dagger(target, config, folder, report, stop_after, about, log, envs, device, start)


def _dagger(target, config: TrainConfig, folder: Path, report, stop_after, about, log, envs, device, start) -> dict:
    torch.manual_seed(config.seed)
    env_config, n, settings = config.env, config.envs, config.dagger
    agent = make_agent(envs, config.sac, device)
    learner = Imitation(agent, settings.learning_rate)
    space, action_size = envs.single_observation_space, envs.single_action_space.shape[0]
    tactile_shape = space["tactile"].shape if "tactile" in space.spaces else None
    dataset = ReplayBuffer(
        min(settings.dataset_size, config.steps), vector_size(space, config.sac.score_input), tactile_shape, action_size
    )
    rng = np.random.default_rng(config.seed)
    teachers = [Explorer("scripted", action_size, env_config, rng) for _ in range(n)]  # one per environment
    step, episode, rounds, evaluations = 0, 0, 0, []
    best, best_tensors, began, seconds_before = None, None, None, 0.0

    checkpoint = store.load_checkpoint(folder)
    if checkpoint is not None:  # continue an interrupted run from its last round's end
        tensors, state, data_folder = checkpoint
        agent.load_tensors({k: v for k, v in tensors.items() if not k.startswith(BEST_PREFIX)})
        learner.load_tensors(tensors)
        best = state.get("best")
        best_tensors = {k[len(BEST_PREFIX) :]: v for k, v in tensors.items() if k.startswith(BEST_PREFIX)} or None
        torch.set_rng_state(tensors["torch_rng"])
        dataset.load(data_folder, state["buffer_size"], state["buffer_cursor"])
        rng.bit_generator.state = state["rng"]
        step, episode, rounds, evaluations = state["step"], state["episode"], state["rounds"], state["evaluations"]
        agent.updates = state["updates"]
        seconds_before, began = state["seconds"], state["start"]
        observations = resume_envs(envs, state["env_rng"], config.seed, step)
        report(Progress(step, config.steps, resumed=True))
    else:
        if start is not None:  # fine-tuning: the start policy's actor and encoder
            began = general.describe(start)
            try:
                agent.load_start(*general.start_tensors(start))
            except ValueError as e:
                raise PianobotError(
                    f"the policy {start} does not fit this run's networks ({e}): train with its options, or from scratch"
                ) from None
        observations, _ = envs.reset(seed=config.seed)
    config = replace(config, from_general=began is not None)

    def policy_tensors() -> dict[str, torch.Tensor]:  # what a stored policy keeps: actor and encoder
        return agent.tensors(with_training_state=False)

    started = time.perf_counter()
    log.start(resumed_at=step if checkpoint is not None else None)
    final, losses, returns = None, None, np.zeros(n)
    if began is not None and checkpoint is None:  # evaluate the start before any step: it counts
        figures = evaluate(agent, target, env_config, config.eval_episodes)
        evaluations.append({"step": 0, **figures})
        best, best_tensors = {"step": 0, **figures}, policy_tensors()
        log.evaluation(0, time.perf_counter() - started, figures)
        report(Progress(0, config.steps, eval_f1=figures["f1"]))
        if config.stop_f1 is not None and figures["f1"] >= config.stop_f1:
            final = {"step": 0, **figures}

    def new_episodes(which: np.ndarray) -> np.ndarray:  # who plays each new episode: True for the teacher
        for i in np.flatnonzero(which):
            teachers[i].reset()
        return rng.random(n) < settings.teacher_share**rounds

    teacher_plays = new_episodes(np.ones(n, bool))
    while final is None and step < config.steps:
        # 1. gather a round's steps, every one labelled with the teacher's action
        round_end = min(step + settings.round_steps, config.steps)
        gathered = 0
        while True:
            vectors, tactiles = agent.split_batch(observations)
            each = [{k: v[i] for k, v in observations.items()} for i in range(n)]
            taught = [teacher.teach(o) for teacher, o in zip(teachers, each)]
            actions = agent.act_batch(vectors, tactiles)
            for i in np.flatnonzero(teacher_plays):
                actions[i] = teachers[i].act(each[i], taught[i])
            observations, rewards, terminations, truncations, _ = envs.step(actions)
            next_vectors, next_tactiles = agent.split_batch(observations)
            dataset.add_batch(vectors, tactiles, actions, rewards, terminations, next_vectors, next_tactiles, taught)
            returns += rewards
            step += n
            gathered += n
            ended = terminations | truncations
            if ended.any():
                seconds = seconds_before + time.perf_counter() - started
                for i in np.flatnonzero(ended):
                    episode += 1
                    report(Progress(step, config.steps, episode_return=float(returns[i]), losses=losses))
                    log.row(step, episode, seconds, float(returns[i]), losses, None)
                    returns[i] = 0.0
                if step >= round_end:
                    break  # (the other environments' episodes go on in the next round)
                observations, _ = envs.reset(options={"reset_mask": ended})
                teacher_plays = np.where(ended, new_episodes(ended), teacher_plays)
            elif step % 200 < n:
                report(Progress(step, config.steps))

        # 2. learn from everything gathered so far, the step size falling along a cosine over the run
        count = max(1, round(settings.updates_per_step * gathered))
        for u in range(count):
            done = min(1.0, (step - gathered + gathered * u / count) / config.steps)
            low, high = settings.final_learning_rate, settings.learning_rate
            learner.set_learning_rate(low + 0.5 * (high - low) * (1 + math.cos(math.pi * done)))
            losses = learner.update(dataset.sample(settings.batch_size, rng, agent.device))
        rounds += 1

        # 3. evaluate, keep the best, checkpoint
        figures = evaluate(agent, target, env_config, config.eval_episodes)
        evaluations.append({"step": step, "round": rounds, **figures})
        if better(figures, best):
            best, best_tensors = {"step": step, **figures}, policy_tensors()
        seconds = seconds_before + time.perf_counter() - started
        log.evaluation(step, seconds, figures, episode)
        report(Progress(step, config.steps, eval_f1=figures["f1"], losses=losses))
        if config.stop_f1 is not None and figures["f1"] >= config.stop_f1:
            final = {"step": step, **figures}
            break
        if step < config.steps:
            state = {
                "step": step,
                "episode": episode,
                "rounds": rounds,
                "updates": agent.updates,
                "evaluations": evaluations,
                "rng": rng.bit_generator.state,
                "env_rng": env_generators(envs),
                "buffer_size": dataset.size,
                "buffer_cursor": dataset.cursor,
                "best": best,
                "seconds": seconds,
                "start": began,
            }
            kept = {BEST_PREFIX + k: v for k, v in (best_tensors or {}).items()}
            store.save_checkpoint(
                folder,
                {**agent.tensors(), **learner.tensors(), "torch_rng": torch.get_rng_state(), **kept},
                state,
                dataset,
            )
        if stop_after is not None and step >= stop_after:
            return {"interrupted_at": step}
        observations, _ = envs.reset(options={"reset_mask": ended})  # the episodes that ended the round
        teacher_plays = np.where(ended, new_episodes(ended), teacher_plays)

    if final is None:  # every round ended in an evaluation: the best of them is the policy
        final, tensors = best, best_tensors
    else:
        tensors = policy_tensors()
    manifest = {
        **(about or {}),
        "target": target if isinstance(target, str) else [asdict(note) for note in target.notes],
        "steps": step,
        "updates": agent.updates,
        "seconds": round(seconds_before + time.perf_counter() - started, 1),
        "device": agent.device.type,
        "start": began,
        "evaluation": final,
        "evaluations": evaluations,
        "config": to_dict(config),
    }
    policy, _ = split_kept(tensors)
    store.save_policy(folder, policy, manifest)
    store.drop_checkpoint(folder)
    log.plot()
    report(Progress(step, config.steps, finished=True))
    return manifest
