"""The wrist guard: a learnt policy's wrist slides no faster than its teacher's while a fingertip is low.

A policy cloned from the scripted pianist learns its switch from "hold the key and ease the wrist
along" to "let go, rise, then rush to the next position" blurred by a control step: it starts the
rush while its finger is still on the key and drags the finger across the neighbouring keys,
which sound. The scripted pianist slides the wrist at most
:attr:`~pianobot.pianist.tuning.PianistTuning.hold_slide` a step while a finger holds a key, and
not at all while a finger that let go is still low over the keys
(:meth:`~pianobot.pianist.motion.Motion.low`); only during a strike may it go faster, and it
rarely does (measured: 3 of about 2500 steps over the examples and 10 random melodies). The guard
holds a policy to ``hold_slide`` whenever a fingertip is low, from the joint angles in the
observation alone, and leaves every other action as the policy chose it. It makes a drag less
likely, not impossible: a fingertip low over the keys may still slide 8 mm a step.

``pianobot play --wrist-guard`` plays the general policy through it (a phrase's own policy,
trained on its phrase until perfect, plays unguarded). It is off by default: the committed
general policy plays as well without it (docs/benchmarks.md), and unguarded it plays as
training evaluated it; a general policy that drags keys while the hand shifts plays better with it.
"""

from __future__ import annotations

import numpy as np

from pianobot.env.piano import EnvConfig
from pianobot.perform.rollout import Controller
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.motion import Motion
from pianobot.pianist.tuning import PianistTuning


class WristGuard:
    """Wraps ``policy`` (a :class:`~pianobot.perform.rollout.Controller`): while any fingertip is
    low over the keys, the wrist's action is clipped to ``tuning.hold_slide`` a control step."""

    def __init__(self, policy: Controller, config: EnvConfig, tuning: PianistTuning = PianistTuning()):
        world = config.world
        if world.discrete_wrist:
            raise ValueError("the wrist guard limits the wrist's speed: it needs discrete_wrist=False")
        self.policy = policy
        self.motion = Motion(world, KeyLayout(world), tuning)
        self.fingers = len(world.hand.spec.fingers)
        self.limit = tuning.hold_slide * world.control_hz / world.hand.max_wrist_speed
        """The wrist's largest action while a fingertip is low (its action is a share of the top speed)."""
        self.capped = 0
        """Control steps in which the guard slowed the wrist, since the guard was made."""

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: dict) -> np.ndarray:
        action = np.array(self.policy.act(observation), dtype=np.float32)  # a copy: the policy's own is left alone
        joints = np.asarray(observation["joints"], dtype=float).reshape(self.fingers, 4)
        if abs(action[-1]) > self.limit and any(self.motion.low(q) for q in joints):
            action[-1] = np.sign(action[-1]) * self.limit
            self.capped += 1
        return action
