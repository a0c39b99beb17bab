"""One hand of a two-hand world as its player sees it: a right hand on a keyboard of its own.

A player (the scripted pianist, a policy) knows one right hand over one keyboard. In a world of
two hands (:class:`~pianobot.sim.world.PianoWorld` with ``hands=("right", "left")``) each hand is
given to its player through a :class:`HandView`: the world seen from that hand, through its
:class:`~pianobot.music.window.Window`. For the right hand the view moves the keyboard by whole
octaves; for the left hand it also mirrors it about D, the one key whose mirror image is itself,
so the left hand (built as the right hand's mirror image, :data:`~pianobot.sim.hand.SIDES`) is a
right hand in the view, with the same joint angles. Both maps are exact: a piano's keys repeat
every octave and are symmetric about D, and the left hand's links are the right's reflected
(tests/test_env_hands.py checks both).

A view offers what the environment reads of a one-hand world (the wrist, the joints, fingertip
points and forces, link poses, key angles, the keys' boxes and the keyboard's width), each in
the view's frame; stepping and resetting the world belong to the world's owner
(:class:`pianobot.env.two_hands.HandsEnv`), which turns each hand's action and start into the
world's with :meth:`HandView.world_action` and :meth:`HandView.world_wrist`, and each step's
result into the hand's with :meth:`HandView.result`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pianobot.music.window import Window
from pianobot.sim.keyboard import KeyEvent, key_boxes, keyboard_width
from pianobot.sim.world import PianoWorld, StepResult, WorldConfig

MIRROR = np.diag([-1.0, 1.0, 1.0])
"""The reflection across a plane of constant x (along the keyboard)."""


class HandView:
    """Hand ``hand`` (its index in ``world.hands``) of ``world``, seen through ``window``: the
    keyboard its player knows is ``window.keyboard``, whose key ``q`` is the world's key
    ``window.outward(q)``. ``config`` is the world's configuration with that keyboard: what the
    player's environment is built for."""

    def __init__(self, world: PianoWorld, hand: int, window: Window):
        if (world.sides[hand] == "left") != (window.hand == "left"):
            raise ValueError(
                f"hand {hand} of the world is the {world.sides[hand]} one; the window is for the {window.hand}"
            )
        spec = world.config.keyboard.spec
        view = window.keyboard
        outward = [window.outward(q) for q in range(view.lowest, view.lowest + view.count)]
        missing = [q for q in outward if q not in spec]
        if missing:
            raise ValueError(
                f"the world's keyboard ({spec.describe()}) lacks keys the {window.hand} hand's player knows"
            )
        self.world, self.hand, self.window = world, hand, window
        self.config: WorldConfig = replace(world.config, keyboard=replace(world.config.keyboard, spec=window.keyboard))
        self.boxes = key_boxes(self.config.keyboard)
        self.width = keyboard_width(self.config.keyboard)
        self.sign = -1.0 if window.hand == "left" else 1.0
        """+1, or -1 where the view mirrors the world (the left hand's)."""
        self.keys = np.array(outward) - spec.lowest
        """For each key of the view, the index of the world's key it is."""
        # x in the view = sign * (x in the world - the world's x of a key) + the view's x of that key
        anchor = window.keyboard.lowest
        self._anchor_view = self.boxes[0].center[0]
        self._anchor_world = world.boxes[window.outward(anchor) - spec.lowest].center[0]

    # -- coordinates -------------------------------------------------------------------------
    def x(self, world_x: float) -> float:
        """A position along the world's keyboard (m) -> the same place along the view's."""
        return self.sign * (world_x - self._anchor_world) + self._anchor_view

    def world_x(self, x: float) -> float:
        """A position along the view's keyboard (m) -> the world's."""
        return self.sign * (x - self._anchor_view) + self._anchor_world

    def point(self, p: np.ndarray) -> np.ndarray:
        """A point of the world -> the view's."""
        return np.array([self.x(p[0]), p[1], p[2]])

    def pitch(self, world_pitch: int) -> int | None:
        """The world's key ``world_pitch`` -> the view's pitch (None: not on the view's keyboard)."""
        q = self.window.inward(world_pitch)
        return q if q in self.window.keyboard else None

    # -- what the environment reads (a one-hand world's interface) ----------------------------
    @property
    def time(self) -> float:
        return self.world.time

    @property
    def tip_links(self) -> dict[int, int]:
        return self.world.hands[self.hand].tips

    def hand_state(self) -> tuple[float, float, np.ndarray, np.ndarray]:
        """The wrist's position (m, along the view's keyboard) and speed, finger joint angles and speeds."""
        wrist, speed, angles, speeds = self.world.hand_state(self.hand)
        return self.x(wrist), self.sign * speed, angles, speeds

    def tip_points(self) -> dict[int, np.ndarray]:
        return {f: self.point(p) for f, p in self.world.tip_points(self.hand).items()}

    def tip_forces(self) -> dict[int, float]:
        return self.world.tip_forces(self.hand)

    def link_pose(self, link: int) -> tuple[np.ndarray, np.ndarray]:
        position, rotation = self.world.link_pose(link, self.hand)
        return self.point(position), (MIRROR @ rotation @ MIRROR if self.sign < 0 else rotation)

    def key_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The view's keys' angles and speeds."""
        angles, speeds = self.world.key_state()
        return angles[self.keys], speeds[self.keys]

    # -- from the player to the world, and back ----------------------------------------------
    def world_action(self, action: np.ndarray) -> np.ndarray:
        """A full action of this hand (finger joints, then the wrist) in the view -> in the world:
        a mirrored hand's joints move as the right's, its wrist the other way."""
        action = np.array(action, dtype=float)
        action[-1] *= self.sign
        return action

    def world_wrist(self, x: float) -> float:
        """A wrist position along the view's keyboard -> the world's."""
        return self.world_x(x)

    def result(self, result: StepResult, others: set[int] = frozenset()) -> StepResult:
        """What a world step did, as the view sees it: its keys' events at the view's pitches, the
        fingers of the strikes of this hand only, and the keys it pressed: a key the other hand
        played (``others``, world pitches) sounds, but is neither pressed by this hand nor any
        finger's of it."""
        events = []
        fingers = {}
        for event in result.events:
            q = self.pitch(event.pitch)
            if q is None:
                continue
            events.append(KeyEvent(event.time, q, event.on, event.velocity))
            if event.on and result.hands.get(event.pitch) == self.hand and event.pitch in result.fingers:
                fingers[q] = result.fingers[event.pitch]
        pressed, velocity = result.pressed[self.keys], result.pressed_velocity[self.keys]  # (copies: fancy indexing)
        if others:  # (mostly none: the hands seldom share a key)
            theirs = np.isin(self.keys + self.world.config.keyboard.spec.lowest, list(others))
            pressed[theirs], velocity[theirs] = False, 0
        return StepResult(events, fingers, pressed, velocity)
