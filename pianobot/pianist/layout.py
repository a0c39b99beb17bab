"""The keyboard as the scripted pianist sees it: where each key is, how high, and where to strike it.

Both halves of the pianist use it: :mod:`~pianobot.pianist.strikes` for strike depths and
speeds, :mod:`~pianobot.pianist.motion` for where to put the wrist and the fingertips.
Positions along the keyboard (x) are in metres from its left end, the wrist's coordinate;
depths into the keyboard (y) are in metres from the keys' hinges; heights are in metres over
the white keys' top surface.
"""

from __future__ import annotations

import math

import numpy as np

from pianobot.sim.keyboard import BLACK_STRIKE_FROM_FRONT, WHITE_STRIKE_FROM_FRONT, key_boxes
from pianobot.sim.world import WorldConfig


class KeyLayout:
    """Key positions, tops and strike points of ``world``'s keyboard, for ``world``'s hand."""

    def __init__(self, world: WorldConfig):
        geometry = world.keyboard.geometry
        boxes = key_boxes(world.keyboard)
        self.key_x = np.array([b.center[0] for b in boxes])
        """Centre of each key along the keyboard (m), lowest key first."""
        self.black = np.array([b.black for b in boxes])
        """Whether each key is black."""
        self.key_top = np.where(self.black, geometry.black_rise, 0.0)
        """Height of each key's top surface (m): 0 for white keys, the black keys' rise for black ones."""
        self.width = sum(not b for b in self.black) * geometry.white_pitch
        """Length of the keyboard (m): the wrist's range."""
        self.white_length = geometry.white_length
        """Length of a white key from its hinge to its front edge (m)."""
        self.black_rise = geometry.black_rise
        """Height of the black keys' tops over the white keys' (m)."""
        self.strike_angle = world.keyboard.strike_fraction * geometry.max_angle
        """Key angle at which a key sounds (rad)."""
        self.release_angle = world.keyboard.release_fraction * geometry.max_angle
        """Key angle over which a sounding key, rising, lets its note go (rad)."""
        self.white_contact_y = geometry.white_length - WHITE_STRIKE_FROM_FRONT
        """Where on a white key the fingertip strikes (m from the hinge): the keyboard's strike point."""
        self.black_contact_y = geometry.black_length - BLACK_STRIKE_FROM_FRONT
        """Where on a black key the fingertip strikes (m from the hinge)."""
        self.black_band_y = geometry.black_length + world.hand.geometry.tip_radius
        """A fingertip closer than this to the hinges (m) is over the black keys' band."""
        self.model = world.hand.model
        """The hand model: where its fingers' bases sit on the palm."""
        self._reach_scale = {
            f: math.tan(self.model.abduction_limit(f)) / math.tan(self.model.geometry.abduction_limit)
            for f in self.model.fingers
        }

    def contact_y(self, key: int) -> float:
        """Where on ``key`` the fingertip strikes (m from the hinge)."""
        return self.black_contact_y if self.black[key] else self.white_contact_y

    def reach_scale(self, finger: int) -> float:
        """How far ``finger`` turns sideways beside the model's fingers (the tan of its abduction
        limit over theirs): the scripted pianist's sideways reaches (``hold_reach``,
        ``strike_reach``) are for those, and a thumb that turns farther reaches farther."""
        return self._reach_scale[finger]

    def wrist_for(self, finger: int, key: int) -> float:
        """Wrist position that puts ``finger`` straight over ``key`` (m)."""
        return float(self.key_x[key] - self.model.base_x(finger))
