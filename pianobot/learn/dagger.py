"""Training by imitation: DAgger (Ross, Gordon and Bagnell, 2011) from the scripted pianist.

Not in the paper, and not the default learner (``TrainConfig.learner``): the paper trains SAC
from rewards. The scripted pianist (:mod:`pianobot.pianist.scripted`) plays random melodies
nearly perfectly (docs/benchmarks.md), and it can say what it would do in any state, also in those
it never leads to itself; a policy that copies it learns a task family in a fraction of SAC's
steps, which is how the general policy is trained (docs/training.md).

:func:`dagger_policy` is the loop, to be read top to bottom. It runs in rounds of
``DaggerConfig.round_steps`` environment steps:

1. gather: every step is labelled with the teacher's noise-free action. In round 0 the teacher
   plays every episode, with the scripted exploration's per-episode noise (the noisy episodes
   show the learner the states a mistake leads to, as in DART); in round r an episode is the
   teacher's with probability ``teacher_share ** r`` and the policy's otherwise (with
   ``hold_guard``, the policy's through the hold guard, as `pianobot play` plays it);
2. learn: ``updates_per_step`` gradient steps of behaviour cloning per step gathered
   (:class:`~pianobot.agent.imitation.Imitation`), on batches drawn from everything gathered
   so far (up to ``dataset_size`` steps, the oldest dropped first), with a step size that falls
   along a cosine from ``learning_rate`` at the run's first step to ``final_learning_rate`` at
   its last;
3. evaluate the policy as :func:`~pianobot.learn.train.train_policy` does (same hand starts,
   same instances), keep the best, and write a checkpoint: the same command resumes there.

A round ends at the first episode end after its steps, so the last one may run past ``steps``
by part of an episode. The run stops after its last round, or at an evaluation reaching ``TrainConfig.stop_f1``
(fine-tuning from the general policy evaluates the start first, as SAC's loop does, and stores
nothing when the start already reaches it, and no policy when no round beats the start). The
stored policy is the best evaluated one, with
the files of a SAC policy (actor and encoder); it has no critic, so SAC fine-tuning from it
begins with fresh Q heads. The run's set-up, beginning, start evaluation, best policy,
checkpoints and manifest are SAC's too: :mod:`pianobot.learn.run`.
"""

from __future__ import annotations

import math

import numpy as np

from pianobot.agent.imitation import Imitation
from pianobot.env.piano import EnvConfig
from pianobot.learn.explore import Explorer
from pianobot.learn.run import Progress, Run, evaluate, open_run
from pianobot.perform.guard import HoldGuard


class GuardedAction:
    """The hold guard (:class:`~pianobot.perform.guard.HoldGuard`) over the policy's actions in one
    environment: ``act(observation, action)`` is the policy's ``action`` as the guard passes it on."""

    def __init__(self, env: EnvConfig):
        self.proposed = _Proposed()
        self.guard = HoldGuard(self.proposed, env)

    def reset(self) -> None:
        """A new episode."""
        self.guard.reset()

    def act(self, observation: dict, action: np.ndarray) -> np.ndarray:
        self.proposed.action = action
        return self.guard.act(observation)


class _Proposed:
    """The policy, as the hold guard asks it: the action it has already chosen."""

    action: np.ndarray | None = None

    def reset(self) -> None:
        pass

    def act(self, observation: dict) -> np.ndarray:
        return self.action


def dagger_policy(target, config, folder, report=lambda p: None, stop_after=None, about=None, start=None) -> dict:
    """Train one policy for a phrase or a task family by DAgger; store it in ``folder``. The
    arguments (and their types) are :func:`~pianobot.learn.train.train_policy`'s; ``stop_after``
    interrupts the run at the first round end after that many steps."""
    with open_run(target, config, folder, report, about, start, evaluate, critic=False) as run:
        return _dagger(run, stop_after)


def _dagger(run: Run, stop_after: int | None) -> dict:
    settings = run.config.dagger
    agent, dataset, rng = run.setup(settings.dataset_size)
    learner = Imitation(agent, settings.learning_rate)
    observations, state, saved = run.begin(agent, dataset, rng)  # afresh (from the start policy) or from a checkpoint
    if run.resumed:
        learner.load_tensors(saved)  # Adam's moments
    config, envs, n = run.config, run.envs, run.config.envs
    action_size = envs.single_action_space.shape[0]
    teachers = [Explorer("scripted", action_size, config.env, rng) for _ in range(n)]  # one per environment
    guards = [GuardedAction(config.env) for _ in range(n)] if settings.hold_guard else None
    step, episode, rounds = state["step"], state["episode"], state.get("rounds", 0)
    losses, returns = None, np.zeros(n)
    final = run.evaluate_start(agent)  # fine-tuning: the start's figures, when it already plays well enough

    def new_episodes(which: np.ndarray) -> np.ndarray:  # who plays each new episode: True for the teacher
        for i in np.flatnonzero(which):
            teachers[i].reset()
            if guards:
                guards[i].reset()
        return rng.random(n) < settings.teacher_share**rounds

    teacher_plays = new_episodes(np.ones(n, bool))
    while final is None and step < config.steps and not run.finishing:
        # 1. gather a round's steps, every one labelled with the teacher's action
        round_end = min(step + settings.round_steps, config.steps)
        gathered = 0
        while True:
            vectors, tactiles = agent.split_batch(observations)
            each = [{k: v[i] for k, v in observations.items()} for i in range(n)]
            taught = [teacher.teach(o) for teacher, o in zip(teachers, each)]
            actions = agent.act_batch(vectors, tactiles)
            for i in range(n):
                if teacher_plays[i]:
                    actions[i] = teachers[i].act(each[i], taught[i])
                elif guards:
                    actions[i] = guards[i].act(each[i], actions[i])
            observations, rewards, terminations, truncations, _ = envs.step(actions)
            next_vectors, next_tactiles = agent.split_batch(observations)
            dataset.add_batch(vectors, tactiles, actions, rewards, terminations, next_vectors, next_tactiles, taught)
            returns += rewards
            step += n
            gathered += n
            ended = terminations | truncations
            if ended.any():
                seconds = run.seconds()
                for i in np.flatnonzero(ended):
                    episode += 1
                    run.report(Progress(step, config.steps, episode_return=float(returns[i]), losses=losses))
                    run.log.row(step, episode, seconds, float(returns[i]), losses, None)
                    returns[i] = 0.0
                if step >= round_end:
                    break  # (the other environments' episodes go on in the next round)
                observations, _ = envs.reset(options={"reset_mask": ended})
                teacher_plays = np.where(ended, new_episodes(ended), teacher_plays)
            elif step % 200 < n:
                run.report(Progress(step, config.steps))

        # 2. learn from everything gathered so far, the step size falling along a cosine over the run
        count = max(1, round(settings.updates_per_step * gathered))
        for u in range(count):
            done = min(1.0, (step - gathered + gathered * u / count) / config.steps)
            low, high = settings.final_learning_rate, settings.learning_rate
            learner.set_learning_rate(low + 0.5 * (high - low) * (1 + math.cos(math.pi * done)))
            losses = learner.update(dataset.sample(settings.batch_size, rng, agent.device))
        rounds += 1

        # 3. evaluate, keep the best, checkpoint
        figures = run.evaluate(agent)
        run.evaluations.append({"step": step, "round": rounds, **figures})
        run.keep_if_best(step, figures, agent)
        run.log.evaluation(step, run.seconds(), figures, episode)
        run.report(Progress(step, config.steps, eval_f1=figures["f1"], losses=losses))
        if run.reached(figures):
            final = {"step": step, **figures}
            break
        if step < config.steps:
            run.checkpoint(agent, dataset, rng, step, episode, {"rounds": rounds}, learner.tensors())
        if stop_after is not None and step >= stop_after:
            return {"interrupted_at": step}
        observations, _ = envs.reset(options={"reset_mask": ended})  # the episodes that ended the round
        teacher_plays = np.where(ended, new_episodes(ended), teacher_plays)

    if final is None and run.best is None:  # (finished at a checkpoint written before any evaluation)
        figures = run.evaluate(agent)
        run.evaluations.append({"step": step, "round": rounds, **figures})
        run.keep_if_best(step, figures, agent)
    if final is None:  # every round ended in an evaluation: the best of them is the policy
        final, tensors = run.best, run.best_tensors
    else:
        tensors = run.policy_tensors(agent)
    return run.finish(agent, step, final, tensors)
