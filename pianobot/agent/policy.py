"""Stored policies: the agent a model's manifest describes, with its weights loaded.

Performing needs only this module, not the training loop: a manifest records the environment
and agent configurations a policy was trained with (rebuilt by :func:`pianobot.config.from_dict`),
and ``policy.safetensors`` holds its actor and encoder. A loaded :class:`SAC` has the controller
interface (``reset()``, ``act(observation)``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.config import ConfigError, from_dict
from pianobot.env.piano import EnvConfig, PianoEnv, idle_pose
from pianobot.errors import PianobotError

if TYPE_CHECKING:
    from pianobot.agent.sac import SAC


def make_agent(env: PianoEnv, config: SACConfig) -> SAC:
    """A fresh agent for this environment's observation and action spaces."""
    from pianobot.agent.sac import SAC, score_size, vector_size  # torch: only once an agent is built

    space = env.observation_space
    tactile = space["tactile"].shape if "tactile" in space.spaces else None
    score = config.score_input
    return SAC(vector_size(space, score), score_size(space, score), tactile, env.action_space.shape[0], config)


def policy_configs(folder: Path) -> tuple[EnvConfig, SACConfig]:
    """The environment and agent configurations the policy in ``folder`` was trained with."""
    manifest = store.read_manifest(folder)
    try:
        env = from_dict(EnvConfig, manifest["config"]["env"], "config.env")
        sac = from_dict(SACConfig, manifest["config"]["sac"], "config.sac")
        idle_pose(env.world)  # a hand that can reach the keys at all
        return env, sac
    except ConfigError as e:
        raise PianobotError(f"{folder / store.MANIFEST_FILE}: {e}: retrain the phrase with --force") from None
    except ValueError as e:
        raise PianobotError(
            f"{folder / store.MANIFEST_FILE} describes a world pianobot cannot build ({e}): retrain the phrase with --force"
        ) from None


def load_policy(folder: Path, env: PianoEnv) -> SAC:
    """The policy stored in ``folder``, acting in ``env`` (which must have the observation
    layout it was trained with: see :func:`policy_configs`)."""
    _, sac_config = policy_configs(folder)
    agent = make_agent(env, sac_config)
    tensors = store.load_tensors(folder / store.POLICY_FILE)
    try:
        agent.load_tensors(tensors, with_training_state=False)
    except ValueError as e:
        raise PianobotError(
            f"{folder / store.POLICY_FILE} does not fit its manifest's configuration ({e}): retrain the phrase with --force"
        ) from None
    return agent
