"""The piano keyboard: hinged keys with a non-linear return spring, and a MIDI-like key sensor.

Geometry (metres): x runs along the keyboard (low to high pitch), y from the key's hinge at the
back (y = 0) towards the player, z up with the white keys' top surface at z = 0. Each key is a
box on a revolute joint at its back end; a positive joint angle pushes its front down.

A key sounds (note-on) when its angle passes the strike angle; its MIDI velocity comes from its
speed at that moment through :class:`VelocityCurve`. It releases (note-off) when it rises back
above the release angle, which lies higher than the strike angle (hysteresis), exactly as a MIDI
keyboard's double-contact sensor behaves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pianobot.config import check_ranges
from pianobot.music.instrument import KeyboardSpec


@dataclass(frozen=True)
class KeyGeometry:
    """Real piano key sizes."""

    white_pitch: float = 0.0235
    """Distance between neighbouring white keys (m)."""
    white_width: float = 0.0225
    """Width of a white key's box; the rest of the pitch is the gap between keys (m)."""
    white_length: float = 0.150
    white_height: float = 0.020
    black_width: float = 0.0137
    black_length: float = 0.095
    black_rise: float = 0.0127
    """Height of a black key's top above the white keys' top (m)."""
    black_height: float = 0.020
    front_dip: float = 0.010
    """How far a white key's front edge goes down when the key is fully pressed (m)."""

    @property
    def max_angle(self) -> float:
        return math.atan2(self.front_dip, self.white_length)

    def __post_init__(self) -> None:
        m = (1e-4, 1.0)  # metres
        check_ranges(
            self,
            white_pitch=m,
            white_width=m,
            white_length=m,
            white_height=m,
            black_width=m,
            black_length=m,
            black_rise=m,
            black_height=m,
            front_dip=m,
        )
        if self.front_dip >= self.white_height or self.black_length >= self.white_length:
            raise ValueError("front_dip must be below white_height and black keys shorter than white ones")


@dataclass(frozen=True)
class VelocityCurve:
    """Key speed at the strike point -> MIDI velocity, logarithmic as in real pianos.

    Key speed is the key's angular speed times a white key's length: the speed of a white key's
    front edge, in m/s. ``velocity = 1 + 126 * clip(log(s / slow) / log(fast / slow), 0, 1)``.
    """

    slow: float = 0.02
    """Key speed (m/s) that gives velocity 1; anything slower also gives 1."""
    fast: float = 0.6
    """Key speed (m/s) that gives velocity 127; anything faster also gives 127."""

    def velocity(self, speed: float | np.ndarray) -> np.ndarray:
        s = np.maximum(np.asarray(speed, dtype=float), 1e-9)
        x = np.clip(np.log(s / self.slow) / math.log(self.fast / self.slow), 0.0, 1.0)
        return np.rint(1 + 126 * x).astype(int)

    def speed(self, velocity: float | np.ndarray) -> np.ndarray:
        """The key speed (m/s) that gives ``velocity``: the inverse of :meth:`velocity`."""
        x = (np.clip(np.asarray(velocity, dtype=float), 1, 127) - 1) / 126
        return self.slow * np.exp(x * math.log(self.fast / self.slow))

    def __post_init__(self) -> None:
        check_ranges(self, slow=(1e-4, 100.0), fast=(1e-4, 100.0))
        if self.slow >= self.fast:
            raise ValueError(f"slow {self.slow} must be below fast {self.fast}")


@dataclass(frozen=True)
class KeyboardConfig:
    """The keyboard's range, key sizes, spring and key sensor."""

    spec: KeyboardSpec = field(default_factory=KeyboardSpec)
    """Which keys (default C4-B5, 24 keys)."""
    geometry: KeyGeometry = field(default_factory=KeyGeometry)
    key_mass: float = 0.05
    """Mass of one key (kg)."""
    spring_gain: float = 0.3
    """Position gain of the return spring (the key motor driving back to rest)."""
    spring_torque: float = 0.04
    """Return torque at rest (N m): about 27 g of touch weight at the key front."""
    spring_torque_pressed: float = 0.12
    """Return torque when fully pressed (N m); the spring stiffens quadratically in between."""
    strike_fraction: float = 0.6
    """A key sounds when it passes this fraction of its full travel."""
    release_fraction: float = 0.35
    """A sounding key releases when it rises above this fraction of its full travel."""
    curve: VelocityCurve = field(default_factory=VelocityCurve)

    def __post_init__(self) -> None:
        check_ranges(
            self,
            key_mass=(1e-4, 10.0),
            spring_gain=(0.0, 100.0),
            spring_torque=(0.0, 100.0),
            spring_torque_pressed=(0.0, 100.0),
            strike_fraction=(0.01, 0.99),
            release_fraction=(0.01, 0.99),
        )
        if self.release_fraction >= self.strike_fraction:
            raise ValueError("release_fraction must be below strike_fraction (a key sounds before it can release)")


@dataclass(frozen=True)
class KeyEvent:
    """What a MIDI keyboard sends: note-on with velocity, or note-off."""

    time: float
    pitch: int
    on: bool
    velocity: int = 0


class KeySensor:
    """Turns key angles and speeds, sampled every physics step, into note-on/off events.

    Pure NumPy, no physics: the simulator feeds it the key states it reads.
    """

    def __init__(self, config: KeyboardConfig):
        self.config = config
        self.pitches = np.array(list(config.spec.pitches))
        self.strike = config.strike_fraction * config.geometry.max_angle
        self.release = config.release_fraction * config.geometry.max_angle
        self.sounding = np.zeros(len(self.pitches), dtype=bool)
        self.velocity = np.zeros(len(self.pitches), dtype=int)

    def reset(self) -> None:
        self.sounding[:] = False
        self.velocity[:] = 0

    def update(
        self, time: float, angles: np.ndarray, speeds: np.ndarray, keys: list[int] | None = None
    ) -> list[KeyEvent]:
        """Feed one sample of all keys; returns the events it caused. ``keys`` (sorted key
        indices): only these can have changed since the last sample (the others are at rest and
        do not sound), so only these are looked at."""
        if keys is None:
            keys = range(len(self.pitches))
        index = np.asarray(keys, dtype=int)
        angle, sounding = angles[index], self.sounding[index]
        struck = index[~sounding & (angle >= self.strike)]
        released = index[sounding & (angle < self.release)]
        events: list[KeyEvent] = []
        if struck.size:
            lever = self.config.geometry.white_length
            velocities = self.config.curve.velocity(np.maximum(speeds[struck], 0.0) * lever)
            self.velocity[struck] = velocities
            self.sounding[struck] = True
            events += [KeyEvent(time, int(p), True, int(v)) for p, v in zip(self.pitches[struck], velocities)]
        if released.size:
            self.sounding[released] = False
            self.velocity[released] = 0
            events += [KeyEvent(time, int(p), False) for p in self.pitches[released]]
        return events


@dataclass(frozen=True)
class KeyBox:
    """One key's box in the keyboard frame at rest: centre, half extents, hinge y and z."""

    pitch: int
    black: bool
    center: tuple[float, float, float]
    half: tuple[float, float, float]


def key_boxes(config: KeyboardConfig) -> list[KeyBox]:
    """Where every key's box lies at rest. White key k's centre is at x = (k + 0.5) * pitch."""
    g = config.geometry
    boxes, white_index = [], 0
    for pitch in config.spec.pitches:
        if KeyboardSpec.is_black(pitch):
            x = white_index * g.white_pitch  # on the boundary with the previous white key
            boxes.append(
                KeyBox(
                    pitch,
                    True,
                    (x, g.black_length / 2, g.black_rise - g.black_height / 2),
                    (g.black_width / 2, g.black_length / 2, g.black_height / 2),
                )
            )
        else:
            x = (white_index + 0.5) * g.white_pitch
            boxes.append(
                KeyBox(
                    pitch,
                    False,
                    (x, g.white_length / 2, -g.white_height / 2),
                    (g.white_width / 2, g.white_length / 2, g.white_height / 2),
                )
            )
            white_index += 1
    return boxes


def keyboard_width(config: KeyboardConfig) -> float:
    whites = sum(not KeyboardSpec.is_black(p) for p in config.spec.pitches)
    return whites * config.geometry.white_pitch


def key_x(config: KeyboardConfig, pitch: int) -> float:
    """Centre of a key along the keyboard (m)."""
    return key_boxes(config)[config.spec.index(pitch)].center[0]


def key_colour(black: bool, sounding: bool) -> list[float]:
    """A key's RGBA colour in rendered frames: sounding keys turn blue."""
    if sounding:
        return [0.1, 0.3, 0.8, 1] if black else [0.45, 0.65, 1.0, 1]
    return [0.08, 0.08, 0.08, 1] if black else [0.95, 0.95, 0.92, 1]


def key_urdf(config: KeyboardConfig, box: KeyBox) -> str:
    """URDF text of one key as a body of its own: a fixed frame and the key's box on a hinge at the
    frame's origin (the simulator places the body at the key's x), limited to [0, full travel];
    one element per line (PyBullet rejects a URDF written as one long line)."""
    g = config.geometry
    name = f"key_{box.pitch}"
    size = " ".join(f"{2 * h:.5f}" for h in box.half)
    origin = f'<origin xyz="0 {box.center[1]:.5f} {box.center[2]:.5f}"/>'
    colour = " ".join(str(c) for c in key_colour(box.black, False))
    m = config.key_mass
    hx, hy, hz = (2 * h for h in box.half)
    inertia = (
        f'<inertia ixx="{m * (hy * hy + hz * hz) / 12:.3e}" iyy="{m * (hx * hx + hz * hz) / 12:.3e}" '
        f'izz="{m * (hx * hx + hy * hy) / 12:.3e}" ixy="0" ixz="0" iyz="0"/>'
    )
    parts = [
        '<?xml version="1.0"?>',
        f'<robot name="{name}">',
        '<link name="frame"><inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>',
        f'<link name="{name}">',
        f'<inertial>{origin}<mass value="{m}"/>{inertia}</inertial>',
        f'<visual>{origin}<geometry><box size="{size}"/></geometry><material name="{"black" if box.black else "white"}"><color rgba="{colour}"/></material></visual>',
        f'<collision>{origin}<geometry><box size="{size}"/></geometry></collision>',
        "</link>",
        f'<joint name="{name}" type="revolute">',
        f'<parent link="frame"/><child link="{name}"/>',
        '<origin xyz="0 0 0"/><axis xyz="-1 0 0"/>',
        f'<limit lower="0" upper="{g.max_angle:.5f}" effort="100" velocity="100"/>',
        "</joint>",
        "</robot>",
    ]
    return "\n".join(parts) + "\n"


WHITE_STRIKE_FROM_FRONT = 0.040
"""A fingertip strikes a white key this far (m) in from its front edge."""
BLACK_STRIKE_FROM_FRONT = 0.010
"""A fingertip strikes a black key this far (m) in from its front edge."""


def strike_points(config: KeyboardConfig) -> np.ndarray:
    """Where on each key's top surface a fingertip strikes it, at rest: array (L, 3) in metres."""
    points = []
    for box in key_boxes(config):
        front = box.center[1] + box.half[1]
        inset = BLACK_STRIKE_FROM_FRONT if box.black else WHITE_STRIKE_FROM_FRONT
        points.append((box.center[0], front - inset, box.center[2] + box.half[2]))
    return np.array(points)
