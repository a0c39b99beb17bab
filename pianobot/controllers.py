"""Controllers with the interface a trained policy has: ``reset()``, then ``act(observation) -> action``.

- :class:`RandomController`: uniform random actions (the paper's random baseline).
- :class:`ScriptedPianist`: plays from the score window in the observation with human priors:
  the wrist slides so the assigned fingers can reach their keys, abduction puts each fingertip
  over its key, and the assigned finger strikes at the speed that the keyboard's velocity
  curve turns into the target velocity, starting early enough to land on the onset.

The scripted pianist reads only the observation (score window, wrist, joint angles) and the
hand's and keyboard's geometry; it is the proof that the simulator is playable.
"""

from __future__ import annotations

import math

import numpy as np

from pianobot.env import EnvConfig
from pianobot.music.tensor import FINGER, NOTE, VELOCITY
from pianobot.sim.hand import FINGER_BASE_X, finger_ik, lowest_point_in_finger_plane
from pianobot.sim.keyboard import key_boxes


class RandomController:
    """Uniform random actions in [-1, 1]."""

    def __init__(self, action_size: int, seed: int | None = None):
        self.action_size = action_size
        self.rng = np.random.default_rng(seed)

    def reset(self) -> None:
        pass

    def act(self, observation: dict) -> np.ndarray:
        return self.rng.uniform(-1.0, 1.0, self.action_size).astype(np.float32)


class ScriptedPianist:
    """A hand-written pianist for velocity control. See the module docstring."""

    white_contact_y = 0.110
    """Where along a white key the fingertip strikes (m from the hinge; the front is at 0.150)."""
    black_contact_y = 0.085
    """Where along a black key the fingertip strikes (its front is at 0.095)."""
    idle_height = 0.010
    """Fingertip height over its key's top (or the white keys' top) when it has nothing to do (m)."""
    min_ready_height = 0.003
    """Lowest hover height before a strike (m)."""
    path_tolerance = 0.002
    """A fingertip that must rise more than this (m) rises first; one that must move across more than this moves across before it goes down."""
    band_clearance = 0.004
    """Crossing into or out of the black keys' band, the fingertip stays this far (m) above their tops."""
    aim_tolerance = 0.004
    """A finger waits at idle height until its tip is this close (m) to above its key."""
    strike_margin = 0.001
    """The fingertip is planned to pass the strike depth by up to this much (m) at the onset."""
    hold_depth_margin = 0.0025
    """A held key is pressed this far (m) past its strike depth before the finger just holds it."""
    hold_speed = 0.08
    """MCP action while holding a key down."""
    white_gain = 1.0
    """Correction on the strike speed for white keys, measured (see docs/simulator.md)."""
    black_gain = 1.0
    """Correction on the strike speed for black keys, measured."""

    def __init__(self, config: EnvConfig):
        if config.world.control != "velocity":
            raise ValueError("the scripted pianist drives joint velocities: use control='velocity'")
        self.config = config
        world = config.world
        self.hand = world.hand
        self.geometry = world.hand.geometry
        self.fingers = world.hand.spec.fingers
        self.dt = 1.0 / world.control_hz
        boxes = key_boxes(world.keyboard)
        self.key_x = np.array([b.center[0] for b in boxes])
        self.black = np.array([b.black for b in boxes])
        self.key_top = np.where(self.black, world.keyboard.geometry.black_rise, 0.0)
        self.width = sum(not b for b in self.black) * world.keyboard.geometry.white_pitch
        self.curve = world.keyboard.curve
        self.strike_angle = world.keyboard.strike_fraction * world.keyboard.geometry.max_angle
        self.white_length = world.keyboard.geometry.white_length
        self.black_rise = world.keyboard.geometry.black_rise
        self.black_band_y = world.keyboard.geometry.black_length + world.hand.geometry.tip_radius
        self.reset()

    def reset(self) -> None:
        self.previous_row: np.ndarray | None = None

    # -- geometry ------------------------------------------------------------------------------
    def _contact_y(self, key: int) -> float:
        return self.black_contact_y if self.black[key] else self.white_contact_y

    def _ik(self, reach: float, drop: float, current: np.ndarray) -> np.ndarray:
        """Flexion angles for a fingertip target; out of reach, the finger keeps its shape."""
        q = finger_ik(self.geometry, reach, drop)
        return current if q is None else q

    # -- planning --------------------------------------------------------------------------------
    def _runs(self, score: np.ndarray, slot: int) -> list[tuple[int, int, int, float]]:
        """(key, first step, end step, velocity) of this finger's notes in the window, in time order."""
        on = (score[:, :, NOTE] > 0.5) & (score[:, :, FINGER + slot] > 0.5)
        runs = []
        for key in np.flatnonzero(on.any(axis=0)):
            column = np.concatenate([[0], on[:, key].astype(int), [0]])
            starts, ends = np.flatnonzero(np.diff(column) == 1), np.flatnonzero(np.diff(column) == -1)
            for s, e in zip(starts, ends):
                runs.append((int(key), int(s), int(e), float(score[s, key, VELOCITY]) * 127))
        return sorted(runs, key=lambda r: r[1])

    def _tip_speed(self, key: int, velocity: float) -> float:
        """Downward fingertip speed (m/s) at which a strike on ``key`` sounds at ``velocity``."""
        front_speed = float(self.curve.speed(velocity))  # the keyboard's curve is in front-edge speed
        gain = self.black_gain if self.black[key] else self.white_gain
        return gain * front_speed * self._contact_y(key) / self.white_length

    def _strike_depth(self, key: int) -> float:
        """How far below the key's top surface the fingertip is when the key sounds (m)."""
        return self._contact_y(key) * math.tan(self.strike_angle)

    def _ready_steps(self, tip_speed: float, depth: float) -> int:
        """Control steps of constant-speed travel from the ready height to the strike."""
        return max(1, math.ceil((self.min_ready_height + depth) / (tip_speed * self.dt)))

    def act(self, observation: dict) -> np.ndarray:
        """One action from the score window, the wrist position and the joint angles."""
        score = observation["score"]
        joints = np.asarray(observation["joints"], dtype=float).reshape(len(self.fingers), 4)
        wrist = (float(observation["wrist"][0]) + 1) / 2 * self.width
        plans: dict[int, tuple] = {}
        for slot, finger in enumerate(self.fingers):
            plan = self._plan_finger(score, slot, joints[slot])
            if plan is not None:
                plans[finger] = plan
        self.previous_row = score[0].copy()
        return self._command(plans, joints, wrist)

    def _plan_finger(self, score: np.ndarray, slot: int, q: np.ndarray) -> tuple | None:
        """(key, phase, ready height, tip speed) for one finger, or None when it has nothing to do.

        Phases: 'ready' hovers over the key; 'strike' moves down so as to reach the strike depth
        exactly at the onset, at the speed the target velocity needs; 'hold' keeps the key down.
        """
        runs = self._runs(score, slot)
        current = next((r for r in runs if r[1] == 0), None)
        upcoming = next((r for r in runs if r[1] > 0), None)
        if current is not None:
            key = current[0]
            began_earlier = self.previous_row is not None and (
                self.previous_row[key, NOTE] > 0.5 and self.previous_row[key, FINGER + slot] > 0.5
            )
            if upcoming is not None:
                speed = self._tip_speed(upcoming[0], upcoming[3])
                depth = self._strike_depth(upcoming[0])
                if upcoming[1] - self._ready_steps(speed, depth) <= 1:  # the next strike is due: let go now
                    return self._approach(upcoming, q)
            if not began_earlier:
                return self._approach(current, q)  # the onset step itself: strike now
            # holding: keep going down at the strike speed until safely past the strike depth
            # (a strike that lands a little late still sounds at the right velocity), then press
            tip_height = self._tip_height(q, key)
            floor = -self._strike_depth(key) - self.hold_depth_margin
            if tip_height > floor:
                speed = self._tip_speed(key, current[3])
                return (key, "strike", 0.0, max(tip_height - speed * self.dt, floor))
            return (key, "hold", 0.0, 0.0)
        if upcoming is not None:
            return self._approach(upcoming, q)
        return None

    def _approach(self, run: tuple, q: np.ndarray) -> tuple:
        key, start, _, velocity = run
        speed = self._tip_speed(key, velocity)
        depth = self._strike_depth(key)
        steps = self._ready_steps(speed, depth)
        height = steps * speed * self.dt - depth
        if start > steps:
            return (key, "ready", height, speed)
        # closed loop: after this step the fingertip should be where constant-speed travel for the
        # remaining (start - 1) steps ends exactly at the strike depth on the onset
        tip_height = self._tip_height(q, key)
        # aim a little past the strike depth so the key sounds while the finger still moves at speed
        past = min(self.strike_margin, speed * self.dt / 4)
        goal = tip_height - speed * self.dt if start == 0 else -depth - past + speed * self.dt * (start - 1)
        floor = -depth - self.hold_depth_margin
        return (key, "strike", height, float(np.clip(goal, floor, tip_height)))

    def _safe_path(self, q: np.ndarray, reach: float, drop: float) -> tuple[float, float]:
        """Move between the white keys' band and the black keys' band high, never low across a black key's front.

        Going towards a black key, rise first; coming back from one to a low target, move back first.
        """
        now_reach, now_drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        band_reach = self.hand.palm_y - self.black_band_y  # a tip reaching further lies over the black keys
        in_band_now = now_reach > band_reach
        in_band_target = reach > band_reach
        safe_drop = self.hand.palm_height - (self.black_rise + self.band_clearance)
        if in_band_target and not in_band_now and now_drop > safe_drop:
            return now_reach, safe_drop  # rise first
        if in_band_now and not in_band_target and drop > safe_drop and now_drop > safe_drop:
            return reach, now_drop  # back out first, at the present height
        return reach, drop

    def _tip_height(self, q: np.ndarray, key: int) -> float:
        """Height of the fingertip's lowest point over the key's top surface (m), from the joint angles."""
        _, drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        return self.hand.palm_height - drop - self.key_top[key]

    def _mcp_for_height(self, q: np.ndarray, height_over_top: float, top: float) -> float:
        """The MCP angle that puts the fingertip at this height, PIP and DIP unchanged (Newton in 1D)."""
        target_drop = self.hand.palm_height - top - height_over_top
        angle = float(q[1])
        for _ in range(6):
            flexion = np.array([angle, q[2], q[3]])
            _, drop = lowest_point_in_finger_plane(self.geometry, flexion)
            flexion[0] += 1e-4
            _, drop2 = lowest_point_in_finger_plane(self.geometry, flexion)
            slope = (drop2 - drop) / 1e-4
            if abs(slope) < 1e-6:
                break
            angle += (target_drop - drop) / slope
        return angle

    # -- turning plans into joint speeds ------------------------------------------------------
    def _command(self, plans: dict, joints: np.ndarray, wrist: float) -> np.ndarray:
        hand, geometry = self.hand, self.geometry
        if plans:
            wanted = [self.key_x[plan[0]] - FINGER_BASE_X[f] for f, plan in plans.items()]
            wrist_target = float(np.clip(np.mean(wanted), 0.0, self.width))
        else:
            wrist_target = wrist
        action = np.zeros(len(self.fingers) * 4 + 1)
        step_limit = hand.max_joint_speed * self.dt
        wrist_step = float(np.clip(wrist_target - wrist, -hand.max_wrist_speed * self.dt, hand.max_wrist_speed * self.dt))
        wrist_next = wrist + wrist_step  # fingers aim from where the wrist will be, so held keys stay held
        for slot, finger in enumerate(self.fingers):
            q = joints[slot]
            key, phase, height, speed = plans.get(finger, (None, "idle", 0.0, 0.0))
            contact_y = self._contact_y(key) if key is not None else self.white_contact_y
            top = self.key_top[key] if key is not None else 0.0
            forward = hand.palm_y - contact_y
            offset = self.key_x[key] - (wrist_next + FINGER_BASE_X[finger]) if key is not None else 0.0
            abduction = float(np.clip(math.atan2(offset, forward), -geometry.abduction_limit, geometry.abduction_limit))
            reach = forward / math.cos(abduction)  # keeps the tip at contact_y even when the key is out of reach
            if phase in ("ready", "strike") and abs(offset - forward * math.tan(abduction)) > self.aim_tolerance:
                phase = "idle"  # not over the key yet: travel high
            if phase == "idle":
                drop = hand.palm_height - max(self.idle_height, top + self.idle_height)
            elif phase in ("ready", "strike"):
                drop = hand.palm_height - (top + height)
            else:  # hold: aim a little below the key's surface
                drop = hand.palm_height - (top - 0.004)
            reach, drop = self._safe_path(q, reach, drop)
            now_reach, now_drop = lowest_point_in_finger_plane(geometry, q[1:])
            rising = drop < now_drop - self.path_tolerance
            if not rising and abs(reach - now_reach) > self.path_tolerance:
                drop = min(drop, now_drop)  # across at this height first, then down
            desired = np.concatenate([[abduction], self._ik(reach, drop, q[1:])])
            command = np.clip((desired - q) / step_limit, -1.0, 1.0)
            if rising and phase != "strike":  # up first, by the knuckle alone, so the tip never dips
                height = hand.palm_height - drop
                command[1] = np.clip((self._mcp_for_height(q, height, 0.0) - q[1]) / step_limit, -1.0, 1.0)
                command[2:] = 0.0
            if phase == "strike":  # ``speed`` holds the height (over the key) to reach by the end of this step
                command[1] = np.clip((self._mcp_for_height(q, speed, top) - q[1]) / step_limit, 0.0, 1.0)
                command[2:] = 0.0  # PIP and DIP keep their shape: the finger pivots at the knuckle
            elif phase == "hold":
                command[1] = max(command[1], self.hold_speed)
            action[slot * 4 : slot * 4 + 4] = command
        action[-1] = wrist_step / (hand.max_wrist_speed * self.dt)
        return action.astype(np.float32)
