"""Motion: turning the strike planner's plans into joint speeds, one control step at a time.

- The wrist slides towards where the finger of the next strike is over its key (a chord's: their mean), only a
  little while a finger holds a key, and not at all while a finger that let go of a key is
  still low over the keys (it would drag across them).
- Each finger's abduction aims its tip at its key from where the wrist will be at the end of
  the step, so held keys stay held while the hand moves.
- The fingertip goes to a waypoint by the end of the step: up first, then across, then down,
  in short straight moves, and into or out of the black keys' band only above their tops;
  strikes and holds go straight to the planned height.
- Inverse kinematics (:func:`~pianobot.sim.hand.finger_ik`) turns the waypoint into flexion
  angles, and the action is the joint speed that reaches them within the step (velocity
  control), or those angles themselves (position control).

Heights are in metres over the white keys' top surface (or over a key's top, where it says so).
"""

from __future__ import annotations

import math

import numpy as np

from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.strikes import Plan, Tip
from pianobot.pianist.tuning import PianistTuning
from pianobot.sim.hand import (
    PREFERRED_TILT,
    TILT_RANGE,
    finger_ik,
    joint_limits,
    lowest_point_in_finger_plane,
)
from pianobot.sim.world import WorldConfig


class Motion:
    """Joint speeds for the hand from the fingers' plans; see the module docstring."""

    def __init__(self, world: WorldConfig, layout: KeyLayout, tuning: PianistTuning):
        self.layout = layout
        self.tuning = tuning
        self.hand = world.hand
        self.geometry = world.hand.geometry
        self.fingers = world.hand.spec.fingers
        self.dt = 1.0 / world.control_hz
        self.position = world.control == "position"
        """Actions are joint angle targets (else joint speeds)."""
        limits = joint_limits(world.hand)
        self.limits = {f: limits[:, 4 * slot : 4 * slot + 4] for slot, f in enumerate(self.fingers)}
        """Each finger's (lower, upper) limits of its four joints (rad): a thumb may turn farther."""

    def tip(self, q: np.ndarray) -> Tip:
        """Where the fingertip's lowest point is, from its joint angles (abduction first)."""
        reach, drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        return Tip(height=self.hand.palm_height - drop, y=self.hand.palm_y - reach * math.cos(q[0]))

    def command(self, plans: dict[int, Plan], joints: np.ndarray, wrist: float) -> np.ndarray:
        """The full command in [-1, 1]: every finger's four joint speeds, then the wrist's.

        ``joints`` are the joint angles by finger slot (F, 4); ``wrist`` is its position (m)."""
        step = self.hand.max_wrist_speed * self.dt
        wrist_step = min(max(float(self._wrist_target(plans, joints, wrist) - wrist), -step), step)
        wrist_next = wrist + wrist_step  # fingers aim from where the wrist will be, so held keys stay held
        action = np.zeros(len(self.fingers) * 4 + 1)
        for slot, finger in enumerate(self.fingers):
            action[slot * 4 : slot * 4 + 4] = self._finger_command(finger, plans.get(finger), joints[slot], wrist_next)
        action[-1] = wrist_step / step
        return action.astype(np.float32)

    def _wrist_target(self, plans: dict[int, Plan], joints: np.ndarray, wrist: float) -> float:
        """Where the wrist should go (m): where the planned fingers are over their keys, on average."""
        layout, tuning = self.layout, self.tuning
        target = wrist
        if plans:
            # the next strike decides: the mean over every planned finger let a note far ahead pull
            # the wrist away from one about to be struck, out of its finger's reach
            strikes = [(plan.start, f, plan.key) for f, plan in plans.items() if plan.phase != "hold"]
            if strikes:
                first = min(start for start, _, _ in strikes)
                wanted = [layout.wrist_for(f, key) for start, f, key in strikes if start == first]
            else:
                wanted = [layout.wrist_for(f, plan.key) for f, plan in plans.items()]
            target = min(max(float(np.mean(wanted)), 0.0), layout.width)
            holds = [
                (layout.wrist_for(f, plan.key), tuning.hold_reach * layout.reach_scale(f))
                for f, plan in plans.items()
                if plan.phase == "hold"
            ]
            if holds:  # a held key's finger may follow a small move only, and only while all held keys allow it
                low = max(max(at - reach for at, reach in holds), wrist - tuning.hold_slide)
                high = min(min(at + reach for at, reach in holds), wrist + tuning.hold_slide)
                target = float(min(max(target, low), high)) if low <= high else wrist
        if tuning.strike_slide < math.inf and any(
            f in plans and plans[f].phase == "strike" and self.low(joints[slot]) for slot, f in enumerate(self.fingers)
        ):
            # a fingertip on its way into its key: a quick slide would drag it off (its abduction lags)
            target = min(max(target, wrist - tuning.strike_slide), wrist + tuning.strike_slide)
        if any(
            self.low(joints[slot]) for slot, f in enumerate(self.fingers) if f not in plans or plans[f].phase == "ready"
        ):
            target = wrist  # a finger that lets go of a key rises before the hand moves
        return target

    def _finger_command(self, finger: int, plan: Plan | None, q: np.ndarray, wrist_next: float) -> np.ndarray:
        """Joint speeds (actions) that bring the fingertip to this step's waypoint by the end of the step."""
        now_reach, now_drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        now_height = self.hand.palm_height - now_drop
        phase, abduction, reach, height = self._target(finger, plan, now_reach, wrist_next)
        abduction, reach, height = self._waypoint(phase, abduction, reach, height, q, now_reach, now_height)
        flexion = self._ik(reach, self.hand.palm_height - height, q[1:])
        if phase not in ("strike", "hold"):
            # a change of the finger's shape spreads over several steps: the light links do not
            # follow a large joint-space move within one step (the distal joint overshot to its limit)
            change = float(np.max(np.abs(flexion - q[1:])))
            if change > self.tuning.max_joint_move:
                flexion = q[1:] + (flexion - q[1:]) * self.tuning.max_joint_move / change
        desired = np.concatenate([[abduction], flexion])
        step = self.hand.max_joint_speed * self.dt
        change = np.minimum(np.maximum(desired - q, -step), step)  # the most a joint moves in one control step
        if self.position:  # the angle to be at by the end of the step, -1 and 1 at the joint's limits
            low, high = self.limits[finger]
            return np.minimum(np.maximum((q + change - low) / (high - low) * 2.0 - 1.0, -1.0), 1.0)
        return change / step

    def _target(
        self, finger: int, plan: Plan | None, now_reach: float, wrist_next: float
    ) -> tuple[str, float, float, float]:
        """(phase, abduction, reach, height): where the fingertip goes, and what it does there.

        The abduction aims the fingertip at the key's strike point; the reach (m from the
        finger's base, in its plane) puts it at that depth even where the key is beyond the
        abduction's limit. A finger not yet over its key waits at idle height ('idle'), and one
        over it but not yet in front of it hovers ('ready'): a strike from there would hit the
        key's edge. ``now_reach``: the fingertip's reach now."""
        layout, tuning = self.layout, self.tuning
        phase = plan.phase if plan is not None else "idle"
        key = plan.key if plan is not None else None
        contact_y = layout.contact_y(key) if key is not None else layout.white_contact_y
        top = float(layout.key_top[key]) if key is not None else 0.0
        forward = self.hand.palm_y - contact_y
        offset = layout.key_x[key] - (wrist_next + layout.model.base_x(finger)) if key is not None else 0.0
        limit = layout.model.abduction_limit(finger)
        abduction = min(max(math.atan2(offset, forward), -limit), limit)
        reach = forward / math.cos(abduction)  # keeps the tip at contact_y even when the key is out of reach
        if phase in ("ready", "strike") and abs(offset - forward * math.tan(abduction)) > tuning.aim_tolerance:
            phase = "idle"  # not over the key yet: wait high
        if phase == "strike" and abs(reach - now_reach) > tuning.aim_tolerance:
            phase = "ready"  # not in front of the key yet: a strike now would hit its edge
        if phase == "hold" and abs(reach - now_reach) > tuning.aim_tolerance:
            # the score says the key is held, but the fingertip never got to it (a strike that could
            # not start in time): pressing on from here would sound its neighbours, or the key late
            phase = "idle"
        if phase == "idle":
            height = top + tuning.idle_height
        elif phase == "ready":
            height = top + plan.height
        else:  # strike or hold: the planned height for the end of this step
            height = top + plan.goal
        return phase, abduction, reach, height

    def _waypoint(
        self,
        phase: str,
        abduction: float,
        reach: float,
        height: float,
        q: np.ndarray,
        now_reach: float,
        now_height: float,
    ) -> tuple[float, float, float]:
        """(abduction, reach, height) to be at by the end of this step on the way to the target.

        Up first; across before down; into or out of the black keys' band only high up; and
        positioning moves in short straight steps, so the tip never dips on the way."""
        hand, geometry, layout, tuning = self.hand, self.geometry, self.layout, self.tuning
        rise_here = finger_ik(geometry, now_reach, hand.palm_height - height) is not None
        if height > now_height + tuning.path_tolerance:
            if rise_here:
                reach = now_reach if abs(reach - now_reach) > tuning.path_tolerance else reach
            over = layout.black_rise if now_reach * math.cos(q[0]) > hand.palm_y - layout.black_band_y else 0.0
            if now_height < over + tuning.clearance:
                # straight up out of the key before swinging sideways (also where the finger cannot
                # rise that high at this reach: swinging at the keys' level strikes the neighbour)
                abduction = float(q[0])
        elif phase not in ("strike", "hold") and abs(reach - now_reach) > tuning.path_tolerance:
            # (a strike is in front of its key within aim_tolerance: it corrects the rest on the way down)
            across = max(height, now_height)  # (a held key stays pressed while the wrist slides)
            if finger_ik(geometry, reach, hand.palm_height - across) is not None:
                height = across  # else the finger, raised high (as a policy may leave it), goes there directly

        # a tip reaching further than band_reach lies over the black keys (the reach is in the
        # finger's plane, turned by its abduction: its depth into the keyboard is reach * cos(abduction))
        band_reach = hand.palm_y - layout.black_band_y
        crossing = (reach * math.cos(abduction) > band_reach) != (now_reach * math.cos(q[0]) > band_reach)
        safe = layout.black_rise + tuning.band_clearance
        if crossing and now_height < safe - tuning.band_tolerance:
            if reach < now_reach or finger_ik(geometry, now_reach, hand.palm_height - safe) is not None:
                reach, height = now_reach, safe
            else:  # curled too close to the palm to rise here: rise while reaching out towards the black key
                reach, height = now_reach + min(tuning.max_move, reach - now_reach), safe
        if phase not in ("strike", "hold"):  # positioning moves go in short straight steps, so the tip never dips
            move = np.array([reach - now_reach, height - now_height])
            length = float(np.hypot(*move))
            if length > tuning.max_move:
                reach, height = (
                    now_reach + move[0] * tuning.max_move / length,
                    now_height + move[1] * tuning.max_move / length,
                )
        return abduction, reach, height

    def _ik(self, reach: float, drop: float, current: np.ndarray) -> np.ndarray:
        """Flexion angles for a fingertip target; out of reach, the finger keeps its shape.

        The fingertip's tilt moves towards the preferred one by at most ``tilt_step`` per
        step: letting the IK pick any tilt can flip the finger between very different shapes
        from one step to the next, faster than its joints follow."""
        # a finger curled (or stretched) beyond the IK's tilts, as a policy may leave it, starts
        # from the nearest one: from outside them no point would be in reach and it would stay so
        tilt = float(np.sum(current))
        # (min of max is np.clip on one number, at a twentieth of its cost: this runs for every finger every step)
        tilt += min(max(PREFERRED_TILT - tilt, -self.tuning.tilt_step), self.tuning.tilt_step)
        tilt = min(max(tilt, TILT_RANGE[0]), TILT_RANGE[1])
        for change in (0.0, 0.002, -0.002, 0.004, -0.004, 0.008, 0.012, 0.016, 0.02):
            q = finger_ik(self.geometry, reach, drop + change, tilt)  # the nearest height this finger can reach there
            if q is not None:
                return q
        return current

    def low(self, q: np.ndarray) -> bool:
        """True when the fingertip is over the keys and lower than their top plus the clearance (it may touch one).
        Over the black keys' band their tops count.

        A fingertip curled back beyond the keys' front, or below them, touches nothing the hand's
        slide could drag: it does not hold the wrist (a policy may leave fingers like that)."""
        reach, drop = lowest_point_in_finger_plane(self.geometry, q[1:])
        y = self.hand.palm_y - reach * math.cos(q[0])
        over_keys = 0.0 <= y <= self.layout.white_length
        # over the black keys' band the keys to drag across stand black_rise higher: a fingertip
        # that let go of a black key and hung under their tops struck its neighbour at full speed
        top = self.layout.black_rise if y < self.layout.black_band_y else 0.0
        height = self.hand.palm_height - drop
        return (
            over_keys
            and -self.layout.white_length * math.tan(self.layout.strike_angle) * 2
            < height
            < top + self.tuning.clearance
        )
