"""Training by Soft Actor-Critic (the paper's learner): one policy per phrase, or per task family.

:func:`train_policy` is the loop, to be read top to bottom: explore, then act with the policy
and learn from the replay buffer at ``update_ratio`` gradient steps per environment step;
evaluate every ``eval_every`` steps; at the first episode end after every
``checkpoint_every`` steps, write a checkpoint that holds everything (networks, optimisers,
buffer, random generators), so that running the same command again continues exactly where an
interrupted run stopped. The policy stored at the end is the best one evaluated.
Given a ``start`` policy (fine-tuning from the general policy, :mod:`pianobot.agent.general`),
the agent begins with its weights, evaluates them before the first step, and that evaluation
counts: when the start already reaches :attr:`TrainConfig.stop_f1` the run stores nothing, and
when no later evaluation beats the start's it stores no policy (either way its manifest says
``"kept": "start"``): a stored policy played better than its start on the evaluation.
Every episode is logged beside the policy (:mod:`pianobot.learn.log`: CSV, TensorBoard, a plot).
With ``TrainConfig.envs`` > 1 the loop steps that many environments at once, in worker processes
(:func:`make_envs`); with 1, the default, its one environment in this process.

What SAC shares with the other learner (:mod:`pianobot.learn.dagger`) is :mod:`pianobot.learn.run`:
the run's set-up, its beginning (afresh, from a start policy, or from a checkpoint), the start's
evaluation, the best policy, checkpoints and the manifest. The names of that module that others
import from this one (:func:`evaluate`, :class:`Progress`, :func:`make_envs`, ...) are in ``__all__``.
Training a whole piece (one job per phrase, parallel workers) is :mod:`pianobot.learn.jobs`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from pianobot.agent.tasks import Target, make_env
from pianobot.learn.config import TrainConfig
from pianobot.learn.explore import Explorer
from pianobot.learn.run import (
    BEST_PREFIX,
    EVAL_SEED,
    TASK_EVAL_EPISODES,
    Progress,
    Run,
    best_policy_tensors,
    better,
    env_generators,
    evaluate,
    kept_tensors,
    make_envs,
    open_run,
    resume_envs,
    split_kept,
)

__all__ = [  # the loop, and the names of pianobot.learn.run that others import from here
    "BEST_PREFIX",
    "EVAL_SEED",
    "TASK_EVAL_EPISODES",
    "Progress",
    "TrainConfig",
    "best_policy_tensors",
    "better",
    "env_generators",
    "evaluate",
    "kept_tensors",
    "make_env",
    "make_envs",
    "resume_envs",
    "split_kept",
    "train_policy",
]


def train_policy(
    target: Target,
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
    are evaluated before the first step and training stops at ``config.stop_f1`` (reached at
    step 0, no policy is stored and the manifest returned says ``"kept": "start"``). Without one
    the run trains from scratch and its manifest says ``from_general: false``. A resumed run
    goes on from its checkpoint, which knows where it began. One run at a time may train into a
    folder (a second one is refused while the first holds it).
    """
    with open_run(target, config, folder, report, about, start, evaluate, critic=True) as run:
        return _train(run, stop_after)


def _train(run: Run, stop_after: int | None) -> dict:
    agent, buffer, rng = run.setup(run.config.sac.buffer_size)
    observations, state, _ = run.begin(agent, buffer, rng)  # afresh (from the start policy) or from a checkpoint
    config, envs, n = run.config, run.envs, run.config.envs
    action_size = envs.single_action_space.shape[0]
    explorers = [Explorer(config.explore, action_size, config.env, rng) for _ in range(n)]  # one per environment
    step, episode, update_debt = state["step"], state["episode"], state.get("update_debt", 0.0)
    for explorer in explorers:
        explorer.reset()
    # an evaluation that was due (but waited for exploration to end) stays due
    next_eval = state.get("next_eval", (step // config.eval_every + 1) * config.eval_every)
    next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
    returns, losses = np.zeros(n), None
    final = run.evaluate_start(agent)  # fine-tuning: the start's figures, when it already plays well enough

    finishing = run.finishing and agent.updates > 0  # (a checkpoint before any learning step trains on)
    while final is None and step < config.steps and not finishing:
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
                figures = run.evaluate(agent)
                temperature = {k: round(losses[k], 4) for k in ("alpha", "entropy")} if losses else {}
                run.evaluations.append({"step": step, **figures, **temperature})
                run.keep_if_best(step, figures, agent)
                run.report(Progress(step, config.steps, eval_f1=figures["f1"]))
                next_eval = (step // config.eval_every + 1) * config.eval_every
            seconds = run.seconds()
            logged = figures  # on the first episode's row
            for i in np.flatnonzero(ended):
                episode += 1
                run.report(Progress(step, config.steps, episode_return=float(returns[i]), losses=losses))
                run.log.row(step, episode, seconds, float(returns[i]), losses, logged)
                returns[i], logged = 0.0, None
            if figures is not None and run.reached(figures):
                final = {"step": step, **figures}  # good enough: stop here
                break
            if step >= next_checkpoint and step < config.steps:
                run.checkpoint(agent, buffer, rng, step, episode, {"update_debt": update_debt, "next_eval": next_eval})
                next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
            if stop_after is not None and step >= stop_after:
                return {"interrupted_at": step}
            observations, _ = envs.reset(options={"reset_mask": ended})
            for i in np.flatnonzero(ended):
                explorers[i].reset()
        elif step % 200 < n:
            run.report(Progress(step, config.steps))

    tensors = run.policy_tensors(agent)
    if final is None:
        final = {"step": step, **run.evaluate(agent)}
        run.evaluations.append(final)
        if run.best is not None and better(run.best, final):  # an earlier policy played better: keep that one
            final, tensors = run.best, run.best_tensors
    return run.finish(agent, step, final, tensors)
