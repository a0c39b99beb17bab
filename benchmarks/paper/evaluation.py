"""Judging: every kept policy (and the baseline controllers) played with the linear reward on
fresh task instances, or a composed piece from several hand starts; an unfinished run's best
policy so far with ``--report --check``."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.learn import CHECK_SEED
from benchmarks.paper.experiments import EVAL_REWARD, SO_FAR_DIR, Options
from benchmarks.paper.runs import Run
from pianobot.agent import store
from pianobot.agent.tasks import make_env
from pianobot.config import to_dict
from pianobot.env.piano import EnvConfig
from pianobot.files import atomic_write
from pianobot.music.phrases import split_phrases
from pianobot.music.piece import Piece


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


def has_evaluation(run: Run, options: Options) -> bool:
    found = read_json(run.result)
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
    from pianobot.perform.plan import assign

    phrases = split_phrases(run.piece, run.phrase_notes)
    models = run.jobs[0].folder.parent
    config = eval_env_config(run.config.env)
    played = []
    for seed in range(hand_starts):
        episode = perform(
            run.piece, lambda env: CompositionalController(env, assign(phrases, models)), config, seed=seed
        )
        played.append((episode.total_reward, episode.report()))
    return _figures(played)


def baseline_figures(controller: str, task: str, seed: int, options: Options) -> dict:
    """A baseline controller (:data:`BASELINES`) on the task's check instances, cached."""
    path = options.store / "baselines" / f"{task}-{controller}-seed{seed}.json"
    episodes = options.check_episodes or 30
    found = read_json(path)
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
    cached = read_json(path)
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


def read_json(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
