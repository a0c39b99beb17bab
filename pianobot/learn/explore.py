"""How the agent acts before learning starts (paper, "Exploration Strategy"), plus our stronger prior.

- ``uniform``: every action uniform in [-1, 1];
- ``repeat``: uniform, but each step repeats the previous action with probability 0.8;
- ``prior``: ``repeat`` plus the wrist stabiliser: the wrist moves in only 10 % of the steps
  (the paper's best);
- ``scripted``: the scripted pianist's action plus Gaussian noise (ours: a prior that already
  knows where the keys are). The noise's scale is drawn once per episode, log-uniformly in
  :data:`SCRIPTED_NOISE`: a strike fails with noise above about 0.02 (docs/benchmarks.md, "How
  precise must a policy be?"), so quiet episodes fill the buffer with notes played right and
  noisy ones with the states a learner's mistakes lead to.
"""

from __future__ import annotations

import numpy as np

from pianobot.env.piano import EnvConfig
from pianobot.pianist.scripted import ScriptedPianist

EXPLORATIONS = ("uniform", "repeat", "prior", "scripted")
REPEAT_PROBABILITY = 0.8
WRIST_MOVE_PROBABILITY = 0.1
SCRIPTED_NOISE = (0.005, 0.2)
"""Range of the per-episode noise scale of ``scripted`` exploration (log-uniform)."""


class Explorer:
    """``reset()`` at each episode start, then ``act(observation)``."""

    def __init__(self, kind: str, action_size: int, config: EnvConfig, rng: np.random.Generator):
        if kind not in EXPLORATIONS:
            raise ValueError(f"exploration must be one of {', '.join(EXPLORATIONS)}; got {kind!r}")
        self.kind, self.size, self.rng = kind, action_size, rng
        self.foot = int(config.pedal_action)
        """1 where the action ends with the foot (the wrist's is then the one before it)."""
        self.pianist = ScriptedPianist(config) if kind == "scripted" else None  # needs velocity or position control
        self.previous: np.ndarray | None = None
        self.noise = 0.0

    def reset(self) -> None:
        self.previous = None
        if self.pianist is not None:
            self.pianist.reset()
            low, high = np.log(SCRIPTED_NOISE)
            self.noise = float(np.exp(self.rng.uniform(low, high)))

    def teach(self, observation: dict) -> np.ndarray | None:
        """The scripted pianist's noise-free action for this step (call once per step, in order:
        it remembers the previous score row), or None when exploring without it."""
        if self.pianist is None:
            return None
        return self.pianist.act(observation)

    def act(self, observation: dict, taught: np.ndarray | None = None) -> np.ndarray:
        """An exploration action; ``taught`` is this step's :meth:`teach` result, if already asked."""
        if self.kind == "scripted":
            action = (taught if taught is not None else self.teach(observation)) + self.rng.normal(
                0.0, self.noise, self.size
            )
            return np.clip(action, -1.0, 1.0).astype(np.float32)
        action = self.rng.uniform(-1.0, 1.0, self.size).astype(np.float32)
        if self.kind in ("repeat", "prior") and self.previous is not None and self.rng.random() < REPEAT_PROBABILITY:
            action = self.previous.copy()
        if self.kind == "prior" and self.rng.random() >= WRIST_MOVE_PROBABILITY:
            action[self.size - 1 - self.foot] = 0.0  # the wrist stays where it is
        self.previous = action
        return action
