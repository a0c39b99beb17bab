"""The scripted pianist: a hand-written controller with the interface a trained policy has
(``reset()``, then ``act(observation) -> action``).

It plays from the score window in the observation with human priors:
  the wrist slides so the assigned fingers can reach their keys, abduction puts each fingertip
  over its key, and the assigned finger strikes at the speed that the keyboard's velocity
  curve turns into the target velocity, starting early enough to land on the onset.

The scripted pianist reads only the observation (score window, wrist, joint angles) and the
hand's and keyboard's geometry; it is the proof that the simulator is playable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pianobot.env.piano import EnvConfig, actuated_indices
from pianobot.music.tensor import FINGER, NOTE, VELOCITY
from pianobot.sim.hand import FINGER_BASE_X, PREFERRED_TILT, TILT_RANGE, finger_ik, lowest_point_in_finger_plane
from pianobot.sim.keyboard import BLACK_STRIKE_FROM_FRONT, WHITE_STRIKE_FROM_FRONT, key_boxes


@dataclass
class Plan:
    """What one finger does in this control step."""

    key: int
    phase: str
    """'ready' (hover at ``height``), 'strike' (down to ``goal``) or 'hold' (keep the key down, going to ``goal``)."""
    height: float = 0.0
    """Ready height over the key's top (m)."""
    goal: float = 0.0
    """Fingertip height over the key's top to reach by the end of this step (m)."""
    start: int = 0
    """Control steps until the note's onset."""
    lead: int = 0
    """Control steps the strike takes from the ready height."""
    next: tuple | None = None
    """While holding: this finger's next note in the window."""
    next_start: int = 0
    next_lead: int = 0


class ScriptedPianist:
    """A hand-written pianist for velocity control. See the module docstring."""

    idle_height = 0.010
    """Fingertip height over its key's top (or the white keys' top) when it has nothing to do (m)."""
    min_ready_height = 0.003
    """Lowest hover height before a strike (m)."""
    path_tolerance = 0.002
    """A fingertip that must rise more than this (m) rises first; one that must move across more than this moves across before it goes down."""
    clearance = 0.003
    """The hand does not slide while a finger that has let go is lower than this over the white keys (m)."""
    band_clearance = 0.004
    """Crossing into or out of the black keys' band, the fingertip stays this far (m) above their tops."""
    band_tolerance = 0.0002
    """A fingertip this little (m) under the safe height for crossing counts as over it: one that
    rose towards it could stop a hair short of it and wait there for ever."""
    aim_tolerance = 0.004
    """A finger waits at idle height until its tip is this close (m) to above its key."""
    strike_margin = 0.001
    """The fingertip is planned to pass the strike depth by up to this much (m) at the onset."""
    hold_depth_margin = 0.0025
    """A held key is pressed this far (m) past its strike depth before the finger just holds it."""
    max_move = 0.008
    """Longest fingertip move (m) in one control step when positioning (strikes are not limited)."""
    prepare_steps = 4
    """Control steps a finger needs to lift, move over and settle before a strike from the ready height."""
    hold_slide = 0.008
    """How far (m) the wrist may move in one step while a finger holds a key."""
    tilt_step = 0.15
    """Most change (rad) of the fingertip's tilt the IK asks for in one control step."""
    hold_reach = 0.030
    """How far (m) the wrist may be from straight over a held key (the abduction makes up for it)."""

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
        # where along a key the fingertip strikes (m from the hinge): the keyboard's strike points
        geometry = world.keyboard.geometry
        self.white_contact_y = geometry.white_length - WHITE_STRIKE_FROM_FRONT
        self.black_contact_y = geometry.black_length - BLACK_STRIKE_FROM_FRONT
        self.black_rise = world.keyboard.geometry.black_rise
        self.black_band_y = world.keyboard.geometry.black_length + world.hand.geometry.tip_radius
        self.actuated = actuated_indices(config)  # the joints the environment's actions move
        self.reset()

    def reset(self) -> None:
        self.previous_row: np.ndarray | None = None

    # -- geometry ------------------------------------------------------------------------------
    def _contact_y(self, key: int) -> float:
        return self.black_contact_y if self.black[key] else self.white_contact_y

    def _ik(self, reach: float, drop: float, current: np.ndarray) -> np.ndarray:
        """Flexion angles for a fingertip target; out of reach, the finger keeps its shape.

        The fingertip's tilt moves towards the preferred one by at most :attr:`tilt_step` per
        step: letting the IK pick any tilt can flip the finger between very different shapes
        from one step to the next, faster than its joints follow."""
        # a finger curled (or stretched) beyond the IK's tilts, as a policy may leave it, starts
        # from the nearest one: from outside them no point would be in reach and it would stay so
        tilt = float(np.clip(np.sum(current), *TILT_RANGE))
        tilt += float(np.clip(PREFERRED_TILT - tilt, -self.tilt_step, self.tilt_step))
        for change in (0.0, 0.002, -0.002, 0.004, -0.004, 0.008, 0.012, 0.016, 0.02):
            q = finger_ik(self.geometry, reach, drop + change, tilt)  # the nearest height this finger can reach there
            if q is not None:
                return q
        return current

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
        return front_speed * self._contact_y(key) / self.white_length

    def _strike_depth(self, key: int) -> float:
        """How far below the key's top surface the fingertip is when the key sounds (m)."""
        return self._contact_y(key) * math.tan(self.strike_angle)

    def _overshoot(self, tip_speed: float) -> float:
        """How far (m) past the strike depth the fingertip is planned to be when the key sounds."""
        return min(self.strike_margin, tip_speed * self.dt / 4)

    def _strike_point(self, tip_speed: float) -> float:
        """When in the onset's control step (0 = its start, 1 = its end) the key should sound.

        The environment's steps are centred on the score's rows, so the middle of the step is
        on time. A loud (fast) strike sounds later in the step: the fingertip goes on at the
        strike speed for the rest of the step and must stop short of the key's bottom
        (:attr:`hold_depth_margin` past the strike depth), or the step's speed would drop."""
        room = self.hold_depth_margin - self._overshoot(tip_speed)  # below the strike depth
        return float(np.clip(1.0 - room / (tip_speed * self.dt), 0.5, 1.0))

    def _ready_steps(self, tip_speed: float, depth: float) -> int:
        """Control steps of constant-speed travel from the ready height before the onset's step."""
        point = self._strike_point(tip_speed)
        return max(1, math.ceil((self.min_ready_height + depth) / (tip_speed * self.dt) - point))

    def act(self, observation: dict) -> np.ndarray:
        """One action from the score window, the wrist position and the joint angles."""
        score = observation["score"]
        joints = np.asarray(observation["joints"], dtype=float).reshape(len(self.fingers), 4)
        wrist = (float(observation["wrist"][0]) + 1) / 2 * self.width
        plans: dict[int, Plan] = {}
        for slot, finger in enumerate(self.fingers):
            plan = self._plan_finger(score, slot, joints[slot])
            if plan is not None:
                plans[finger] = plan
        self._let_go(plans, joints, wrist)
        self.previous_row = score[0].copy()
        return self._command(plans, joints, wrist)[self.actuated]

    def _wrist_for(self, finger: int, key: int) -> float:
        """Wrist position that puts ``finger`` straight over ``key``."""
        return float(self.key_x[key] - FINGER_BASE_X[finger])

    def _let_go(self, plans: dict[int, "Plan"], joints: np.ndarray, wrist: float) -> None:
        """Release held keys early when the hand must get ready for what comes next.

        A holding finger lets go in time for its own next strike; every holding finger lets go
        in time for a strike (its own or another finger's) that needs the wrist where a held
        key is out of reach, counting the steps the wrist needs to get there.
        """
        def release(finger: int) -> None:
            nxt = plans[finger].next
            if nxt is None:
                del plans[finger]
            else:
                plans[finger] = self._approach(nxt, joints[self.fingers.index(finger)])

        for finger, plan in list(plans.items()):
            if plan.phase == "hold" and plan.next is not None and plan.next_start - plan.next_lead - self.prepare_steps <= 0:
                release(finger)
        holds = {f: p for f, p in plans.items() if p.phase == "hold"}
        if not holds:
            return
        low = max(self._wrist_for(f, p.key) for f, p in holds.items()) - self.hold_reach
        high = min(self._wrist_for(f, p.key) for f, p in holds.items()) + self.hold_reach
        strikes = [(f, p.key, p.start, p.lead) for f, p in plans.items() if p.phase != "hold"]
        strikes += [(f, p.next[0], p.next_start, p.next_lead) for f, p in holds.items() if p.next is not None]
        for finger, key, start, lead in strikes:
            wanted = self._wrist_for(finger, key)
            travel = max(0.0, low - wanted, wanted - high)
            shift_steps = math.ceil(travel / (self.hand.max_wrist_speed * self.dt))
            if travel > 0 and start - lead - self.prepare_steps - shift_steps <= 0:
                for held in holds:
                    release(held)
                return

    def _plan_finger(self, score: np.ndarray, slot: int, q: np.ndarray) -> "Plan | None":
        """What one finger should do now, or None when it has nothing to do.

        Phases: 'ready' hovers over the key; 'strike' moves down so as to reach the strike depth
        exactly at the onset, at the speed the target velocity needs; 'hold' keeps a sounding
        key down (first going on down at the strike speed, so that a strike that lands a little
        late still sounds at the right velocity).
        """
        runs = self._runs(score, slot)
        current = next((r for r in runs if r[1] == 0), None)
        upcoming = next((r for r in runs if r[1] > 0), None)
        if current is None:
            return self._approach(upcoming, q) if upcoming is not None else None
        key = current[0]
        began_earlier = self.previous_row is not None and (
            self.previous_row[key, NOTE] > 0.5 and self.previous_row[key, FINGER + slot] > 0.5
        )
        if not began_earlier:
            return self._approach(current, q)  # the onset step itself: strike now
        tip_height = self._tip_height(q, key)
        floor = -self._strike_depth(key) - self.hold_depth_margin
        goal = max(tip_height - self._tip_speed(key, current[3]) * self.dt, floor)
        plan = Plan(key, "hold", goal=goal)
        if upcoming is not None:
            plan.next = upcoming
            plan.next_start = upcoming[1]
            plan.next_lead = self._ready_steps(self._tip_speed(upcoming[0], upcoming[3]), self._strike_depth(upcoming[0]))
        return plan

    def _approach(self, run: tuple, q: np.ndarray) -> "Plan":
        key, start, _, velocity = run
        speed = self._tip_speed(key, velocity)
        depth = self._strike_depth(key)
        steps = self._ready_steps(speed, depth)
        point = self._strike_point(speed)
        height = (steps + point) * speed * self.dt - depth
        if start > steps:
            return Plan(key, "ready", height=height, start=start, lead=steps)
        # closed loop: after this step the fingertip should be where constant-speed travel passes
        # the strike depth at the strike point of the onset's step, (start - 1 + point) steps on
        tip_height = self._tip_height(q, key)
        goal = tip_height - speed * self.dt if start == 0 else -depth - self._overshoot(speed) + speed * self.dt * (start - 1 + point)
        floor = -depth - self.hold_depth_margin
        return Plan(key, "strike", height=height, goal=float(np.clip(goal, floor, tip_height)), start=start, lead=steps)

    # -- turning plans into joint speeds ------------------------------------------------------
    def _command(self, plans: dict, joints: np.ndarray, wrist: float) -> np.ndarray:
        hand = self.hand
        wrist_target = wrist
        if plans:
            wanted = [self._wrist_for(f, plan.key) for f, plan in plans.items()]
            wrist_target = float(np.clip(np.mean(wanted), 0.0, self.width))
            holds = [self._wrist_for(f, plan.key) for f, plan in plans.items() if plan.phase == "hold"]
            if holds:  # a held key's finger may follow a small move only, and only while all held keys allow it
                low = max(max(holds) - self.hold_reach, wrist - self.hold_slide)
                high = min(min(holds) + self.hold_reach, wrist + self.hold_slide)
                wrist_target = float(np.clip(wrist_target, low, high)) if low <= high else wrist
        if any(self._low(joints[slot]) for slot, f in enumerate(self.fingers) if f not in plans or plans[f].phase == "ready"):
            wrist_target = wrist  # a finger that lets go of a key rises before the hand moves
        step = hand.max_wrist_speed * self.dt
        wrist_step = float(np.clip(wrist_target - wrist, -step, step))
        wrist_next = wrist + wrist_step  # fingers aim from where the wrist will be, so held keys stay held
        action = np.zeros(len(self.fingers) * 4 + 1)
        for slot, finger in enumerate(self.fingers):
            action[slot * 4 : slot * 4 + 4] = self._finger_command(finger, plans.get(finger), joints[slot], wrist_next)
        action[-1] = wrist_step / step
        return action.astype(np.float32)

    def _finger_command(self, finger: int, plan: "Plan | None", q: np.ndarray, wrist_next: float) -> np.ndarray:
        """Joint speeds (actions) that bring the fingertip to this step's waypoint by the end of the step."""
        hand, geometry = self.hand, self.geometry
        phase = plan.phase if plan is not None else "idle"
        key = plan.key if plan is not None else None
        contact_y = self._contact_y(key) if key is not None else self.white_contact_y
        top = float(self.key_top[key]) if key is not None else 0.0
        forward = hand.palm_y - contact_y
        offset = self.key_x[key] - (wrist_next + FINGER_BASE_X[finger]) if key is not None else 0.0
        abduction = float(np.clip(math.atan2(offset, forward), -geometry.abduction_limit, geometry.abduction_limit))
        reach = forward / math.cos(abduction)  # keeps the tip at contact_y even when the key is out of reach
        if phase in ("ready", "strike") and abs(offset - forward * math.tan(abduction)) > self.aim_tolerance:
            phase = "idle"  # not over the key yet: wait high
        now_reach, now_drop = lowest_point_in_finger_plane(geometry, q[1:])
        now_height = hand.palm_height - now_drop
        if phase == "strike" and abs(reach - now_reach) > self.aim_tolerance:
            phase = "ready"  # not in front of the key yet: a strike now would hit its edge
        height = {"idle": top + self.idle_height, "ready": top + (plan.height if plan else 0.0)}.get(phase)
        if height is None:  # strike or hold: the planned height for the end of this step
            height = top + plan.goal
        # waypoints: up first; across before down; into or out of the black keys' band only high up
        rise_here = finger_ik(geometry, now_reach, hand.palm_height - height) is not None
        if height > now_height + self.path_tolerance and rise_here:
            reach = now_reach if abs(reach - now_reach) > self.path_tolerance else reach
            over = self.black_rise if now_reach > hand.palm_y - self.black_band_y else 0.0
            if now_height < over + self.clearance:
                abduction = float(q[0])  # straight up out of the key before swinging sideways
        elif phase != "hold" and abs(reach - now_reach) > self.path_tolerance:
            across = max(height, now_height)  # (a held key stays pressed while the wrist slides)
            if finger_ik(geometry, reach, hand.palm_height - across) is not None:
                height = across  # else the finger, raised high (as a policy may leave it), goes there directly

        band_reach = hand.palm_y - self.black_band_y  # a tip reaching further lies over the black keys
        crossing = (reach > band_reach) != (now_reach > band_reach)
        safe = self.black_rise + self.band_clearance
        if crossing and now_height < safe - self.band_tolerance:
            if reach < now_reach or finger_ik(geometry, now_reach, hand.palm_height - safe) is not None:
                reach, height = now_reach, safe
            else:  # curled too close to the palm to rise here: rise while reaching out towards the black key
                reach, height = now_reach + min(self.max_move, reach - now_reach), safe
        if phase not in ("strike", "hold"):  # positioning moves go in short straight steps, so the tip never dips
            move = np.array([reach - now_reach, height - now_height])
            length = float(np.hypot(*move))
            if length > self.max_move:
                reach, height = now_reach + move[0] * self.max_move / length, now_height + move[1] * self.max_move / length
        flexion = self._ik(reach, hand.palm_height - height, q[1:])
        desired = np.concatenate([[abduction], flexion])
        command = np.clip((desired - q) / (hand.max_joint_speed * self.dt), -1.0, 1.0)
        return command

    def _low(self, q: np.ndarray) -> bool:
        """True when the fingertip is over the keys and lower than their top plus the clearance (it may touch one).

        A fingertip curled back beyond the keys' front, or below them, touches nothing the hand's
        slide could drag: it does not hold the wrist (a policy may leave fingers like that)."""
        reach, drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        over_keys = 0.0 <= self.hand.palm_y - reach * math.cos(q[0]) <= self.white_length
        height = self.hand.palm_height - drop
        return over_keys and -self.white_length * math.tan(self.strike_angle) * 2 < height < self.clearance

    def _tip_height(self, q: np.ndarray, key: int) -> float:
        """Height of the fingertip's lowest point over the key's top surface (m), from the joint angles."""
        _, drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        return self.hand.palm_height - drop - self.key_top[key]
