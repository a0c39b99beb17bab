"""A gymnasium environment: the hand plays one phrase (or one random task instance) on the keyboard.

A task family comes as a *sampler*, a function that draws a fingered piece from the
environment's generator at every reset (``sampler=``); ``task=`` names one of the paper's
families (:mod:`pianobot.music.tasks`), and :mod:`pianobot.agent.tasks` makes the samplers of
every family, the ``melody`` phrases included (they need the fingering planner, above this layer).

``step()`` acts on the physics, then observes, then computes the reward. The episode lasts a
lead-in (the hand gets ready), the phrase, and a short tail; its end is ``truncated``, never
``terminated``: nothing about the state makes the future worthless. ``info`` carries the reward
terms, the key events with the finger that struck each key, and the keys to press now.

Observations (a dict; docs/simulator.md describes each): the score's L x (2+F) matrix for the
current step and ``lookahead`` following steps; the fingertips' tactile images of the last two
steps (uint8, pooled to ``tactile_pool``); wrist position and speed; finger joint angles and
speeds; for each finger, where the next key it has to play lies relative to its fingertip, how
soon, how loud, and how much longer to hold the key it holds (:func:`finger_targets`, not in the
paper); only when asked for (the paper's ablation), key angles and speeds; and with the pedal an
action, the score's pedal.
Actions, each in [-1, 1]: the actuated finger joints (of abduction, MCP, PIP, DIP per finger):
joint speeds (``WorldConfig.control='velocity'``, the default), angle targets with -1 and 1 at
the joint's limits ('position') or torques ('torque'); the wrist's speed along the rail (or, with
``discrete_wrist``, a white key to go to); with ``pedal_action``, the foot (above 0: pedal down).

Version history (the ids' ``-v<N>``, :data:`pianobot.env.VERSION`; a stored policy records the
version it was trained on, its manifest's ``simulator``, and the :class:`EnvConfig` it was
trained with; :data:`pianobot.agent.store.FORMAT` says how older records are read). A version
changes whenever the same actions could play differently; a change that adds a setting and
leaves the default environment playing as before keeps it:

- v1, later: ``pedal=`` (the written sustain pedal, worked by the environment, ``info["pedal"]``)
  and ``pedal_action``; without a pedal an episode plays as before.
- v1 (2026-11-24): every key is a body of its own, asleep while at rest and untouched. The
  keys' geometry, mass, hinge, limits and spring are v0's, but the solver orders its work
  differently: finger joints move 0.004 rad apart from v0's on average over a performance, and
  now and then a note one physics step or one velocity unit. Also added, without changing how
  a one-hand environment plays: ``length=`` and ``view=`` (one hand of a two-hand world,
  :mod:`pianobot.env.two_hands`).
- v0: the first registered version: the whole keyboard one body; finger targets with the next
  note's velocity (``target_velocity``) that point at note onsets with the time left to hold a
  held key (``target_onsets``), both of which can be turned off to reproduce the observations
  of policies trained before them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Callable

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from pianobot.config import check_ranges
from pianobot.env.rewards import RewardConfig, reward_terms
from pianobot.music.instrument import check_playable
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Piece
from pianobot.music.tasks import TASKS, make_task
from pianobot.music.tensor import FINGER, NOTE, VELOCITY, ScoreSpec, score_tensor, steps_for
from pianobot.sim.frame import HandView
from pianobot.sim.hand import JOINT_KINDS, finger_ik, joint_limits, joint_names
from pianobot.sim.keyboard import strike_points
from pianobot.sim.tactile import TactileConfig, TactileRenderer, pool, to_uint8
from pianobot.sim.world import PianoWorld, StepResult, WorldConfig

Sampler = Callable[[np.random.Generator], Piece]
"""Draws one task instance, a fingered piece, from a generator (the environment's ``np_random``)."""
IDLE_HEIGHT = 0.010
"""At the start the fingertips hover this high (m) over the white keys, 40 mm in from their front."""


def idle_pose(config: WorldConfig) -> np.ndarray:
    """Joint angles (abduction, MCP, PIP, DIP) of one finger at the start of an episode."""
    hand = config.hand
    reach = hand.palm_y - (config.keyboard.geometry.white_length - 0.040)
    flexion = finger_ik(hand.geometry, reach, hand.palm_height - IDLE_HEIGHT)
    if flexion is None:
        raise ValueError("the hand's palm_y / palm_height leave the keys out of the fingers' reach")
    return np.concatenate([[0.0], flexion])


SPEED_BOUND = 5.0
"""Speeds are observed as fractions of their maximum, clipped to +-SPEED_BOUND (a collision can spike them)."""


def _bounded(values) -> np.ndarray:
    # (np.minimum of np.maximum is np.clip, at a third of its cost on a few numbers)
    return np.minimum(np.maximum(np.asarray(values, dtype=np.float32), -SPEED_BOUND), SPEED_BOUND)


TARGET_SCALE = 0.1
"""Fingertip-to-key offsets are observed in units of this many metres (clipped to +-SPEED_BOUND)."""


def finger_targets(
    window: np.ndarray,
    tips: dict[int, np.ndarray],
    points: np.ndarray,
    fingers: tuple[int, ...],
    velocity: bool = True,
    previous: np.ndarray | None = None,
) -> np.ndarray:
    """For each finger, the next key it plays in the score ``window`` (steps x keys x channels):
    the offset (x, y, z) from its fingertip to that key's strike point in units of
    :data:`TARGET_SCALE`, how soon, 1 for now falling to 0 for "not in the window", and (with
    ``velocity``) how loud, the score's velocity channel (0 when nothing is to be played).

    With ``previous`` (the score row before the window's first; zeros before the piece), "next"
    means the next note to *start*, and a last column says how much longer the finger is to hold
    the key it holds now, as a fraction of the window (0 when it holds nothing or strikes now).
    Without it a held note reads as "strike now" for as long as it lasts: a policy cannot tell
    the strike from the hold, and a repeated note from the one before it.

    The score names keys by index; this says where they are for the hand and how hard to strike
    them, which is what a policy would otherwise have to learn for every key separately.
    """
    onsets = previous is not None
    targets = np.zeros((len(fingers), 4 + velocity + onsets), np.float32)
    steps = len(window)
    for i, finger in enumerate(fingers):
        on = window[:, :, FINGER + i] > 0.5
        if onsets:
            # a note starts where its key's finger channel turns on (repeated notes are apart by a step)
            before = np.vstack([previous[None, :, FINGER + i] > 0.5, on[:-1]])
            rows, keys = np.nonzero(on & ~before)
            held = np.flatnonzero(on[0] & before[0])
            if held.size:
                targets[i, -1] = np.argmin(np.append(on[:, held[0]], False)) / steps  # rows the hold goes on
        else:
            rows, keys = np.nonzero(on)
        if rows.size:
            targets[i, :3] = (points[keys[0]] - tips[finger]) / TARGET_SCALE
            targets[i, 3] = 1.0 - rows[0] / steps
            if velocity:
                targets[i, 4] = window[rows[0], keys[0], VELOCITY]
    return np.minimum(np.maximum(targets, -SPEED_BOUND), SPEED_BOUND)


def actuated_indices(config: "EnvConfig") -> np.ndarray:
    """Where the action's values go in the full command (every finger joint, then the wrist):
    the actuated joints of each finger in its hand model's order (:data:`JOINT_KINDS`), then the wrist."""
    kinds = config.world.hand.model.joint_kinds(config.world.hand.spec.fingers)
    return np.array([i for i, kind in enumerate(kinds) if kind in config.actuated] + [len(kinds)])


def finger_counts(config: "EnvConfig") -> tuple[tuple[int, ...], tuple[int, ...]]:
    """For each finger (in order): how many joints it has (observed), and how many the action moves."""
    model, fingers = config.world.hand.model, config.world.hand.spec.fingers
    joints = tuple(len(model.joints_of(f)) for f in fingers)
    moved = tuple(sum(j in config.actuated for j in model.joints_of(f)) for f in fingers)
    return joints, moved


def start_angles(config: WorldConfig) -> np.ndarray:
    """Every finger joint's angle at the start of an episode, in action order (:func:`idle_pose`
    for each finger, its model's joints)."""
    pose = dict(zip(JOINT_KINDS, idle_pose(config)))
    return np.array([pose[j] for j in config.hand.model.joint_kinds(config.hand.spec.fingers)])


@dataclass(frozen=True)
class EnvConfig:
    """Everything that shapes an episode, its observations and its reward."""

    world: WorldConfig = field(default_factory=WorldConfig)
    """Keyboard, hand, physics rates and control mode."""
    reward: RewardConfig = field(default_factory=RewardConfig)
    lookahead: int = 10
    """Score steps observed after the current one (10 = 0.5 s at the default 20 Hz)."""
    tactile: bool = True
    """Observe the fingertips' tactile images."""
    tactile_sensor: TactileConfig = field(default_factory=TactileConfig)
    tactile_pool: tuple[int, int] | None = (15, 20)
    """Average-pool the 60 x 80 images to this size (None keeps full resolution): what the agent
    sees, stores in its replay buffer and feeds its convolutions."""
    key_observations: bool = False
    """Also observe key angles and speeds (privileged; the paper's ablation)."""
    lead_in: float = 1.0
    """Seconds before the first note, for the hand to get ready (the wrist may have to cross the keyboard)."""
    tail: float = 0.25
    """Seconds after the last note ends."""
    target_observations: bool = True
    """Observe each finger's offset to the next key it plays (not in the paper; see docs/training.md)."""
    target_velocity: bool = True
    """With the target observations, also the velocity that key is to sound at."""
    target_onsets: bool = True
    """With the target observations, point each finger at its next note *onset* and say how much
    longer it is to hold the key it holds (without it a held note reads as one to strike now,
    and repeated notes cannot be told apart)."""
    random_start: bool = True
    """Start the wrist at a random position along the keyboard (else at its centre)."""
    pedal_action: bool = False
    """The sustain pedal is the action's last value (the foot: above 0 holds it down), the score's
    pedal is observed (``"pedal"``: down or up now and ``lookahead`` steps ahead) and rewarded
    (``reward.pedal_weight``). Without it the environment works the pedal as the piece's written
    pedal says (none for a task instance): the foot follows the score."""
    actuated: tuple[str, ...] = JOINT_KINDS
    """Finger joints the policy moves, all four by default (abduction is needed for chords and
    for keys beside the wrist's line); the others hold their starting angle, as the paper froze
    the joints not crucial to a task: ("mcp", "pip") leaves 2 per finger plus the wrist."""

    def __post_init__(self) -> None:
        if not self.actuated or set(self.actuated) - set(JOINT_KINDS) or len(set(self.actuated)) < len(self.actuated):
            raise ValueError(
                f"actuated joints must be distinct names from {', '.join(JOINT_KINDS)}; got {', '.join(self.actuated) or 'none'}"
            )
        check_ranges(self, lookahead=(0, 200), lead_in=(0.0, 60.0), tail=(0.0, 60.0))
        if self.tactile_pool is not None:
            (rows, cols), sensor = self.tactile_pool, self.tactile_sensor
            if not (rows >= 1 and cols >= 1 and sensor.rows % rows == 0 and sensor.cols % cols == 0):
                raise ValueError(
                    f"tactile_pool {rows} x {cols} must divide the sensor's {sensor.rows} x {sensor.cols} images"
                )

    @property
    def score_spec(self) -> ScoreSpec:
        return ScoreSpec(self.world.keyboard.spec, self.world.hand.spec, self.world.control_hz)


class PianoEnv(gym.Env):
    """The hand plays ``piece`` (a phrase), or a fresh instance from ``sampler`` (or of the
    paper's task ``task``) at each reset.

    ``length``: seconds the episode's score lasts at least (the piece's duration by default, or
    until its written ``pedal`` rises; the rest silent). ``view``: one hand of a two-hand world, seen through its window
    (:class:`~pianobot.sim.frame.HandView`), instead of a world of its own; the world's owner
    (:class:`~pianobot.env.two_hands.HandsEnv`) resets it between :meth:`draw_start` and
    :meth:`begin`, and steps it before :meth:`absorb`."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": WorldConfig.control_hz}

    def __init__(
        self,
        piece: Piece | None = None,
        task: str | None = None,
        config: EnvConfig = EnvConfig(),
        render_mode: str | None = None,
        sampler: Sampler | None = None,
        length: float | None = None,
        view: HandView | None = None,
        pedal: Pedal | None = None,
    ):
        if [piece, task, sampler].count(None) != 2:
            raise ValueError("give exactly one of piece=, task= or sampler=")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode {render_mode!r}: choose None or 'rgb_array'")
        if task is not None:
            if task not in TASKS:
                raise ValueError(
                    f"unknown task {task!r}: choose one of {', '.join(TASKS)} (other families come as a "
                    "sampler=, from pianobot.agent.tasks)"
                )
            sampler = partial(make_task, task, keyboard=config.score_spec.keyboard)
        self.config = config
        self.spec_score = config.score_spec
        self.task = task
        self.sampler = sampler
        self.render_mode = render_mode
        if piece is not None:
            check_playable(piece, self.spec_score.keyboard, self.spec_score.hand)
        if view is not None and (view.config.keyboard.spec != config.world.keyboard.spec or render_mode is not None):
            raise ValueError("a hand's view needs the environment's keyboard to be the view's, and no render mode")
        self.piece = piece
        self.pedal = pedal or Pedal()  # (the written sustain pedal, in the piece's time; none for a task)
        self.length = max(length or 0.0, self.pedal.spans[-1][1]) if self.pedal else length  # (until it rises)
        self.world = view if view is not None else PianoWorld(config.world)
        self.owns_world = view is None
        """False for one hand of a world of two (:class:`pianobot.env.two_hands.HandsEnv` steps and resets it)."""
        self.n_fingers = len(config.world.hand.spec.fingers)
        self.n_joints = len(joint_names(config.world.hand.spec))
        keys = self.spec_score.keyboard.count
        self.lead_steps = steps_for(config.lead_in, self.spec_score)
        self.strike_points = strike_points(config.world.keyboard)
        self.tactile = (
            TactileRenderer(config.tactile_sensor, config.world.hand.geometry, self.world.boxes)
            if config.tactile
            else None
        )

        obs = {
            "score": spaces.Box(0.0, 1.0, (config.lookahead + 1, keys, self.spec_score.channels), np.float32),
            "wrist": spaces.Box(-SPEED_BOUND, SPEED_BOUND, (2,), np.float32),
            "joints": spaces.Box(-np.pi, np.pi, (self.n_joints,), np.float32),
            "joint_velocities": spaces.Box(-SPEED_BOUND, SPEED_BOUND, (self.n_joints,), np.float32),
        }
        if config.target_observations:
            width = 4 + config.target_velocity + config.target_onsets
            obs["targets"] = spaces.Box(-SPEED_BOUND, SPEED_BOUND, (self.n_fingers, width), np.float32)
        if config.tactile:
            rows, cols = config.tactile_pool or (config.tactile_sensor.rows, config.tactile_sensor.cols)
            obs["tactile"] = spaces.Box(0, 255, (2, self.n_fingers, rows, cols), np.uint8)
        if config.key_observations:
            obs["keys"] = spaces.Box(-SPEED_BOUND, SPEED_BOUND, (keys,), np.float32)
            obs["key_velocities"] = spaces.Box(-SPEED_BOUND, SPEED_BOUND, (keys,), np.float32)
        if config.pedal_action:
            obs["pedal"] = spaces.Box(0.0, 1.0, (config.lookahead + 1,), np.float32)
        self.observation_space = spaces.Dict(obs)
        self.actuated = actuated_indices(config)
        # what the joints left out of the action get: no speed, or (position control) their starting angles
        self.frozen = np.zeros(self.n_joints + 1)
        if config.world.control == "position":
            low, high = joint_limits(config.world.hand)
            self.frozen[:-1] = (start_angles(config.world) - low) / (high - low) * 2.0 - 1.0
        self.action_space = spaces.Box(-1.0, 1.0, (len(self.actuated) + config.pedal_action,), np.float32)
        self.pedal_down = False  # (whether the foot held the pedal down in the step just taken)
        if piece is not None:
            self._set_piece(piece)

    # -- episode bookkeeping -------------------------------------------------------------------
    def _set_piece(self, piece: Piece) -> None:
        self.piece = piece
        spec = self.spec_score
        body = steps_for(max(piece.duration, self.length or 0.0) + self.config.tail, spec)
        self.horizon = self.lead_steps + body
        padded = self.horizon + self.config.lookahead + 1
        tensor = score_tensor(piece, spec, steps=body)
        self.score = np.zeros((padded, spec.keyboard.count, spec.channels), dtype=np.float32)
        self.score[self.lead_steps : self.lead_steps + body] = tensor
        self.pedal_score = np.zeros(padded, np.float32)  # (the written pedal at each score row's middle)
        self.pedal_score[self.lead_steps : self.lead_steps + body] = self.pedal.steps(body, spec.control_hz)
        finger_numbers = np.array(spec.hand.fingers)
        has_finger = self.score[:, :, FINGER:].max(axis=2) > 0.5
        self.target_finger = np.where(has_finger, finger_numbers[self.score[:, :, FINGER:].argmax(axis=2)], 0)

    @property
    def score_start(self) -> float:
        """World time (s) at which the piece's time 0 falls.

        The score tensor puts a note in the row nearest its onset (row r stands for r * dt
        +- dt/2), so control step t, which sounds whatever the keys do from world time t * dt
        to (t + 1) * dt, stands for the same span: the piece's time 0 is the middle of the
        first step after the lead-in. The reward of a step thus credits onsets within half a
        step either side of the score's, inside the note F1's 50 ms tolerance."""
        return (self.lead_steps + 0.5) / self.spec_score.control_hz

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        wrist = self.draw_start(seed)
        self.world.reset(wrist, self.start_pose())
        return self.begin()

    # (one hand of a world of two resets in three parts: its world's owner resets the world between them)
    def draw_start(self, seed: int | None = None) -> float:
        """Seed the episode, draw its piece (from a sampler) and the wrist's start (m along the keyboard)."""
        super().reset(seed=seed)
        if self.sampler is not None:
            piece = self.sampler(self.np_random)
            check_playable(piece, self.spec_score.keyboard, self.spec_score.hand)
            self._set_piece(piece)
        width = self.world.width
        return float(self.np_random.uniform(0.0, width)) if self.config.random_start else width / 2

    def start_pose(self) -> np.ndarray:
        """Every finger joint's angle at the start of an episode."""
        return start_angles(self.config.world)

    def begin(self) -> tuple[dict, dict]:
        """The episode's first observation and info, once the world is reset."""
        self._tip_cache = None
        self.t = 0
        self.pedal_down = False
        self.key_finger = np.zeros(self.spec_score.keyboard.count, dtype=int)
        if self.tactile is not None:
            shape = self.observation_space["tactile"].shape[1:]
            self.tactile_history = [np.zeros(shape, np.uint8), np.zeros(shape, np.uint8)]
            self.tactile_history[1] = self._tactile_image()
        return self._observe(), {"piece": self.piece}

    # -- the step: act, observe, reward ------------------------------------------------------
    def full_action(self, action) -> np.ndarray:
        """The policy's action spread over every finger joint and the wrist (frozen joints: speed 0, or
        in position control the angles they start at)."""
        full = self.frozen.copy()
        full[self.actuated] = action
        return full

    def step(self, action):
        action = np.asarray(action, dtype=np.float64)
        self.pedal_down = self.foot(action)
        return self.absorb(self.world.step(self.full_action(action[: len(self.actuated)])))

    def foot(self, action: np.ndarray | None = None) -> bool:
        """Whether the pedal is down this step: the action's foot (``pedal_action``), else the written pedal."""
        if self.config.pedal_action and action is not None:
            return bool(action[-1] > 0)
        return bool(self.pedal_score[self.t] > 0.5)

    def absorb(self, result: StepResult):
        """Observe and reward what a step of the world did (``step`` without acting: one hand of a
        world of two is acted for by the world's owner)."""
        self._tip_cache = None  # the hand has moved
        lowest = self.spec_score.keyboard.lowest
        for event in result.events:
            key = event.pitch - lowest
            self.key_finger[key] = result.fingers.get(event.pitch, 0) if event.on else 0

        if self.tactile is not None:
            self.tactile_history = [self.tactile_history[1], self._tactile_image()]
        target_row = self.score[self.t]
        played = result.pressed_velocity / 127.0
        terms = reward_terms(
            self.config.reward,
            played,
            self.key_finger,
            target_row[:, VELOCITY] * target_row[:, NOTE],
            self.target_finger[self.t],
            self._fingertip_distances() if self.config.reward.closeness_weight else None,
        )
        if self.config.pedal_action:  # (the foot as the score says, down or up)
            terms["pedal"] = self.config.reward.pedal_weight * (self.pedal_down == (self.pedal_score[self.t] > 0.5))
        reward = float(sum(terms.values()))
        self.t += 1
        truncated = self.t >= self.horizon
        info = {
            "reward_terms": terms,
            "events": result.events,
            "fingers": result.fingers,
            "pressed": result.pressed,
            "target": target_row[:, NOTE] > 0.5,
            "pedal": self.pedal_down,
        }
        return self._observe(), reward, False, truncated, info

    def _fingertip_distances(self) -> np.ndarray:
        """For the keys to play now, or else the next ones in the lookahead: each assigned
        fingertip's distance (m) to its key's strike point."""
        window = self.target_finger[self.t : self.t + self.config.lookahead + 1]
        rows = np.flatnonzero(window.any(axis=1))
        if rows.size == 0:
            return np.zeros(0)
        keys = np.flatnonzero(window[rows[0]])
        tips = self._tips()
        return np.array([np.linalg.norm(tips[window[rows[0], k]] - self.strike_points[k]) for k in keys])

    def _tips(self) -> dict[int, np.ndarray]:
        """The fingertips' points, asked of the simulator once per step (reward and observation share them)."""
        if self._tip_cache is None:
            self._tip_cache = self.world.tip_points()
        return self._tip_cache

    def targets(self, window: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
        """:func:`finger_targets` for the score window at the current step, from the hand's current
        pose; ``previous``: the score row before the window (default: the episode's own; compositional
        execution gives its phrase's)."""
        if not self.config.target_onsets:
            previous = None
        elif previous is None:
            previous = self.score[self.t - 1] if self.t > 0 else np.zeros_like(self.score[0])
        fingers = self.spec_score.hand.fingers
        return finger_targets(window, self._tips(), self.strike_points, fingers, self.config.target_velocity, previous)

    def _tactile_image(self) -> np.ndarray:
        angles, _ = self.world.key_state()
        forces = self.world.tip_forces()
        images = []
        for finger, link in self.world.tip_links.items():
            position, rotation = self.world.link_pose(link)
            images.append(self.tactile.image(position, rotation, angles, forces[finger]))
        images = np.stack(images)
        if self.config.tactile_pool is not None:
            images = pool(images, *self.config.tactile_pool)
        return to_uint8(images)

    def _observe(self) -> dict:
        cfg, world = self.config, self.world
        wrist, wrist_speed, angles, speeds = world.hand_state()
        hand = cfg.world.hand
        obs = {
            "score": self.score[self.t : self.t + cfg.lookahead + 1].copy(),
            "wrist": _bounded([2 * wrist / world.width - 1, wrist_speed / hand.max_wrist_speed]),
            "joints": angles.astype(np.float32),
            "joint_velocities": _bounded(speeds / hand.max_joint_speed),
        }
        if cfg.target_observations:
            obs["targets"] = self.targets(obs["score"])
        if self.tactile is not None:
            obs["tactile"] = np.stack(self.tactile_history)
        if cfg.key_observations:
            key_angles, key_speeds = world.key_state()
            max_angle = cfg.world.keyboard.geometry.max_angle
            obs["keys"] = _bounded(key_angles / max_angle)
            obs["key_velocities"] = _bounded(key_speeds / (max_angle * cfg.world.control_hz))
        if cfg.pedal_action:
            obs["pedal"] = self.pedal_score[self.t : self.t + cfg.lookahead + 1].copy()
        return obs

    def render(self) -> np.ndarray | None:
        """The simulation's camera frame (height x width x 3, uint8) with ``render_mode="rgb_array"``;
        without a render mode, None and a warning, as gymnasium's environments do."""
        if self.render_mode is None:
            gym.logger.warn(
                'render() is called without a render mode: make the environment with render_mode="rgb_array"'
            )
            return None
        return self.world.render()

    def close(self):
        if self.owns_world:
            self.world.close()
