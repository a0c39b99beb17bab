"""The scripted pianist: a hand-written controller with the interface a trained policy has
(``reset()``, then ``act(observation) -> action``).

It plays from the score window in the observation with human priors:
  the wrist slides so the assigned fingers can reach their keys, abduction puts each fingertip
  over its key, and the assigned finger strikes at the speed that the keyboard's velocity
  curve turns into the target velocity, starting early enough to land on the onset.

The scripted pianist reads only the observation (score window, wrist, joint angles) and the
hand's and keyboard's geometry; it is the proof that the simulator is playable. Its parts:

- :mod:`~pianobot.pianist.strikes`: the timing and velocity of strikes: which key each finger
  plays next, from how high, how fast and when it lets go (a :class:`~pianobot.pianist.strikes.Plan`
  per finger and step);
- :mod:`~pianobot.pianist.motion`: the plans as joint speeds: the wrist's slide, the
  fingertips' waypoints and the inverse kinematics;
- :mod:`~pianobot.pianist.layout`: the keyboard's geometry as both see it;
- :mod:`~pianobot.pianist.tuning`: its tuning constants (:class:`PianistTuning`), with units.
"""

from __future__ import annotations

import numpy as np

from pianobot.env.piano import EnvConfig, actuated_indices
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.motion import Motion
from pianobot.pianist.strikes import StrikePlanner
from pianobot.pianist.tuning import PianistTuning, tuning_for
from pianobot.sim.hand import JOINT_KINDS


class ScriptedPianist:
    """A hand-written pianist for velocity or position control. See the module docstring."""

    def __init__(self, config: EnvConfig, tuning: PianistTuning | None = None):
        if config.world.control not in ("velocity", "position"):
            raise ValueError("the scripted pianist drives joint speeds or angles: use control='velocity' or 'position'")
        self.config = config
        self.tuning = tuning = tuning or tuning_for(config.world.hand)
        self.fingers = config.world.hand.spec.fingers
        model = config.world.hand.model
        if any(model.joints_of(f) != JOINT_KINDS for f in self.fingers):
            raise ValueError(
                f"the scripted pianist moves fingers with {', '.join(JOINT_KINDS)} joints, which not every finger "
                f"of the {model.name} hand has"
            )
        self.layout = KeyLayout(config.world)
        self.strikes = StrikePlanner(config.world, self.layout, tuning)
        self.motion = Motion(config.world, self.layout, tuning)
        self.actuated = actuated_indices(config)  # the joints the environment's actions move
        self.reset()

    def reset(self) -> None:
        """Forget the previous step: the next observation starts an episode."""
        self.previous_row: np.ndarray | None = None
        """The score row of the previous step: a note on in it too began earlier (hold, do not strike)."""
        self.released: frozenset[tuple[int, int]] = frozenset()
        """(finger, key) of the notes let go before their written end (not pressed again while they last)."""

    def act(self, observation: dict) -> np.ndarray:
        """One action from the score window, the wrist position and the joint angles."""
        score = observation["score"]
        joints = np.asarray(observation["joints"], dtype=float).reshape(len(self.fingers), len(JOINT_KINDS))
        wrist = (float(observation["wrist"][0]) + 1) / 2 * self.layout.width
        tips = {finger: self.motion.tip(q) for finger, q in zip(self.fingers, joints)}
        plans = self.strikes.plan(score, self.previous_row, tips, wrist, self.released)
        held = self.strikes.held(score, self.previous_row)  # (a note let go stays let go until it ends)
        self.released = frozenset(
            (finger, key)
            for finger, key in held.items()
            if (finger, key) in self.released
            or not (finger in plans and plans[finger].phase == "hold" and plans[finger].key == key)
        )
        self.previous_row = score[0].copy()
        action = self.motion.command(plans, joints, wrist)[self.actuated]
        if "pedal" in observation:  # (the pedal is an action: the foot follows the score)
            action = np.append(action, 1.0 if observation["pedal"][0] > 0.5 else -1.0)
        return action
