"""Strike planning: when each finger strikes which key, from how high and how fast.

Every control step the planner reads each finger's notes from the score window
(:func:`finger_runs`) and gives the finger a :class:`Plan` for this step:

- ``ready``: hover over the next key at the height from which constant-speed travel, started
  :attr:`Plan.lead` steps before the onset, reaches the strike depth on time; or rise to that
  height from a key the finger has let go of but still presses, before it strikes it again
  (:meth:`StrikePlanner._approach`);
- ``strike``: go down at the speed that the keyboard's velocity curve turns into the target
  velocity, so as to pass the strike depth in the onset's step. Every step re-plans from
  where the fingertip actually is (closed loop);
- ``hold``: keep a sounding key down, first going on down at the strike speed, so that a strike
  that lands a little late still sounds at the right velocity.

A held key is held until its written end, and let go sooner only when the hand must get ready for
what comes next (:meth:`StrikePlanner._let_go`): its own finger's next strike (a repeated key: just
long enough for the key to rise), or a strike that needs the wrist where no abduction reaches the
held key from.

The planner knows no joints: it is given each fingertip's height, and
:mod:`~pianobot.pianist.motion` turns its plans into joint speeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np

from pianobot.music.tensor import FINGER, NOTE, VELOCITY
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.tuning import PianistTuning
from pianobot.sim.world import WorldConfig


class Run(NamedTuple):
    """One note of one finger in the score window: consecutive rows with its key on."""

    key: int
    """The key (0 = the keyboard's lowest)."""
    start: int
    """Its first row: control steps from now until its onset (0 = this step)."""
    end: int
    """The row after its last one (control steps from now until it ends)."""
    velocity: float
    """The MIDI velocity it is to sound at."""


def finger_runs(score: np.ndarray, slot: int) -> list[Run]:
    """The notes of the hand's ``slot``-th finger in the score window (T, L, 5), in time order."""
    on = (score[:, :, NOTE] > 0.5) & (score[:, :, FINGER + slot] > 0.5)
    runs = []
    for key in np.flatnonzero(on.any(axis=0)):
        column = np.concatenate([[0], on[:, key].astype(int), [0]])
        starts, ends = np.flatnonzero(np.diff(column) == 1), np.flatnonzero(np.diff(column) == -1)
        for s, e in zip(starts, ends):
            runs.append(Run(int(key), int(s), int(e), float(score[s, key, VELOCITY]) * 127))
    return sorted(runs, key=lambda r: r.start)


class Tip(NamedTuple):
    """Where a fingertip's lowest point is: all the planner knows of the hand."""

    height: float
    """Over the white keys' top surface (m)."""
    y: float
    """Depth into the keyboard: distance from the keys' hinges (m)."""


Phase = Literal["ready", "strike", "hold"]


@dataclass(frozen=True)
class Plan:
    """What one finger does in this control step. Heights are over the key's top surface (m)."""

    key: int
    phase: Phase
    """'ready' (hover at ``height``), 'strike' (down to ``goal``) or 'hold' (keep the key down, going to ``goal``)."""
    height: float = 0.0
    """Ready height: where a strike starts (m)."""
    goal: float = 0.0
    """Fingertip height to reach by the end of this step (m)."""
    start: int = 0
    """Control steps until the note's onset."""
    lead: int = 0
    """Control steps the strike takes from the ready height."""
    next_note: Run | None = None
    """While holding: this finger's next note in the window."""
    next_lead: int = 0
    """While holding: control steps from letting go to the next note's onset step: getting to its
    ready height, then its strike."""


class StrikePlanner:
    """Plans every finger's strikes from the score window; see the module docstring."""

    def __init__(self, world: WorldConfig, layout: KeyLayout, tuning: PianistTuning):
        self.layout = layout
        self.tuning = tuning
        self.fingers = world.hand.spec.fingers
        self.dt = 1.0 / world.control_hz
        self.curve = world.keyboard.curve
        self.max_wrist_speed = world.hand.max_wrist_speed
        self._timings: dict[tuple, tuple[float, int] | int] = {}
        """:meth:`ready`, :meth:`hop_steps` and :meth:`release_steps` by their arguments: each depends on
        them alone, and the fingering planner asks the same ones many thousand times."""

    def plan(
        self,
        score: np.ndarray,
        previous_row: np.ndarray | None,
        tips: dict[int, Tip],
        wrist: float | None = None,
        released: frozenset[tuple[int, int]] = frozenset(),
    ) -> dict[int, Plan]:
        """The plan of every finger that has something to do, by finger.

        ``previous_row`` is the score row of the previous step (None at the first step): it tells a
        note that began earlier, to hold, from one to strike now. ``tips``: where each fingertip is, by
        finger; ``wrist``: where the wrist is (m; None: wherever a strike needs it); ``released``:
        (finger, key) of the notes that began earlier and were let go before their written end
        (:meth:`held` tells them): they are not pressed again, which would sound them twice.
        """
        plans: dict[int, Plan] = {}
        for slot, finger in enumerate(self.fingers):
            plan = self._plan_finger(score, slot, previous_row, tips[finger], released)
            if plan is not None:
                plans[finger] = plan
        self._let_go(plans, tips, wrist)
        return plans

    def held(self, score: np.ndarray, previous_row: np.ndarray | None) -> dict[int, int]:
        """Each finger's note that began earlier and is written to sound now, by finger: its key."""
        if previous_row is None:
            return {}
        now, before = score[0], previous_row  # (only the first row counts: no need to read the window's runs)
        out = {}
        for slot, finger in enumerate(self.fingers):
            keys = np.flatnonzero(
                (now[:, NOTE] > 0.5)
                & (now[:, FINGER + slot] > 0.5)
                & (before[:, NOTE] > 0.5)
                & (before[:, FINGER + slot] > 0.5)
            )
            if keys.size:
                out[finger] = int(keys[-1])
        return out

    # -- speed, depth and timing of one strike -----------------------------------------------------
    def tip_speed(self, key: int, velocity: float) -> float:
        """Downward fingertip speed (m/s) at which a strike on ``key`` sounds at ``velocity``."""
        front_speed = float(self.curve.speed(velocity))  # the keyboard's curve is in front-edge speed
        return min(front_speed * self.layout.contact_y(key) / self.layout.white_length, self.tuning.max_strike_speed)

    def strike_depth(self, key: int) -> float:
        """How far below the key's top surface the fingertip is when the key sounds (m)."""
        return self.layout.contact_y(key) * math.tan(self.layout.strike_angle)

    def overshoot(self, tip_speed: float) -> float:
        """How far (m) past the strike depth the fingertip is planned to be when the key sounds."""
        return min(self.tuning.strike_margin, tip_speed * self.dt / 4)

    def strike_point(self, tip_speed: float) -> float:
        """When in the onset's control step (0 = its start, 1 = its end) the key should sound.

        The environment's steps are centred on the score's rows, so the middle of the step is
        on time. A loud (fast) strike sounds later in the step: the fingertip goes on at the
        strike speed for the rest of the step and must stop short of the key's bottom
        (``hold_depth_margin`` past the strike depth), or the step's speed would drop."""
        room = self.tuning.hold_depth_margin - self.overshoot(tip_speed)  # below the strike depth
        return float(min(max(1.0 - room / (tip_speed * self.dt), 0.5), 1.0))

    def ready_steps(self, tip_speed: float, depth: float, lowest: float | None = None) -> int:
        """Control steps of constant-speed travel from the ready height before the onset's step
        (``lowest``: the lowest ready height over the key's top, m; default ``min_ready_height``)."""
        point = self.strike_point(tip_speed)
        lowest = self.tuning.min_ready_height if lowest is None else lowest
        needed = (lowest + depth) / (tip_speed * self.dt) - point
        return max(self.tuning.min_lead_steps, math.ceil(needed))

    def repeat_height(self, key: int) -> float:
        """The lowest ready height (m over ``key``'s top) of a finger striking again the key it has
        just let go of: ``repeat_rise`` over the depth at which the key let its note go, as a piano
        strikes a key again before it is all the way up; at most ``min_ready_height``."""
        return min(self.tuning.min_ready_height, self.tuning.repeat_rise - self.release_depth(key))

    def release_depth(self, key: int) -> float:
        """How deep (m under its top, where the fingertip strikes it) ``key`` is when, rising, it lets its note go."""
        return self.layout.contact_y(key) * math.tan(self.layout.release_angle)

    def ready(self, run: Run, repeat: bool = False) -> tuple[float, int]:
        """(height, lead) of ``run``'s strike: its ready height over the key's top (m) and the
        control steps of constant-speed travel from there before the onset's step (``repeat``: the
        finger strikes again the key it has just let go of, from :meth:`repeat_height`)."""
        found = self._timings.get(("ready", run.key, run.velocity, repeat))
        if found is None:
            speed, depth = self.tip_speed(run.key, run.velocity), self.strike_depth(run.key)
            steps = self.ready_steps(speed, depth, self.repeat_height(run.key) if repeat else None)
            found = self._timings["ready", run.key, run.velocity, repeat] = (
                (steps + self.strike_point(speed)) * speed * self.dt - depth,
                steps,
            )
        return found

    def positioning_steps(self, tip: Tip, key: int, height: float) -> int:
        """Control steps a fingertip at ``tip`` takes to hover ``height`` over ``key``'s top in front
        of its strike point, along the path :mod:`~pianobot.pianist.motion` takes: up first, across
        (into or out of the black keys' band only above their tops), then down, ``travel_share`` of
        ``max_move`` per step; and ``settle_steps`` more to be still there before the strike starts."""
        layout, tuning = self.layout, self.tuning
        goal_y, goal_height = layout.contact_y(key), layout.key_top[key] + height
        across = abs(goal_y - tip.y)
        if across <= tuning.path_tolerance:
            path = abs(goal_height - tip.height)
        else:
            crossing = (goal_y < layout.black_band_y) != (tip.y < layout.black_band_y)
            top = max(goal_height, tip.height, layout.black_rise + tuning.band_clearance if crossing else 0.0)
            path = (top - tip.height) + across + (top - goal_height)
        return math.ceil(path / (tuning.max_move * tuning.travel_share) - 1e-9) + tuning.settle_steps

    def hop_steps(self, from_key: int, to_key: int, velocity: float) -> int:
        """Fewest control steps from one note's onset to the next note's onset for the same finger:
        ``from_key`` sounds in its onset's step and is let go at the next, the fingertip goes from the
        pressed key to its ready height over ``to_key`` (:meth:`positioning_steps`, at least
        ``prepare_steps``), then strikes at ``velocity``. ``to_key`` may be ``from_key`` (a repeat: with
        ``repeat_rise``, as :meth:`release_steps` times it)."""
        found = self._timings.get(("hop", from_key, to_key, velocity))
        if found is None:
            if self._repeats(from_key, to_key):
                found = 1 + self.release_steps(from_key, to_key, velocity, same_finger=True)
            else:
                found = 1 + self._lift_and_strike(from_key, to_key, velocity, self.tuning.prepare_steps)
            self._timings["hop", from_key, to_key, velocity] = found
        return found

    def release_steps(self, from_key: int, to_key: int, velocity: float, same_finger: bool = False) -> int:
        """Control steps before a strike on ``to_key`` at ``velocity`` that a finger holding ``from_key``
        lets go, as :meth:`plan` does (:meth:`preparing_steps`, then the strike; ``same_finger``: the
        strike is the holding finger's own, which strikes the same key again from :meth:`repeat_height`)."""
        found = self._timings.get(("release", from_key, to_key, velocity, same_finger))
        if found is None:
            height, lead = self.ready(Run(to_key, 0, 1, velocity), repeat=same_finger and from_key == to_key)
            found = self.preparing_steps(self._pressed(from_key), from_key, to_key, height) + lead
            self._timings["release", from_key, to_key, velocity, same_finger] = found
        return found

    def _repeats(self, from_key: int, to_key: int) -> bool:
        """Whether a finger striking ``to_key`` again after ``from_key`` strikes it from :meth:`repeat_height`."""
        return from_key == to_key and self.tuning.repeat_rise < math.inf

    def preparing_steps(self, tip: Tip, from_key: int, to_key: int, height: float) -> int:
        """Control steps a finger holding ``from_key`` with its tip at ``tip`` needs from letting go to
        the start of its strike on ``to_key`` from ``height``: :meth:`positioning_steps`, at least
        ``prepare_steps``; on the same key, straight up and down again in front of it, no settling and
        at least ``repeat_prepare_steps``."""
        tuning = self.tuning
        if to_key == from_key:
            return max(tuning.repeat_prepare_steps, self.positioning_steps(tip, to_key, height) - tuning.settle_steps)
        return max(tuning.prepare_steps, self.positioning_steps(tip, to_key, height))

    def _pressed(self, key: int) -> Tip:
        """Where a fingertip holding ``key`` down is."""
        layout = self.layout
        return Tip(layout.key_top[key] - self.strike_depth(key) - self.tuning.hold_depth_margin, layout.contact_y(key))

    def _lift_and_strike(self, from_key: int, to_key: int, velocity: float, prepare: int) -> int:
        height, lead = self.ready(Run(to_key, 0, 1, velocity))
        return max(prepare, self.positioning_steps(self._pressed(from_key), to_key, height)) + lead

    # -- plans ----------------------------------------------------------------------------------
    def _plan_finger(
        self,
        score: np.ndarray,
        slot: int,
        previous_row: np.ndarray | None,
        tip: Tip,
        released: frozenset[tuple[int, int]] = frozenset(),
    ) -> Plan | None:
        """What one finger should do now, or None when it has nothing to do (``tip``: where its tip is;
        ``released``: as :meth:`plan`'s)."""
        runs = finger_runs(score, slot)
        current = next((r for r in runs if r.start == 0), None)
        upcoming = next((r for r in runs if r.start > 0), None)
        key = current.key if current is not None else -1
        began_earlier = (
            current is not None
            and previous_row is not None
            and (previous_row[key, NOTE] > 0.5 and previous_row[key, FINGER + slot] > 0.5)
        )
        if current is None or (began_earlier and (self.fingers[slot], key) in released):
            if upcoming is None:
                return None
            pressed = key if current is not None else self._pressed_before(previous_row, slot)
            return self._approach(upcoming, tip, pressed)
        if not began_earlier:
            return self._approach(current, tip)  # the onset step itself: strike now
        tip_height = tip.height - self.layout.key_top[key]
        floor = -self.strike_depth(key) - self.tuning.hold_depth_margin
        goal = max(tip_height - self.tip_speed(key, current.velocity) * self.dt, floor)
        seen = score.shape[0] > 2  # (a window of three rows or more shows the note's end and a repeat after it)
        struck_again = seen and score[2, key, NOTE] > 0.5  # after the gap that tells a repeat
        if current.end == 1 and self.tuning.end_rise < math.inf and seen and not struck_again:  # its last step
            goal = max(goal, -self.release_depth(key) - self.tuning.end_rise)
        if upcoming is None:
            return Plan(key, "hold", goal=goal)
        height, lead = self.ready(upcoming, repeat=upcoming.key == key)
        next_lead = lead + self.preparing_steps(tip, key, upcoming.key, height)
        return Plan(key, "hold", goal=goal, next_note=upcoming, next_lead=next_lead)

    @staticmethod
    def _pressed_before(previous_row: np.ndarray | None, slot: int) -> int | None:
        """The key the finger in ``slot`` was written to hold in the previous step's row, if any."""
        if previous_row is None:
            return None
        keys = np.flatnonzero((previous_row[:, NOTE] > 0.5) & (previous_row[:, FINGER + slot] > 0.5))
        return int(keys[-1]) if keys.size else None

    def _approach(self, run: Run, tip: Tip, pressed: int | None = None) -> Plan:
        """The plan for striking ``run``: hover while its onset is far, else strike (``tip``: where the
        fingertip is; ``pressed``: the key the finger held last, which it has let go of).

        A strike only goes down from where the fingertip is. So, with ``rise_before_repeat`` (the
        pianist's hand), a finger that strikes ``pressed`` again while its tip is still under the key's
        top, more than ``path_tolerance`` under its strike's path (it has not risen from the key, which
        must come up to sound again: a repeat sooner than the strike from the ready height takes),
        hovers instead: it rises, and strikes once up, late and louder if it must."""
        tip_height = tip.height - self.layout.key_top[run.key]
        plan = self._strike(run, tip, repeat=run.key == pressed and tip_height < 0)
        rise = self.tuning.rise_before_repeat and run.key == pressed
        if rise and plan.phase == "strike" and run.start > 0 and tip_height < 0:
            if self._path_height(run) > tip_height + self.tuning.path_tolerance:
                return Plan(run.key, "ready", height=plan.height, start=run.start, lead=plan.lead)
        return plan

    def _path_height(self, run: Run) -> float:
        """Where the fingertip should be after this step, over the key's top (m), on the constant-speed
        travel that passes the strike depth at the strike point of ``run``'s onset step, ``run.start``
        (at least 1) steps on."""
        speed = self.tip_speed(run.key, run.velocity)
        depth = self.strike_depth(run.key)
        return -depth - self.overshoot(speed) + speed * self.dt * (run.start - 1 + self.strike_point(speed))

    def _strike(self, run: Run, tip: Tip, repeat: bool = False) -> Plan:
        """Hover over ``run``'s key while its onset is far, else strike it (closed loop: re-planned each
        step from where the fingertip is; ``repeat``: as :meth:`ready`'s)."""
        key, start = run.key, run.start
        speed = self.tip_speed(key, run.velocity)
        depth = self.strike_depth(key)
        height, steps = self.ready(run, repeat)
        point = self.strike_point(speed)
        if start > steps:
            return Plan(key, "ready", height=height, start=start, lead=steps)
        # closed loop: after this step the fingertip should be on its constant-speed path
        tip_height = tip.height - self.layout.key_top[key]
        if start == 0:  # the onset's step: sound on time, faster (louder) only if a late start asks for it
            goal = tip_height - max(speed * self.dt, (tip_height + depth + self.overshoot(speed)) / point)
        else:
            goal = self._path_height(run)
        floor = -depth - self.tuning.hold_depth_margin
        return Plan(
            key, "strike", height=height, goal=float(min(max(goal, floor), tip_height)), start=start, lead=steps
        )

    def strike_reach(self, key: int, finger: int) -> float:
        """Farthest the wrist may be from straight over ``key`` for ``finger`` to strike it (m)."""
        reach = self.tuning.black_strike_reach if self.layout.black[key] else self.tuning.strike_reach
        return reach * self.layout.reach_scale(finger)

    def _let_go(self, plans: dict[int, Plan], tips: dict[int, Tip], wrist: float | None) -> None:
        """Release held keys early when the hand must get ready for what comes next.

        A holding finger lets go in time for its own next strike, or another finger's on its key. Every holding finger lets go in
        time for a strike (its own or another finger's) that no wrist position keeping the held keys
        in reach (``hold_reach``) lets its finger reach (``strike_reach``), or not soon enough at the
        speed the wrist slides while holding (``hold_slide``; a strike alone at its onset may begin
        ``lone_strike_wrist_steps`` before the wrist is there), counting the steps the wrist needs to
        get where the finger is straight over its key.
        """
        tuning, layout = self.tuning, self.layout

        def release(finger: int, rule: str) -> None:
            self.released_for(finger, plans[finger], rule)
            upcoming = plans[finger].next_note
            if upcoming is None:
                del plans[finger]
            else:
                plans[finger] = self._approach(upcoming, tips[finger], plans[finger].key)

        for finger, plan in list(plans.items()):
            if plan.phase == "hold" and plan.next_note is not None and plan.next_note.start - plan.next_lead <= 0:
                release(finger, "own next note")
        for finger, plan in list(plans.items()):  # another finger strikes the held key: it must rise first
            if plan.phase == "strike" or plan.phase == "ready":
                for held, other in list(plans.items()):
                    if other.phase == "hold" and other.key == plan.key and held != finger:
                        if plan.start - plan.lead - tuning.repeat_prepare_steps <= 0:
                            release(held, "same key")
        holds = {f: p for f, p in plans.items() if p.phase == "hold"}
        if not holds:
            return
        low = max(layout.wrist_for(f, p.key) - tuning.hold_reach * layout.reach_scale(f) for f, p in holds.items())
        high = min(layout.wrist_for(f, p.key) + tuning.hold_reach * layout.reach_scale(f) for f, p in holds.items())
        # (finger, key, onset, lead, extra): the wrist slides only once the fingers that let go have risen. A free
        # finger's strike needs prepare_steps on top of its lead (it aims and settles once the wrist is there:
        # tidying that overlap away cost a melody, measured); a holding finger's next_lead already counts its
        # path to the ready height, so its own next strike needs only lift_steps more
        strikes = [(f, p.key, p.start, p.lead, tuning.prepare_steps) for f, p in plans.items() if p.phase != "hold"]
        strikes += [
            (f, p.next_note.key, p.next_note.start, p.next_lead, tuning.lift_steps)
            for f, p in holds.items()
            if p.next_note is not None
        ]
        starts = [start for _, _, start, _, _ in strikes]
        for finger, key, start, lead, extra in strikes:
            wanted = layout.wrist_for(finger, key)
            late = tuning.lone_strike_wrist_steps if starts.count(start) == 1 else 0  # (a chord's wrist must be there)
            if self._strike_while_holding(
                wanted, self.strike_reach(key, finger), low, high, start - lead + late, wrist
            ):
                continue
            travel = max(0.0, low - wanted, wanted - high)
            shift_steps = math.ceil(travel / (self.max_wrist_speed * self.dt))
            if travel > 0 and start - lead - extra - shift_steps <= 0:
                for held in holds:
                    release(held, "wrist move")
                return

    def released_for(self, finger: int, plan: Plan, rule: str) -> None:
        """Called as :meth:`_let_go` lets ``finger`` go of its held key (``plan``, its hold) before the key's
        written end, by ``rule``: 'own next note', 'same key' (another finger strikes it next) or 'wrist
        move'. Does nothing; a diagnostic (benchmarks/early.py) watches it."""

    def _strike_while_holding(
        self, wanted: float, reach: float, low: float, high: float, steps: int, wrist: float | None
    ) -> bool:
        """Whether a finger straight over its key with the wrist at ``wanted`` (m) can strike it from a
        wrist position in the held keys' window [``low``, ``high``] (within ``reach`` of ``wanted``), the
        wrist sliding there at ``hold_slide`` per step within ``steps`` (None ``wrist``: it is there)."""
        near, far = max(low, wanted - reach), min(high, wanted + reach)
        if near > far:
            return False
        if wrist is None:
            return True
        distance = max(0.0, near - wrist, wrist - far)
        return math.ceil(distance / self.tuning.hold_slide - 1e-9) <= steps
