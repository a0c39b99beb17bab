"""Stored policies: the agent a model's manifest describes, with its weights loaded.

Performing needs only this module, not the training loop: a manifest records the environment
and agent configurations a policy was trained with (rebuilt by :func:`pianobot.config.from_dict`)
and what it was trained on, a phrase or a task family's name (:func:`policy_env` rebuilds its
environment), and ``policy.safetensors`` holds its actor and encoder, loaded on the CPU whatever
device trained them. A loaded :class:`SAC` has the controller interface (``reset()``,
``act(observation)``).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.tasks import make_env
from pianobot.config import ConfigError, from_dict
from pianobot.env.piano import EnvConfig, PianoEnv, finger_counts, idle_pose
from pianobot.errors import PianobotError, SettingError, quote
from pianobot.music.piece import Note, Piece
from pianobot.music.tasks import FAMILIES

if TYPE_CHECKING:
    import torch

    from pianobot.agent.sac import SAC


def make_agent(env, config: SACConfig, device: str | torch.device = "cpu", training: bool = True) -> SAC:
    """A fresh agent, on ``device``, for the observation and action spaces of ``env`` (a
    :class:`PianoEnv`, or a gymnasium vector of them); ``training`` False: only what acting needs."""
    from pianobot.agent.actors import finger_layout
    from pianobot.agent.sac import SAC, score_size, vector_size  # torch: only once an agent is built

    space = getattr(env, "single_observation_space", env.observation_space)
    actions = getattr(env, "single_action_space", env.action_space)
    tactile = space["tactile"].shape if "tactile" in space.spaces else None
    score = config.score_input
    return SAC(
        vector_size(space, score),
        score_size(space, score),
        tactile,
        actions.shape[0],
        config,
        device,
        finger_layout(space, finger_counts(_env_config(env))),
        training,
    )


def _env_config(env) -> EnvConfig:
    """The :class:`EnvConfig` of a :class:`PianoEnv` (wrapped or not) or of a gymnasium vector of them."""
    if hasattr(env, "get_attr"):
        return env.get_attr("config")[0]
    return env.unwrapped.config


def policy_configs(folder: Path) -> tuple[EnvConfig, SACConfig]:
    """The environment and agent configurations the policy in ``folder`` was trained with, with no
    simulation window (``world.gui``): whether one is shown is the caller's choice, never a file's."""
    manifest = store.read_manifest(folder)
    try:
        env = from_dict(EnvConfig, manifest["config"]["env"], "config.env")
        sac = from_dict(SACConfig, manifest["config"]["sac"], "config.sac")
        idle_pose(env.world)  # a hand that can reach the keys at all
        return replace(env, world=replace(env.world, gui=False)), sac
    except ConfigError as e:
        raise SettingError(
            f"{folder / store.MANIFEST_FILE}: {e}: retrain the phrase with jobs.force", "jobs.force"
        ) from None
    except ValueError as e:
        raise SettingError(
            f"{folder / store.MANIFEST_FILE} describes a world pianobot cannot build ({e}): retrain the phrase with "
            "jobs.force",
            "jobs.force",
        ) from None


def policy_target(folder: Path) -> Piece | str:
    """What the policy in ``folder`` was trained on, as its manifest records it: its phrase (a
    Piece), or the name of its task family (one of :data:`~pianobot.music.tasks.FAMILIES`)."""
    target = store.read_manifest(folder).get("target")
    where = folder / store.MANIFEST_FILE
    if isinstance(target, str):
        if target not in FAMILIES:
            raise SettingError(
                f"{where}: task {quote(target)} is not one pianobot knows ({', '.join(FAMILIES)}): retrain with "
                "jobs.force",
                "jobs.force",
            )
        return target
    try:
        return Piece(tuple(Note(**note) for note in target))
    except (TypeError, ValueError, PianobotError) as e:
        raise SettingError(
            f"{where} does not record the phrase it was trained on ({e}): retrain with jobs.force", "jobs.force"
        ) from None


def policy_env(folder: Path) -> PianoEnv:
    """The environment the policy in ``folder`` was trained in, rebuilt from its manifest: its
    phrase, or fresh instances of its task family each episode (of a ``parts`` policy trained with
    given parts, ``train --pieces``, the family's own instances only: the manifest's ``given`` says
    which folder the rest came from, not the parts themselves)."""
    env_config, _ = policy_configs(folder)
    return make_env(policy_target(folder), env_config)


def load_policy(folder: Path, env: PianoEnv) -> SAC:
    """The policy stored in ``folder``, acting in ``env`` (which must have the observation
    layout it was trained with: see :func:`policy_configs`)."""
    _, sac_config = policy_configs(folder)
    agent = make_agent(env, sac_config, training=False)
    tensors = store.load_tensors(folder / store.POLICY_FILE)
    try:
        agent.load_tensors(tensors, with_training_state=False)
    except ValueError as e:
        raise SettingError(
            f"{folder / store.POLICY_FILE} does not fit its manifest's configuration ({e}): retrain the phrase with "
            "jobs.force",
            "jobs.force",
        ) from None
    return agent
