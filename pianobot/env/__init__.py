"""The gymnasium environment (:mod:`pianobot.env.piano`) and its rewards (:mod:`pianobot.env.rewards`).

The ids ``pianobot/Piano-v0`` (give ``piece=``) and one per task family (``pianobot/OneNote-v0``,
``pianobot/ThreeNote-v0``, ...) are registered with gymnasium on ``import pianobot``; the
simulator is imported only when ``gymnasium.make`` builds one. The ``melody`` family has no id:
its phrases are fingered by the planner, above this layer; ``pianobot.agent.tasks.make_env("melody",
config)`` makes its environment.
"""

from __future__ import annotations

import gymnasium as gym

from pianobot.music.tasks import TASKS

ENTRY_POINT = "pianobot.env.piano:PianoEnv"


def env_id(task: str) -> str:
    """The gymnasium id of a task family, e.g. 'three-note' -> 'pianobot/ThreeNote-v0'."""
    return "pianobot/" + "".join(part.capitalize() for part in task.split("-")) + "-v0"


def register_envs() -> None:
    """Register ``pianobot/Piano-v0`` and one id per task family (once)."""
    if "pianobot/Piano-v0" in gym.registry:
        return
    gym.register(id="pianobot/Piano-v0", entry_point=ENTRY_POINT)
    for task in TASKS:
        gym.register(id=env_id(task), entry_point=ENTRY_POINT, kwargs={"task": task})


register_envs()
