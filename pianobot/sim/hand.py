"""An Allegro-like right hand on a wrist that slides along the keyboard, built from code.

Each finger has the Allegro's four joints: abduction (about the vertical axis), then three
flexion joints (MCP, PIP, DIP) with the Allegro's link lengths. The fingers point away from the
player (-y) and curl down onto the keys; positive flexion curls. The palm sits at a fixed height
on a prismatic wrist joint along x, as in the paper.

Fingers use the pianists' numbers: 2 index, 3 middle, 4 ring (the default hand); 1 thumb is
optional. The thumb is modelled as a fourth finger beside the index with the same joint layout
(an approximation: the Allegro thumb's base is rotated, which matters little for pressing keys
from above).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pianobot.config import check_ranges
from pianobot.music.instrument import HandSpec


@dataclass(frozen=True)
class FingerGeometry:
    """Allegro finger dimensions (m) and joint limits (rad)."""

    base_to_mcp: float = 0.0164
    proximal: float = 0.0540
    middle: float = 0.0384
    distal: float = 0.0267
    """From the DIP joint to the fingertip's end, the tip sphere included."""
    tip_radius: float = 0.009
    """Narrower than the Allegro's 14 mm tip, so that one fingertip fits on one 22.5 mm key, as a human fingertip does."""
    link_radius: float = 0.008
    abduction_limit: float = 0.47
    flexion_limits: tuple[tuple[float, float], ...] = ((-0.196, 1.61), (-0.174, 1.709), (-0.227, 1.618))

    def __post_init__(self) -> None:
        m = (1e-4, 1.0)  # metres
        check_ranges(
            self,
            base_to_mcp=(0.0, 1.0),
            proximal=m,
            middle=m,
            distal=m,
            tip_radius=m,
            link_radius=m,
            abduction_limit=(0.0, 1.6),
        )
        if len(self.flexion_limits) != 3 or any(not -3.2 < low < high < 3.2 for low, high in self.flexion_limits):
            raise ValueError(f"flexion_limits {self.flexion_limits}: three (low, high) pairs in radians, low < high")


JOINT_KINDS = ("abd", "mcp", "pip", "dip")
"""A finger's joints, in action order: abduction (about the vertical), then three flexion joints."""


@dataclass(frozen=True)
class HandModel:
    """Everything about a hand's body that the rest of pianobot asks, for the right hand (the left
    is its mirror image, :data:`SIDES`): which fingers it has and where each finger's base sits
    on the palm, the fingers' links and joint limits, the finger sets it plays with, and which
    fingers may pass which. The world builds its URDF from it (:func:`hand_urdf`), the
    environment its joints, the fingering planner and the scripted pianist their reach.

    A new hand is a module that makes one and registers it (:func:`register_hand_model`); a
    :class:`~pianobot.music.instrument.HandSpec` names it."""

    name: str
    bases: tuple[tuple[int, float, float], ...]
    """(finger, x, y) of each finger's base (m): x across the palm from the wrist (towards the
    high keys for the right hand), y towards the pianist; fingers in pianists' numbers, 1 thumb
    ... 5 little, in order."""
    geometry: FingerGeometry = field(default_factory=FingerGeometry)
    """Every finger's links and joint limits."""
    finger_sets: tuple[tuple[int, ...], ...] = ()
    """The fingers it plays with, in order of preference (the first is the default)."""
    passes: frozenset[tuple[int, int]] = frozenset()
    """(a, b): finger a may pass under or over finger b (none: no finger passes another)."""
    joints: tuple[str, ...] = JOINT_KINDS
    """Each finger's joints, in action order (names from :data:`JOINT_KINDS`); the others are fixed."""
    finger_joints: tuple[tuple[int, tuple[str, ...]], ...] = ()
    """(finger, joints): fingers whose joints are not :attr:`joints` (a thumb with fewer, say)."""
    abduction: tuple[tuple[int, float], ...] = ()
    """(finger, limit): fingers whose sideways reach is not :attr:`FingerGeometry.abduction_limit`
    (rad; a thumb that reaches under the palm, say)."""
    tuning: tuple[tuple[str, float], ...] = ()
    """(name, value): the scripted pianist's and the fingering planner's constants for this hand
    other than their defaults (:class:`~pianobot.pianist.tuning.PianistTuning`'s fields)."""
    settings: tuple[tuple[str, float], ...] = ()
    """(name, value): the :class:`HandConfig` settings this body has other than their defaults
    (the palm's pose over the keys, its motors), as :func:`hand_config` applies them."""
    written_fingering: bool = False
    """Whether a file's 1-5 fingering, written for a human hand, is this hand's: its marks are kept
    where the hand can play them, in a part fingered throughout or in part and in both hands' parts
    (:func:`~pianobot.pianist.fingering.ensure_fingering`; else a part fingered throughout is played
    as written, and any other, and both hands' parts, are fingered anew for this hand)."""
    lends_notes: bool = False
    """Whether a note of a chord one hand cannot reach goes to the other hand where that one can take
    it, as pianists do, in a file that names each note's hand too (:mod:`pianobot.pianist.lend`;
    else the hand's reduction drops it)."""

    def __post_init__(self) -> None:
        numbers = [f for f, _, _ in self.bases]
        if not numbers or numbers != sorted(set(numbers)) or any(not 1 <= f <= 5 for f in numbers):
            raise ValueError(f"hand model {self.name!r}: fingers {numbers} must be distinct numbers 1-5, in order")
        for fingers in self.finger_sets:
            if not fingers or not set(fingers) <= set(numbers):
                raise ValueError(f"hand model {self.name!r}: finger set {fingers} is not among its fingers {numbers}")
        for finger, joints in [(None, self.joints), *self.finger_joints]:
            if not joints or not set(joints) <= set(JOINT_KINDS) or len(set(joints)) != len(joints):
                raise ValueError(f"hand model {self.name!r}: joints {joints} must be distinct names from {JOINT_KINDS}")
            if finger is not None and finger not in numbers:
                raise ValueError(f"hand model {self.name!r}: joints given for finger {finger}, which it lacks")
        for finger, limit in self.abduction:
            if finger not in numbers or not 0.0 <= limit <= 1.6:
                raise ValueError(
                    f"hand model {self.name!r}: abduction ({finger}, {limit}): one of its fingers, 0-1.6 rad"
                )
        for a, b in self.passes:
            if a not in numbers or b not in numbers or a == b:
                raise ValueError(f"hand model {self.name!r}: ({a}, {b}) in passes: two of its fingers {numbers}")

    @property
    def fingers(self) -> tuple[int, ...]:
        return tuple(f for f, _, _ in self.bases)

    def base_x(self, finger: int, side: str = "right") -> float:
        """Where a finger's base sits across the palm (m, along the keyboard, from the wrist)."""
        x = next(x for f, x, _ in self.bases if f == finger)
        return x if side == "right" else -x

    def base_y(self, finger: int) -> float:
        return next(y for f, _, y in self.bases if f == finger)

    def joints_of(self, finger: int) -> tuple[str, ...]:
        """A finger's actuated joints, in action order."""
        return dict(self.finger_joints).get(finger, self.joints)

    def abduction_limit(self, finger: int) -> float:
        """How far (rad) a finger turns sideways either way."""
        return dict(self.abduction).get(finger, self.geometry.abduction_limit)

    def passes_by(self, a: int, b: int) -> bool:
        """Whether fingers ``a`` and ``b`` may cross (one under or over the other)."""
        return (a, b) in self.passes or (b, a) in self.passes

    def joint_kinds(self, fingers: tuple[int, ...]) -> list[str]:
        """The kind of every joint of ``fingers``, finger by finger, in action order."""
        return [j for f in fingers for j in self.joints_of(f)]


ALLEGRO = HandModel(
    name="allegro",
    bases=((1, -0.0870, 0.012), (2, -0.0435, 0.0), (3, 0.0, 0.0), (4, 0.0435, 0.0)),
    finger_sets=((2, 3, 4), (1, 2, 3, 4)),
)
"""The Allegro-like hand of the paper: index, middle and ring fingers 43.5 mm apart, and a thumb
modelled as a fourth finger beside the index (the Allegro's four joints each); no finger passes
another."""

HAND_MODELS: dict[str, HandModel] = {}
"""The hand models pianobot knows, by name (:func:`register_hand_model`)."""


def register_hand_model(model: HandModel) -> HandModel:
    """Make ``model`` known by its name (again: replaced)."""
    HAND_MODELS[model.name] = model
    return model


register_hand_model(ALLEGRO)


def hand_model(name: str) -> HandModel:
    """The registered hand model called ``name``; another is a one-line error naming those there are."""
    try:
        return HAND_MODELS[name]
    except KeyError:
        raise ValueError(f"hand model {name!r}: choose one of {', '.join(HAND_MODELS)}") from None


FINGER_BASE_X = {f: x for f, x, _ in ALLEGRO.bases}
"""The Allegro-like hand's finger bases across the palm (m): :attr:`ALLEGRO`'s (kept for code that reads them)."""
FINGER_BASE_Y = {f: y for f, _, y in ALLEGRO.bases}


@dataclass(frozen=True)
class HandConfig:
    """The hand's fingers, pose above the keyboard and actuator limits."""

    spec: HandSpec = field(default_factory=HandSpec)
    """Which fingers are built and actuated (default index, middle, ring)."""
    geometry: FingerGeometry = field(default_factory=FingerGeometry)
    palm_height: float = 0.070
    """Height of the finger bases above the white keys' top (m)."""
    palm_y: float = 0.190
    """y of the finger bases (the keys run from y = 0 at the hinge to 0.15 at the front)."""
    max_joint_speed: float = 12.0
    """Joint speed (rad/s) at action +-1 in velocity control, and the fastest a joint moves in position control."""
    joint_force: float = 0.7
    """Most torque (N m) a joint motor may use to reach its commanded speed (about the Allegro's)."""
    max_joint_torque: float = 0.7
    """Torque (N m) at action +-1 in torque control."""
    max_wrist_speed: float = 1.0
    """Wrist speed along the rail (m/s) at action +-1."""
    wrist_force: float = 60.0
    """Most force (N) the wrist motor may use."""
    finger_mass: float = 0.03
    """Mass of each finger link (kg)."""

    def __post_init__(self) -> None:
        missing = set(self.spec.fingers) - set(self.model.fingers)
        if missing:
            raise ValueError(
                f"hand fingers {self.spec.fingers}: the {self.model.name} hand has fingers "
                f"{', '.join(map(str, self.model.fingers))}"
            )
        check_ranges(
            self,
            palm_height=(1e-3, 1.0),
            palm_y=(1e-3, 1.0),
            max_joint_speed=(1e-3, 1e3),
            joint_force=(1e-4, 1e3),
            max_joint_torque=(1e-4, 1e3),
            max_wrist_speed=(1e-3, 100.0),
            wrist_force=(1e-3, 1e5),
            finger_mass=(1e-4, 10.0),
        )

    @property
    def model(self) -> HandModel:
        """The hand model :attr:`spec` names."""
        return hand_model(self.spec.model)


def hand_config(spec: HandSpec) -> HandConfig:
    """The configuration of the hand ``spec`` names, with its model's finger geometry (every other
    setting the default): the one way code that knows only a spec makes a hand."""
    model = hand_model(spec.model)
    return HandConfig(spec=spec, geometry=model.geometry, **dict(model.settings))


def default_fingers(model: str) -> HandSpec:
    """The hand ``model`` names with the fingers it plays with by default (its first finger set)."""
    return HandSpec(fingers=hand_model(model).finger_sets[0], model=model)


def joint_limits(config: HandConfig) -> np.ndarray:
    """(2, J): the lower and upper limit (rad) of every finger joint, in action order."""
    g, model = config.geometry, config.model
    limits = []
    for f in config.spec.fingers:
        reach = model.abduction_limit(f)
        by_kind = dict(zip(JOINT_KINDS, [(-reach, reach), *g.flexion_limits]))
        limits += [by_kind[j] for j in model.joints_of(f)]
    return np.array(limits).T


def joint_names(spec: HandSpec) -> list[str]:
    """Actuated finger joints in action order: for each finger, its model's joints (abduction, MCP, PIP, DIP)."""
    model = hand_model(spec.model)
    return [f"f{f}_{j}" for f in spec.fingers for j in model.joints_of(f)]


def _box_inertia(mass: float, size: tuple[float, float, float]) -> str:
    x, y, z = size
    return (
        f'<inertia ixx="{mass * (y * y + z * z) / 12:.3e}" iyy="{mass * (x * x + z * z) / 12:.3e}" '
        f'izz="{mass * (x * x + y * y) / 12:.3e}" ixy="0" ixz="0" iyz="0"/>'
    )


def _link(name: str, mass: float, length: float, radius: float, colour: str, tip: float = 0.0) -> str:
    """A finger link along -y: a capsule-like box, plus the fingertip sphere if ``tip`` > 0."""
    size = (2 * radius, length, 2 * radius)
    visual_tip = collision_tip = ""
    if tip:
        center = f"0 {-(length - tip):.5f} 0"
        visual_tip = (
            f'<visual><origin xyz="{center}"/><geometry><sphere radius="{tip}"/></geometry>'
            f'<material name="tip"><color rgba="0.9 0.75 0.2 1"/></material></visual>'
        )
        collision_tip = f'<collision><origin xyz="{center}"/><geometry><sphere radius="{tip}"/></geometry></collision>'
        length = length - tip  # the box ends at the sphere's centre
        size = (2 * radius, length, 2 * radius)
    origin = f'<origin xyz="0 {-length / 2:.5f} 0"/>'
    return "\n".join(
        [
            f'<link name="{name}">',
            f'<inertial>{origin}<mass value="{mass}"/>{_box_inertia(mass, size)}</inertial>',
            f'<visual>{origin}<geometry><box size="{size[0]:.4f} {size[1]:.4f} {size[2]:.4f}"/></geometry>'
            f'<material name="{colour}"><color rgba="0.2 0.2 0.25 1"/></material></visual>',
            visual_tip,
            f'<collision>{origin}<geometry><box size="{size[0]:.4f} {size[1]:.4f} {size[2]:.4f}"/></geometry></collision>',
            collision_tip,
            "</link>",
        ]
    )


def _joint(name: str, kind: str, parent: str, child: str, xyz: tuple, axis: str, limits: tuple) -> str:
    return "\n".join(
        [
            f'<joint name="{name}" type="{kind}">',
            f'<parent link="{parent}"/><child link="{child}"/>',
            f'<origin xyz="{xyz[0]:.5f} {xyz[1]:.5f} {xyz[2]:.5f}"/><axis xyz="{axis}"/>',
            f'<limit lower="{limits[0]}" upper="{limits[1]}" effort="100" velocity="100"/>',
            '<dynamics damping="0.01" friction="0"/>',
            "</joint>",
        ]
    )


SIDES = ("right", "left")
"""A hand's side. The left hand is the right hand's mirror image across the plane x = wrist: its
fingers in the mirrored places (the thumb on the high side) and its abduction axes reversed, so
the same joint angles put every link at the mirror image of the right hand's."""


def thumb_side_reach(config: HandConfig) -> float:
    """How far (m) a hand's finger bases and links reach from its wrist towards its thumb's side
    (down the keyboard for the right hand, up for the left), with no abduction."""
    return -min(config.model.base_x(f) for f in config.spec.fingers) + config.geometry.link_radius


def hand_urdf(config: HandConfig, rail: tuple[float, float], side: str = "right") -> str:
    """URDF text of the rail, the sliding palm and the fingers of a ``side`` hand (one element per
    line: PyBullet rejects a URDF written as one long line)."""
    if side not in SIDES:
        raise ValueError(f"a hand's side is one of {', '.join(SIDES)}; got {side!r}")
    g = config.geometry
    mirror = -1 if side == "left" else 1
    parts = ['<?xml version="1.0"?>', f'<robot name="{config.model.name}_like_{side}_hand">']
    parts.append(
        '<link name="rail"><inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    )
    palm_size = (0.13, 0.05, 0.012)
    parts.append(
        "\n".join(
            [
                '<link name="palm">',
                f'<inertial><origin xyz="0 0.045 0.01"/><mass value="0.4"/>{_box_inertia(0.4, palm_size)}</inertial>',
                f'<visual><origin xyz="{-0.015 * mirror} 0.03 0.015"/><geometry><box size="{palm_size[0]} {palm_size[1]} {palm_size[2]}"/></geometry>'
                '<material name="palm"><color rgba="0.3 0.3 0.35 1"/></material></visual>',
                "</link>",
            ]
        )
    )
    parts.append(_joint("wrist", "prismatic", "rail", "palm", (0, 0, 0), "1 0 0", rail))
    for f in config.spec.fingers:
        prefix = f"f{f}"
        parts.append(_link(f"{prefix}_base", config.finger_mass, g.base_to_mcp, g.link_radius, "finger"))
        parts.append(
            _joint(
                f"{prefix}_abd",
                "revolute" if "abd" in config.model.joints_of(f) else "fixed",
                "palm",
                f"{prefix}_base",
                (config.model.base_x(f, side), config.model.base_y(f), 0.0),
                f"0 0 {mirror}",
                (-config.model.abduction_limit(f), config.model.abduction_limit(f)),
            )
        )
        chain = [("mcp", "proximal", g.proximal), ("pip", "middle", g.middle), ("dip", "distal", g.distal)]
        parent, offset = f"{prefix}_base", g.base_to_mcp
        for (joint, link, length), limits in zip(chain, g.flexion_limits):
            tip = g.tip_radius if link == "distal" else 0.0
            parts.append(_link(f"{prefix}_{link}", config.finger_mass, length, g.link_radius, "finger", tip))
            parts.append(
                _joint(
                    f"{prefix}_{joint}",
                    "revolute" if joint in config.model.joints_of(f) else "fixed",
                    parent,
                    f"{prefix}_{link}",
                    (0, -offset, 0),
                    "1 0 0",
                    limits,
                )
            )
            parent, offset = f"{prefix}_{link}", length
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


# -- kinematics in the finger's plane, for controllers -----------------------------------------
def lowest_point_in_finger_plane(geometry: FingerGeometry, flexion: np.ndarray) -> tuple[float, float]:
    """(reach, drop) of the lowest point of the fingertip sphere: where it meets a key from above."""
    a1, a2, a3 = np.cumsum(flexion)
    reach = geometry.base_to_mcp + geometry.proximal * math.cos(a1) + geometry.middle * math.cos(a2)
    drop = geometry.proximal * math.sin(a1) + geometry.middle * math.sin(a2)
    centre = geometry.distal - geometry.tip_radius
    return reach + centre * math.cos(a3), drop + centre * math.sin(a3) + geometry.tip_radius


PREFERRED_TILT = 1.1
"""The distal link's preferred angle below the horizontal (rad) when a fingertip meets a key."""
TILT_RANGE = (0.6, 1.57)
"""Tilts the IK considers: between them the fingertip, not a knuckle, is the finger's lowest point."""


_TILT_OFFSETS = np.concatenate([[0.0], np.repeat(np.arange(1, 50) * 0.02, 2) * np.tile([1, -1], 49)])
"""The tilts :func:`finger_ik` tries, as offsets from the preferred one, nearest first."""
_SLACK = 1e-6
"""How far (rad) the vectorized screen in :func:`finger_ik` lets a tilt stray outside the limits:
it only has to keep every tilt the exact check would accept."""


def _ik_at(geometry: FingerGeometry, reach: float, drop: float, phi: float) -> np.ndarray | None:
    """MCP, PIP and DIP angles that put the fingertip's lowest point at (reach, drop) with the
    distal link at ``phi`` below the horizontal, or None where the joint limits forbid it."""
    centre_x, centre_z = reach, drop - geometry.tip_radius
    l3 = geometry.distal - geometry.tip_radius
    x = centre_x - l3 * math.cos(phi) - geometry.base_to_mcp
    z = centre_z - l3 * math.sin(phi)
    cosine = (x * x + z * z - geometry.proximal**2 - geometry.middle**2) / (2 * geometry.proximal * geometry.middle)
    if abs(cosine) > 1:
        return None
    pip = math.acos(cosine)
    mcp = math.atan2(z, x) - math.atan2(
        geometry.middle * math.sin(pip), geometry.proximal + geometry.middle * math.cos(pip)
    )
    dip = phi - mcp - pip
    (lo1, hi1), (lo2, hi2), (lo3, hi3) = geometry.flexion_limits
    if lo1 <= mcp <= hi1 and lo2 <= pip <= hi2 and lo3 <= dip <= hi3:
        return np.array([mcp, pip, dip])
    return None


def finger_ik(geometry: FingerGeometry, reach: float, drop: float, tilt: float = PREFERRED_TILT) -> np.ndarray | None:
    """MCP, PIP and DIP angles that put the fingertip's lowest point at (reach, drop).

    Three joints for two coordinates leave one freedom: the distal link's angle below the
    horizontal (``tilt``, rad). The tilt closest to the preferred one within [0.6, 1.57] that the
    joint limits allow is used (tried in steps of 0.02 rad, nearer first, the larger first of
    two equally near); between those bounds the fingertip, not a knuckle, is the finger's lowest
    point. Returns None when the point is out of reach.
    """
    if TILT_RANGE[0] <= tilt <= TILT_RANGE[1]:
        q = _ik_at(geometry, reach, drop, tilt)  # the usual case: the preferred tilt itself
        if q is not None:
            return q
    # every other tilt at once, screened loosely in NumPy; the exact check decides, in order
    phi = tilt + _TILT_OFFSETS[1:]
    l3 = geometry.distal - geometry.tip_radius
    x = reach - l3 * np.cos(phi) - geometry.base_to_mcp
    z = drop - geometry.tip_radius - l3 * np.sin(phi)
    cosine = (x * x + z * z - geometry.proximal**2 - geometry.middle**2) / (2 * geometry.proximal * geometry.middle)
    pip = np.arccos(np.clip(cosine, -1.0, 1.0))
    mcp = np.arctan2(z, x) - np.arctan2(
        geometry.middle * np.sin(pip), geometry.proximal + geometry.middle * np.cos(pip)
    )
    ok = (phi >= TILT_RANGE[0] - _SLACK) & (phi <= TILT_RANGE[1] + _SLACK) & (np.abs(cosine) <= 1.0 + _SLACK)
    for angle, (lo, hi) in zip((mcp, pip, phi - mcp - pip), geometry.flexion_limits):
        ok &= (angle >= lo - _SLACK) & (angle <= hi + _SLACK)
    for candidate in phi[np.flatnonzero(ok)]:
        if TILT_RANGE[0] <= candidate <= TILT_RANGE[1]:
            q = _ik_at(geometry, reach, drop, float(candidate))
            if q is not None:
                return q
    return None
