"""Automatic fingering for the robot hand: dynamic programming over the piece's chords.

The hand slides on a rail along the keyboard; each finger's base sits at a fixed offset from the
wrist (:attr:`pianobot.sim.hand.HandModel.bases`) and reaches sideways by abduction. A *state* is
one way of playing one chord (a melody note is a chord of one): which finger takes each note and
where the wrist stands, on a grid of a quarter of a white key. The planner finds the sequence of
states with the lowest total cost:

- **wrist travel** in white keys, plus a fixed cost for every move (fewer, larger moves are
  easier to play than many small ones);
- **stretch**: each finger's sideways offset from straight over its key, squared, in units of
  its reach (a finger straight over its key strikes most reliably);
- a **hop** cost when one finger plays two different keys in a row;
- a **legato** cost (``PianistTuning.legato_cost``) for every note the scripted pianist would have to let go
  before its written end: its finger plays the next chord too (a hop, or the same key again), another
  finger plays its key next, or the wrist moves to where the key is out of the finger's reach, and
  there is less time between its written end and the next onset than that takes. It grows with the
  share of the note's written length lost, so where the planner has a choice, a note is held to its end.

Hard constraints (what this hand cannot do): a finger reaches at most :data:`REACH_FRACTION` of
what its abduction limit allows; simultaneous notes take distinct fingers in pitch order; a
finger still holding a key is not reused and the wrist keeps that key in its reach; fingertips
never cross each other in the hand's frame between consecutive chords, but where the hand lets
two fingers pass (:attr:`~pianobot.sim.hand.HandModel.passes`: the thumb under, a finger over it),
at a cost; the wrist moves at
most as fast as its motor allows in the time between onsets, less the time a finger needs to
lift and settle; and a finger strikes again no sooner than the scripted pianist can let go,
move over and strike. Where the tempo makes those last two impossible, the planner still
returns its best fingering and says which notes and why (:attr:`FingeringPlan.problems`).

The same dynamic programme answers, chord by chord, what the hand can do: :meth:`Planner.place`
(can one hand position reach this chord?) and :meth:`Planner.follow` (can the hand get from
what it has played to this chord, holding what still sounds, and in time?). Reading one hand's
part of a recording asks them to reduce the part to what the hand can play
(:mod:`pianobot.pianist.reduce`); no other module knows the hand's geometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations
from typing import Sequence

import numpy as np

from pianobot.errors import PianobotError, SettingError
from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable
from pianobot.music.piece import Note, Piece, pitch_name
from pianobot.pianist.fingering_plan import FingeringPlan
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.strikes import Run, StrikePlanner
from pianobot.pianist.tuning import PianistTuning, tuning_for
from pianobot.sim.hand import HandConfig, hand_config, hand_model
from pianobot.sim.keyboard import KeyboardConfig, key_boxes, keyboard_width, strike_points
from pianobot.sim.world import WorldConfig

REACH_FRACTION = PianistTuning.reach_fraction
"""Share of the abduction limit's sideways reach the planner uses (the rest is margin for aim); a hand
model may set its own (``PianistTuning.reach_fraction``)."""
BLACK_REACH = 0.6
"""Share of that reach used on black keys: a slanted fingertip easily slips off their narrow tops."""
GRID = 4
"""Wrist positions per white key."""
MOVE_COST = 1.0
"""Cost of any wrist move, in white keys of travel."""
STRETCH_COST = 0.5
"""Cost of a finger at the edge of its reach (scales with the offset squared)."""
HOP_COST = 0.75
"""Cost of one finger playing two different keys in a row, with time to spare."""
HARD_HOP_COST = 3.0
"""The same when the onsets are less than :data:`HOP_TIME` apart (lift, move over, strike), or
from or to a black key (the fingertip must rise over it and move along the keys too)."""
HOP_TIME = 0.4
PASS_COST = 0.5
"""Cost of one finger passing another (the thumb under, a finger over it) where the hand lets them."""
TIP_GAP = 0.015
"""Least sideways distance (m) between two fingertips, in the hand's frame."""
ROOM_COST = 5.0
"""Cost of each white key the wrist stands outside its room (:meth:`Planner.plan`'s ``room``: where
the other hand leaves this one space)."""
MARK_COST = 50.0
"""Cost of each note given another finger than the file marks it with (:meth:`Planner.plan`): far
above any move, stretch or legato cost, so a mark is kept wherever the hand can play it, and given
up only where it cannot reach or (in a partly fingered part) is too slow."""
_INFEASIBLE = 1e9
_TOO_FAST = 1e3
_SLOW_MARK = MARK_COST / 4
"""A move or hop too fast, where a mark may be kept though only the hand's speed is against it
(``Planner.plan(timing=False)``): less than a mark, so the mark stays, but not free, so the notes
fingered anew are still fingered in time where they can be."""


@dataclass(frozen=True, eq=False)
class Reach:
    """Where the hand can be once it has played ``chord``: for every state (finger assignment x
    wrist position, as :class:`Planner` numbers them) the least cost of getting there, at least
    :data:`_INFEASIBLE` where it cannot. Made by :meth:`Planner.place` and :meth:`Planner.follow`."""

    chord: tuple[Note, ...]
    cost: np.ndarray

    @property
    def possible(self) -> bool:
        """Whether the hand can play the chord at all, after what came before."""
        return bool(self.cost.min() < _INFEASIBLE)


class Planner:
    """Fingering for one hand on one keyboard."""

    def __init__(
        self,
        keyboard: KeyboardConfig = KeyboardConfig(),
        hand: HandConfig = HandConfig(),
        tuning: PianistTuning | None = None,
    ):
        tuning = tuning or tuning_for(hand)
        self.keyboard, self.hand = keyboard, hand
        self.spec = keyboard.spec
        self.fingers = hand.spec.fingers
        self.base_x = {f: hand.model.base_x(f) for f in hand.model.fingers}
        """Each finger's base across the palm (m, from the wrist)."""
        self.key_x = np.array([b.center[0] for b in key_boxes(keyboard)])
        # sideways reach at the white keys' strike points; black keys get no more, since a
        # slanted fingertip easily slips off their narrow tops
        forward = hand.palm_y - strike_points(keyboard)[:, 1].max()
        self.black = np.array([b.black for b in key_boxes(keyboard)])
        share = tuning.reach_fraction * forward * np.where(self.black, BLACK_REACH, 1.0)
        self.reach = {f: share * math.tan(hand.model.abduction_limit(f)) for f in self.fingers}
        """Each finger's sideways reach (m) at each key."""
        self.stretch_cost = {f: STRETCH_COST * (tuning.thumb_stretch if f == 1 else 1.0) for f in self.fingers}
        """What each finger at the edge of its reach costs (the thumb's: ``tuning.thumb_stretch`` of it)."""
        self.passes = {(a, b) for a in self.fingers for b in self.fingers if hand.model.passes_by(a, b)}
        """The pairs of fingers that may cross (both orders)."""
        self.pitch = keyboard.geometry.white_pitch
        self.grid = np.arange(0.0, keyboard_width(keyboard) + 1e-9, self.pitch / GRID)
        self._move = self.grid[None, :] - self.grid[:, None]
        """Wrist displacement between grid positions (rows: from, columns: to)."""
        self._move_cost = np.abs(self._move) / self.pitch + MOVE_COST * (np.abs(self._move) > 1e-9)
        """What moving the wrist costs, before the fingers are considered (read-only: every use copies)."""
        self._distance = np.abs(self._move)
        self._move.flags.writeable = self._move_cost.flags.writeable = self._distance.flags.writeable = False
        self._in_reach: dict[tuple[int, int], np.ndarray] = {}
        self._chord_states: dict[tuple[int, ...], tuple[tuple[tuple[int, ...], ...], tuple[int, ...], np.ndarray]] = {}
        """Each chord's :meth:`_states`, by its keys (read-only)."""
        world = WorldConfig(keyboard=keyboard, hand=hand)
        self.strikes = StrikePlanner(world, KeyLayout(world), tuning)
        """The scripted pianist's strike planning (``tuning``: its constants): how soon a finger can strike
        again, and how soon before the next strike it lets go of a key."""

    # -- one chord ---------------------------------------------------------------------------
    def _states(self, chord: Sequence[Note]) -> tuple[tuple[tuple[int, ...], ...], tuple[int, ...], np.ndarray]:
        """Finger assignments (pitch order = finger order), the chord's keys, and per assignment
        and wrist position the stretch cost (at least :data:`_INFEASIBLE` where a finger cannot
        reach its key)."""
        keys = tuple(self.spec.index(n.pitch) for n in sorted(chord, key=lambda n: n.pitch))
        known = self._chord_states.get(keys)  # (a chord's keys alone decide: asked again and again)
        if known is not None:
            return known
        assignments = tuple(combinations(self.fingers, len(chord)))
        cost = np.zeros((len(assignments), len(self.grid)))
        for a, fingers in enumerate(assignments):
            for key, finger in zip(keys, fingers):
                offset = (self.key_x[key] - self.grid - self.base_x[finger]) / self.reach[finger][key]
                cost[a] += np.where(np.abs(offset) <= 1.0, self.stretch_cost[finger] * offset**2, _INFEASIBLE)
        cost.flags.writeable = False
        self._chord_states[keys] = assignments, keys, cost
        return assignments, keys, cost

    def _transition(
        self,
        prev_keys: Sequence[int],
        keys: Sequence[int],
        fingers_prev: tuple,
        fingers: tuple,
        held: list[bool],
        time: float,
        rows: np.ndarray,
        cols: np.ndarray,
    ) -> np.ndarray:
        """Cost (len(rows) x len(cols)) of going from one state's fingers to the next's, for every pair of
        wrist positions (``rows``: the previous ones, ``cols``: the next ones, as grid indices)."""
        move, cost = self._move[rows][:, cols], self._move_cost[rows][:, cols]
        for key_p, finger_p, is_held in zip(prev_keys, fingers_prev, held):
            if is_held:  # still sounding at the next onset: finger busy, key kept in reach
                if finger_p in fingers:
                    return np.full_like(cost, _INFEASIBLE)
                cost = cost + np.where(self._reaches(key_p, finger_p)[cols], 0.0, _INFEASIBLE)[None, :]
            for key, finger in zip(keys, fingers):
                if finger == finger_p:
                    easy = time >= HOP_TIME and not (self.black[key] or self.black[key_p])
                    cost = cost + (0.0 if key == key_p else HOP_COST if easy else HARD_HOP_COST)
                    continue
                # in the hand's frame the new fingertip lies on its own side of the old one, or
                # passes it (the thumb under, a finger over it) where the hand lets them cross
                relative = (self.key_x[key] - self.key_x[key_p]) - move
                crossing = PASS_COST if (finger, finger_p) in self.passes else _INFEASIBLE
                cost = cost + np.where(np.sign(finger - finger_p) * relative >= TIP_GAP, 0.0, crossing)
        return cost

    # -- from chord to chord: the queries behind plan() -----------------------------------
    def place(self, chord: Sequence[Note]) -> Reach:
        """Every way of playing ``chord`` on its own: ``place(chord).possible`` says whether one
        hand position reaches all its notes (distinct fingers in pitch order)."""
        _, _, cost = self._states(chord)
        return Reach(tuple(chord), cost.ravel())

    def follow(self, before: Reach, chord: Sequence[Note], in_time: bool = False) -> Reach:
        """Every way of playing ``chord`` right after ``before``'s chord, holding those of its notes
        that still sound at ``chord``'s onset. ``possible`` is False when no fingering gets there
        (a held note out of reach, fingertips that would cross); with ``in_time``, also when
        neither the wrist nor a finger can get there in the time between the onsets."""
        return self._follow(before, chord, in_time)[0]

    def _follow(
        self, before: Reach, chord: Sequence[Note], in_time: bool, slow: float = _TOO_FAST
    ) -> tuple[Reach, np.ndarray]:
        """:meth:`follow`, and for each state the state before it on the cheapest way there (``slow``: the
        cost of a move or hop too fast, where not ``in_time``)."""
        prev_chord, chord = before.chord, tuple(chord)
        p_assign, p_keys, _ = self._states(prev_chord)
        assignments, keys, local = self._states(chord)
        onset = chord[0].onset
        held = [n.offset > onset + 1e-6 for n in sorted(prev_chord, key=lambda n: n.pitch)]
        velocities = [n.velocity for n in sorted(chord, key=lambda n: n.pitch)]
        time = onset - prev_chord[0].onset
        slow = _INFEASIBLE if in_time else slow
        too_fast = np.where(self._wrist_too_fast(self._distance, time, chord), slow, 0.0)
        # the slowest strike's lead from its ready height: a note out of reach is let go before it
        lead = max(self.strikes.ready(Run(key, 0, 1, v))[1] for key, v in zip(keys, velocities))
        # Only states that can be reached count: a previous state at _INFEASIBLE or more, or a next one
        # whose fingers cannot reach their keys, is never on a feasible way, so the transitions are worked
        # out between the others alone (the same costs and choices there; the rest stay infeasible).
        width = len(self.grid)
        before_cost = before.cost.reshape(len(p_assign), width)
        rows = [np.flatnonzero(c < _INFEASIBLE) for c in before_cost]
        cost = local + _INFEASIBLE  # (where nothing feasible leads: infeasible, as before)
        best = np.zeros(local.shape, dtype=np.intp)
        for a, f in enumerate(assignments):
            cols = np.flatnonzero(local[a] < _INFEASIBLE)
            if not len(cols):
                continue
            steps, origins = [], []
            for a_p, f_p in enumerate(p_assign):
                if not len(rows[a_p]):
                    continue
                hop = slow if self._fast_hop(p_keys, f_p, keys, f, time, velocities) else 0.0
                legato = self._legato(prev_chord, onset, p_keys, f_p, keys, f, velocities, lead)
                legato = legato[:, cols] if isinstance(legato, np.ndarray) else legato
                block = (
                    self._transition(p_keys, keys, f_p, f, held, time, rows[a_p], cols)
                    + too_fast[rows[a_p]][:, cols]
                    + hop
                    + legato
                )
                steps.append(before_cost[a_p, rows[a_p]][:, None] + block)
                origins.append(a_p * width + rows[a_p])
            if not steps:
                continue
            step, origin = np.concatenate(steps), np.concatenate(origins)
            chosen = np.argmin(step, axis=0)
            cost[a, cols] = step[chosen, np.arange(len(cols))] + local[a, cols]
            best[a, cols] = origin[chosen]
        return Reach(chord, cost.ravel()), best.ravel()

    def _legato(
        self,
        prev_chord: Sequence[Note],
        onset: float,
        prev_keys: Sequence[int],
        fingers_prev: tuple,
        keys: Sequence[int],
        fingers: tuple,
        velocities: Sequence[int],
        lead: int,
    ) -> np.ndarray | float:
        """Cost (W, by the next wrist position, or one number) of the previous chord's notes that the
        scripted pianist must let go before their written end to play the next chord at ``onset`` with
        ``fingers`` (``lead``: the control steps of its slowest strike from the ready height): the share of each note's written length lost, times ``legato_cost``. A note is let
        go :meth:`~pianobot.pianist.strikes.StrikePlanner.release_steps` before a strike of its own
        finger or on its own key, and ``prepare_steps`` and the strike's lead before a strike from a wrist
        position where its key is out of its finger's reach (the hand slides only once it has risen)."""
        strikes, tuning = self.strikes, self.strikes.tuning
        cost: np.ndarray | float = 0.0
        for note, key_p, finger_p in zip(sorted(prev_chord, key=lambda n: n.pitch), prev_keys, fingers_prev):
            slack = onset - note.offset  # time from its written end to the next onset (s)
            if slack < -1e-6:
                continue  # held over the onset: _transition keeps its finger and key
            before = 0.0  # how long before the onset the note must be let go (s)
            for key, finger, velocity in zip(keys, fingers, velocities):
                if finger == finger_p or key == key_p:
                    steps = strikes.release_steps(key_p, key, velocity, same_finger=finger == finger_p)
                    before = max(before, steps * strikes.dt)
            lost = min(max((before - slack) / note.duration, 0.0), 1.0)
            # out of reach from the next wrist position: let go before the slowest strike's lead and the slide
            leap = (tuning.prepare_steps + lead) * strikes.dt
            leap_lost = min(max((leap - slack) / note.duration, 0.0), 1.0)
            lost_by_wrist = np.where(self._reaches(key_p, finger_p), lost, max(lost, leap_lost))
            cost = cost + tuning.legato_cost * lost_by_wrist[None, :]
        return cost

    def _reaches(self, key: int, finger: int) -> np.ndarray:
        """Whether ``finger`` reaches ``key`` from each wrist position of the grid (read-only, cached)."""
        reaches = self._in_reach.get((key, finger))
        if reaches is None:
            reaches = np.abs(self.key_x[key] - self.grid - self.base_x[finger]) / self.reach[finger][key] <= 1.0
            reaches.flags.writeable = False
            self._in_reach[key, finger] = reaches
        return reaches

    def _wrist_too_fast(self, move: np.ndarray | float, time: float, chord: Sequence[Note]) -> np.ndarray:
        """Whether the wrist cannot move ``move`` (m) in the ``time`` s before ``chord``'s onset:
        every move leaves the tuning's ``settle_time`` for the fingers to lift and settle, and a leap (a
        move longer than a finger reaches sideways, so the finger cannot aim at its key before
        the wrist gets there) also leaves the slowest strike of ``chord`` from its ready height:
        the pianist starts that strike only once its finger is over the key."""
        speed = self.hand.max_wrist_speed
        lead = max(self.strikes.ready(Run(self.spec.index(n.pitch), 0, 1, n.velocity))[1] for n in chord)
        settle = self.strikes.tuning.settle_time
        limit = speed * max(0.0, time - settle)
        leap_limit = speed * max(0.0, time - settle - lead * self.strikes.dt)
        move = np.asarray(move)
        farthest = max(r.max() for r in self.reach.values())
        return (move > limit + 1e-9) | ((move > farthest) & (move > leap_limit + 1e-9))

    def _fast_hop(
        self,
        prev_keys: Sequence[int],
        fingers_prev: tuple,
        keys: Sequence[int],
        fingers: tuple,
        time: float,
        velocities: Sequence[int],
    ) -> str:
        """'FINGER from KEY to KEY' where a finger must strike again (another key, or the same one)
        sooner than the scripted pianist can let go, move over, settle and strike at the new note's
        velocity (:meth:`~pianobot.pianist.strikes.StrikePlanner.hop_steps`), else ''."""
        for key_p, finger_p in zip(prev_keys, fingers_prev):
            for key, finger, velocity in zip(keys, fingers, velocities):
                if finger == finger_p and time < self.strikes.hop_steps(key_p, key, velocity) * self.strikes.dt - 1e-9:
                    low = self.spec.lowest
                    return f"finger {finger} must go from {pitch_name(low + key_p)} to {pitch_name(low + key)}"
        return ""

    def _outside(self, chord: Sequence[Note], low: float, high: float) -> np.ndarray:
        """:data:`ROOM_COST` per white key that each state (assignment x wrist position) of
        ``chord`` puts the wrist outside [``low``, ``high``]: the planner's wrist, or the scripted
        pianist's, whichever is farther out."""
        assignments, keys, _ = self._states(chord)
        pianist = np.array([np.mean([self.key_x[k] - self.base_x[f] for k, f in zip(keys, a)]) for a in assignments])
        grid = np.maximum(np.maximum(low - self.grid, self.grid - high), 0.0)
        own = np.maximum(np.maximum(low - pianist, pianist - high), 0.0)
        return ROOM_COST * np.maximum(grid[None, :], own[:, None]) / self.pitch

    def _off_marks(self, chord: Sequence[Note]) -> np.ndarray:
        """:data:`MARK_COST` per note of ``chord`` that each state (assignment x wrist position) fingers
        otherwise than its mark (a note without a finger has no mark)."""
        marks = [n.finger for n in sorted(chord, key=lambda n: n.pitch)]
        assignments, _, _ = self._states(chord)
        off = [sum(m is not None and m != f for m, f in zip(marks, a)) for a in assignments]
        return np.repeat(MARK_COST * np.array(off, float)[:, None], len(self.grid), axis=1)

    # -- the whole piece ---------------------------------------------------------------------
    def plan(
        self, piece: Piece, room: Sequence[tuple[float, float]] | None = None, timing: bool = True
    ) -> FingeringPlan:
        """The lowest-cost fingering of ``piece`` (the module's notes), keeping the fingers its notes
        have where the hand can (:data:`MARK_COST`); without ``timing``, a move or hop too fast costs
        less than a mark (:data:`_SLOW_MARK`), so a mark only the hand's speed is against is kept (and the
        speed is not said in :attr:`FingeringPlan.problems`: its caller keeps a file's fingering as written). ``room``: for each chord
        (as :meth:`~pianobot.music.piece.Piece.chords` gives them) the lowest and highest wrist
        position (m, ``-inf``/``inf`` for none) that keeps this hand clear of the other; a state
        whose wrist, or where its fingers put the scripted pianist's wrist (straight over their
        keys, on average), lies outside costs :data:`ROOM_COST` per white key."""
        chords = piece.chords()
        if room is not None and len(room) != len(chords):
            raise ValueError(f"room has {len(room)} entries for {len(chords)} chords")
        too_many = next((c for c in chords if len(c) > len(self.fingers)), None)
        if too_many is not None:
            said = f"{len(too_many)} notes start together at {too_many[0].onset:.3f} s ({', '.join(n.name for n in too_many)})"
            message = (
                f"{said} but the hand has {len(self.fingers)} fingers: drop notes from that chord (e.g. with load.track), "
                "let the part be reduced to what one hand can play (load.hand right or load.hand left)"
            ) + (", or enable the thumb with hand.fingers" if 1 not in self.fingers else "")
            raise SettingError(message, "hand.fingers", "load.track", "load.hand")
        reaches, back = [], [None]
        for i, chord in enumerate(chords):
            if not self.place(chord).possible:
                keys = [self.spec.index(n.pitch) for n in chord]
                span = abs(self.key_x[keys[-1]] - self.key_x[keys[0]]) * 100
                raise SettingError(
                    f"the chord {' '.join(n.name for n in chord)} at {chord[0].onset:.3f} s spans {span:.1f} cm, "
                    "more than this hand reaches: drop a note from it, transpose part of it, or let the part be "
                    "reduced to what one hand can play (load.hand right or load.hand left)",
                    "load.hand",
                )
            if i == 0:
                reach = self.place(chord)
            else:
                reach, best = self._follow(reaches[-1], chord, in_time=False, slow=_TOO_FAST if timing else _SLOW_MARK)
                back.append(best)
            if room is not None:
                reach = Reach(reach.chord, reach.cost + self._outside(chord, *room[i]).ravel())
            if any(n.finger is not None for n in chord):
                reach = Reach(reach.chord, reach.cost + self._off_marks(chord).ravel())
            reaches.append(reach)

        index = int(np.argmin(reaches[-1].cost))
        if not reaches[-1].possible:
            i = next(i for i, reach in enumerate(reaches) if not reach.possible)
            raise SettingError(
                f"no fingering lets this hand go from {' '.join(n.name for n in chords[i - 1])} to "
                f"{' '.join(n.name for n in chords[i])} at {chords[i][0].onset:.3f} s: the notes held there cross or lie "
                "too far apart for its fingers; play one voice (load.track), let the part be reduced to what one hand "
                "can play (load.hand right or load.hand left), or shorten the held notes",
                "load.track",
                "load.hand",
            )
        path = [index]
        for i in range(len(chords) - 1, 0, -1):
            path.append(int(back[i][path[-1]]))
        path.reverse()

        fingers: list[int] = []  # piece.chords() groups piece.notes in order, each chord by pitch
        wrist, chosen = [], []
        for chord, state in zip(chords, path):
            a, w = divmod(state, len(self.grid))
            assignments, keys, _ = self._states(chord)
            wrist.append(float(self.grid[w]))
            chosen.append((keys, assignments[a]))
            fingers.extend(assignments[a])
        problems = []
        for i in range(1, len(chords)):
            time = chords[i][0].onset - chords[i - 1][0].onset
            distance = abs(wrist[i] - wrist[i - 1])
            velocities = [n.velocity for n in sorted(chords[i], key=lambda n: n.pitch)]
            hop = self._fast_hop(*chosen[i - 1], *chosen[i], time, velocities)
            if timing and (self._wrist_too_fast(distance, time, chords[i]) or hop):
                what = (
                    f"{hop} in {time:.3f} s" if hop else f"the wrist must move {distance * 100:.1f} cm in {time:.3f} s"
                )
                problems.append(
                    f"{' '.join(n.name for n in chords[i - 1])} at {chords[i - 1][0].onset:.3f} s -> "
                    f"{' '.join(n.name for n in chords[i])} at {chords[i][0].onset:.3f} s: {what}, "
                    "faster than this hand can (slow down with load.tempo)"
                )
        moves = np.abs(np.diff(wrist)) > 1e-9
        fingered = piece.with_fingers(fingers)
        return FingeringPlan(
            fingered, tuple(wrist), float(np.abs(np.diff(wrist)).sum()), int(moves.sum()), tuple(problems)
        )


def ensure_fingering(
    piece: Piece, keyboard: KeyboardSpec, hand: HandSpec, refinger: bool = False
) -> tuple[Piece, FingeringPlan | None]:
    """``piece`` as it is when every note has a finger (and not ``refinger``; for a hand model that
    plays written fingering, where the hand can play every mark), else fingered by the planner; the
    plan is returned too, or None when the piece kept its fingering. A hand
    model that plays written fingering (:attr:`~pianobot.sim.hand.HandModel.written_fingering`)
    keeps a piece's marks where it can, a fully fingered piece's too: where the hand cannot play
    one (a stretch beyond its reach, fingers that would cross), the planner fingers the piece,
    keeping every other mark it can, and a mark only the hand's speed is against (the scripted
    pianist strikes late if it must); where the planner finds no fingering at all, the piece is kept
    as written. Another hand model keeps a fully fingered piece as it is and fingers any other anew;
    with ``refinger``, every piece is fingered anew."""
    marked = not refinger and hand_model(hand.model).written_fingering
    if piece.has_fingering and not refinger and not marked:
        return piece, None
    check_playable(piece.without_fingering(), keyboard, hand)  # on the keyboard, not too many notes at once
    full = marked and piece.has_fingering
    try:
        plan = _plan(piece if marked else piece.without_fingering(), piece.bpm, keyboard, hand, not full)
    except PianobotError:
        if full:
            return piece, None  # (the planner finds no fingering: played as written, as before)
        raise
    if full and [n.finger for n in plan.piece.notes] == [n.finger for n in piece.notes]:
        return piece, None  # (every mark playable: kept as written)
    return plan.piece, plan


@lru_cache(maxsize=2)
def _plan(piece: Piece, bpm: float, keyboard: KeyboardSpec, hand: HandSpec, timing: bool = True) -> FingeringPlan:
    """:func:`plan_fingering`, kept for the last pieces asked (``bpm`` is in the key because a
    piece's equality leaves it out): ``pianobot play`` asks whether one hand plays a file, then
    plays it, and music objects are immutable, so the plan is the same both times."""
    return plan_fingering(piece, KeyboardConfig(spec=keyboard), hand_config(hand), timing)


def plan_fingering(
    piece: Piece, keyboard: KeyboardConfig = KeyboardConfig(), hand: HandConfig = HandConfig(), timing: bool = True
) -> FingeringPlan:
    """The lowest-cost fingering of ``piece`` for ``hand`` on ``keyboard`` (see the module's notes;
    ``timing``: as :meth:`Planner.plan`'s)."""
    return Planner(keyboard, hand).plan(piece, timing=timing)
