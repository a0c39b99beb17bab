"""The world's settings (:class:`WorldConfig`) and the records :class:`~pianobot.sim.world.PianoWorld`
hands out: one hand's bodies and joints (:class:`HandBody`), what one control step did
(:class:`StepResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pianobot.config import check_ranges
from pianobot.music.tensor import ScoreSpec
from pianobot.sim.hand import HandConfig
from pianobot.sim.keyboard import KeyboardConfig, KeyEvent

CONTROL_MODES = ("velocity", "position", "torque")
LIMIT_STOP_TORQUE = 5.0
"""Torque (N m) with which a joint's mechanical stop holds it at its limit under torque control."""


@dataclass(frozen=True)
class WorldConfig:
    """Physics settings and the two bodies."""

    keyboard: KeyboardConfig = field(default_factory=KeyboardConfig)
    hand: HandConfig = field(default_factory=HandConfig)
    physics_hz: float = 240.0
    """Physics steps per second (500 Hz cost twice as much and showed no benefit)."""
    control_hz: float = ScoreSpec.control_hz
    """Control steps per second; each runs physics_hz / control_hz physics steps (the score's rate)."""
    solver_iterations: int = 50
    """Constraint solver iterations per physics step (PyBullet's default). At 15 the env steps 1.5x
    as fast, but the last finger's joints do not follow a large commanded move (docs/simulator.md)."""
    control: str = "velocity"
    """Finger joint control: 'velocity' (action = joint speed), 'position' (action = joint angle
    target, -1 and 1 at the joint's limits) or 'torque' (action = joint torque)."""
    discrete_wrist: bool = False
    """If True the wrist action picks one of the white keys' positions and the wrist servoes there."""
    gui: bool = False
    """Open PyBullet's window instead of running headless."""

    def __post_init__(self) -> None:
        if self.control not in CONTROL_MODES:
            raise ValueError(f"control must be one of {', '.join(CONTROL_MODES)}; got {self.control!r}")
        check_ranges(self, physics_hz=(1.0, 10_000.0), control_hz=(0.1, self.physics_hz), solver_iterations=(1, 1000))

    @property
    def substeps(self) -> int:
        return max(1, int(round(self.physics_hz / self.control_hz)))


@dataclass
class StepResult:
    """What one control step did."""

    events: list[KeyEvent]
    """Note-on/off events, in time order."""
    fingers: dict[int, int]
    """For every note-on in ``events``: pitch -> the finger that touched the key (if one did)."""
    pressed: np.ndarray
    """Keys that sounded at any time during the step (bool, one per key)."""
    pressed_velocity: np.ndarray
    """Their note-on velocity (int, 0 where not pressed)."""
    hands: dict[int, int] = field(default_factory=dict)
    """For every note-on in ``fingers``: pitch -> the index (in ``PianoWorld.hands``) of the hand
    whose finger it was."""


@dataclass(frozen=True)
class HandBody:
    """One hand in the world: its ``side``, its ``body``, its ``wrist``'s (prismatic) joint, its
    ``fingers``' joints in action order, and ``tips``: finger -> the link of its fingertip."""

    side: str
    body: int
    wrist: int
    fingers: tuple[int, ...]
    tips: dict[int, int]
