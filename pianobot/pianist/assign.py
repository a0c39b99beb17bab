"""Which hand plays each note of a two-hand piece, and each hand's fingering.

A piece whose tracks are named for hands says which hand plays each note
(:func:`pianobot.music.load.load_hands`). Where nothing says, :func:`assign_hands` decides by a
small dynamic programme over the piece's chords (notes started within
:data:`~pianobot.music.load.CHORD_SPREAD` of each other): a *state* is how many of a chord's
notes, from the bottom, the left hand takes (the rest go to the right hand, so within a chord the
hands never cross). The programme finds the states with the lowest total cost:

- **travel**: each hand covers the notes it has played, as far as it reaches from one position
  (:func:`span`, the widest interval the planner lets it hold); a note within that reach costs
  no travel, one beyond it the distance beyond, squared in octaves, times :data:`TRAVEL_COST`
  (one long leap is harder than several steps, so a leap is shared between the hands);
- **switch**: :data:`SWITCH_COST` for a hand that plays a chord after the other played the one
  before alone (a melody stays in one hand unless the other hand is much nearer), and
  :data:`HOLD_COST` for each note a hand holds while it strikes another (a free hand takes a
  moving voice more easily);
- **register**: :data:`HOME_COST` per semitone a note lies on the other hand's side of the
  piece's middle (halfway between the median lowest and the median highest note of its chords
  wider than one hand reaches; no such cost in a piece without them), which settles what travel
  leaves open;
- **crossing**: the left hand's position stays below the right hand's; where a hand's notes
  pass the resting hand, that hand is pushed aside and pays its travel; notes struck across the
  other hand's held notes cost :data:`CROSS_COST` (the held note must be let go);
- **what a hand cannot do**, read from the fingering planner (:class:`~pianobot.pianist.fingering.Planner`,
  the one module that knows the hand's reach; the left hand is the right hand's mirror image,
  asked through :meth:`~pianobot.music.piece.Piece.mirror`): more notes than the hand has
  fingers, or a chord no hand position reaches, costs :data:`FORBIDDEN` (chosen only where no
  split of the chord is playable); notes held under a new chord that leave too few fingers or lie
  out of reach cost :data:`HELD_COST` each (the held note ends early when the hand's part is reduced).

So notes one hand cannot take go to the other: a chord too wide for one hand is split between
them, a melody that moves into the other hand's region passes to it. Notes that already have a
hand keep it. Each hand's part is then reduced to what the hand can play and fingered by the
planner (:func:`finger_hands`; the left hand's part mirrored, planned as a right hand's, and
mirrored back), the two fingerings chosen so that the wrists keep the distance the world keeps
between them where they can (:func:`finger_apart`: two hands a third apart are fingered with
the fingers on their thumbs' side rather than pushed aside as they play).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music import midi_io
from pianobot.music import window as windows
from pianobot.music.instrument import HandSpec, KeyboardSpec, keyboard_for
from pianobot.music.load import CHORD_SPREAD, LEGATO_OVERLAP, LoadOptions, load_hands, thin_hand
from pianobot.music.piece import Note, Piece, mirror_pitch, pitch_name
from pianobot.pianist.fingering import Planner, ensure_fingering
from pianobot.pianist.fingering_plan import FingeringPlan
from pianobot.pianist.reduce import reduce_part
from pianobot.pianist.tuning import tuning_for
from pianobot.sim.hand import hand_config, hand_model, thumb_side_reach
from pianobot.sim.keyboard import KeyboardConfig, key_boxes

TRAVEL_COST = 12.0
"""Cost of a hand moving one octave (squared for longer moves)."""
SWITCH_COST = 1.5
"""Cost of a hand starting to play after the other hand played the chord before alone."""
HOLD_COST = 1.0
"""Cost of each note a hand holds while it strikes another (a free hand takes a moving voice more easily)."""
HOME_COST = 0.5
"""Cost of each semitone a note lies on the other hand's side of the piece's middle."""
CROSS_COST = 100.0
"""Cost of a note struck across a note the other hand still holds."""
HELD_COST = 10.0
"""Cost of each note held under a new chord of the same hand that leaves it too few fingers or is out of reach."""
FORBIDDEN = 1e4
"""Cost of giving a hand more notes than its fingers, or a chord it cannot span."""
_REACH_KEYS = KeyboardSpec(48, 48)
"""The keyboard the reach is asked on (C3-B6): a chord is moved there by whole octaves, which keeps
every key's place relative to the others."""


@dataclass(frozen=True)
class HandAssignment:
    """The piece with every note's hand, and how far it is from what the hands can play."""

    piece: Piece
    cost: float
    unplayable: int
    """Chords no split between the hands makes playable for both (their parts are reduced later)."""


@lru_cache(maxsize=4096)
def _reaches(pitches: tuple[int, ...], spec: HandSpec) -> bool:
    """Whether a right hand ``spec`` names can hold ``pitches`` (sorted) at one hand position."""
    if len(pitches) > len(spec.fingers):
        return False
    shift = _REACH_KEYS.lowest - pitches[0] // 12 * 12
    if pitches[-1] + shift not in _REACH_KEYS:
        return False
    planner = _planner(spec)
    return planner.place([Note(0.0, p + shift, 1.0) for p in pitches]).possible


@lru_cache(maxsize=8)
def _planner(spec: HandSpec) -> Planner:
    return Planner(KeyboardConfig(spec=_REACH_KEYS), hand_config(spec))


def reaches(pitches, hand: str, spec: HandSpec = HandSpec()) -> bool:
    """Whether ``hand`` ('right' or 'left') can hold all of ``pitches`` at once, at one position:
    no more notes than fingers, none beyond the planner's reach. The left hand is asked as the
    right hand's mirror image."""
    if not pitches:
        return True
    keys = [mirror_pitch(p) for p in pitches] if hand == "left" else list(pitches)
    return _reaches(tuple(sorted(keys)), spec)


def group_chords(piece: Piece, spread: float = CHORD_SPREAD) -> list[list[int]]:
    """Indices into ``piece.notes`` grouped as :func:`~pianobot.music.load.gather_chords` groups notes
    (each joins the chord started at most ``spread`` s before it), each chord by pitch."""
    groups: list[list[int]] = []
    notes = piece.notes
    for i, note in enumerate(notes):
        if groups and note.onset - notes[groups[-1][0]].onset <= spread:
            if note.pitch not in {notes[j].pitch for j in groups[-1]}:
                groups[-1].append(i)
                continue
        groups.append([i])
    return [sorted(g, key=lambda j: notes[j].pitch) for g in groups]


@dataclass(frozen=True)
class _State:
    """One way of playing up to a chord: its cost, the state before it, what each hand covers
    (None before it has played) and the notes each hand still holds."""

    cost: float
    back: int
    left: Window | None
    right: Window | None
    held_left: tuple[Note, ...]
    held_right: tuple[Note, ...]
    played: tuple[bool, bool]
    """Whether the left and the right hand played this chord."""


def middle(piece: Piece, groups: list[list[int]], spec: HandSpec = HandSpec()) -> float | None:
    """Halfway between the median lowest and the median highest note of the chords wider than one
    hand reaches (``groups`` as :func:`group_chords` gives them); None where there are none (a piece
    one hand could hold chord by chord has no register for each hand)."""
    wide = [g for g in groups if piece.notes[g[-1]].pitch - piece.notes[g[0]].pitch > span(spec)]
    if not wide:
        return None
    low = float(np.median([piece.notes[g[0]].pitch for g in wide]))
    high = float(np.median([piece.notes[g[-1]].pitch for g in wide]))
    return (low + high) / 2


def _local_cost(chord: list[Note], k: int, spec: HandSpec, middle: float | None) -> float:
    """What the split itself costs: notes fixed to the other hand, more notes than fingers, a
    chord too wide for the hand, notes on the other hand's side of the middle."""
    left, right = chord[:k], chord[k:]
    if any(n.hand == "right" for n in left) or any(n.hand == "left" for n in right):
        return float("inf")
    cost = 0.0
    if middle is not None:
        cost += HOME_COST * (
            sum(max(0.0, n.pitch - middle) for n in left) + sum(max(0.0, middle - n.pitch) for n in right)
        )
    for part, hand in ((left, "left"), (right, "right")):
        if part and not reaches([n.pitch for n in part], hand, spec):
            cost += FORBIDDEN
    return cost


def span(spec: HandSpec) -> int:
    """The widest interval (semitones) the planner lets one hand position hold with ``spec``'s fingers."""
    return _span(spec)


@lru_cache(maxsize=8)
def _span(spec: HandSpec) -> int:
    return max((d for d in range(1, 25) if _reaches((60, 60 + d), spec)), default=0)


Window = tuple[int, int]
"""The lowest and highest note a hand covers from where it is (at most :func:`span` apart)."""


def _move(window: Window | None, low: int, high: int, reach: int) -> tuple[float, Window]:
    """What moving a hand that covers ``window`` to notes ``low``-``high`` costs, and the window after:
    nothing while the notes lie within its reach, else the distance beyond, squared in octaves."""
    if window is None:
        return 0.0, (low, high)
    lo, hi = window
    shift = max(0, high - (lo + reach)) + max(0, (hi - reach) - low)
    new_lo = min(low, max(lo, high - reach))
    return TRAVEL_COST * (shift / 12.0) ** 2, (new_lo, max(high, min(hi, new_lo + reach)))


def _step(state: _State, chord: list[Note], k: int, spec: HandSpec) -> tuple[float, tuple]:
    """The cost of playing ``chord`` split at ``k`` after ``state``, and the new (left, right,
    held left, held right, played) of the state it leads to."""
    onset = chord[0].onset
    left, right = chord[:k], chord[k:]
    held_l = tuple(n for n in state.held_left if n.offset > onset + LEGATO_OVERLAP)
    held_r = tuple(n for n in state.held_right if n.offset > onset + LEGATO_OVERLAP)
    reach = span(spec)
    cost = 0.0
    win_l, win_r = state.left, state.right
    if left:
        travel, win_l = _move(win_l, left[0].pitch, left[-1].pitch, reach)
        cost += travel + (SWITCH_COST if state.played == (False, True) else 0.0) + HOLD_COST * len(held_l)
    if right:
        travel, win_r = _move(win_r, right[0].pitch, right[-1].pitch, reach)
        cost += travel + (SWITCH_COST if state.played == (True, False) else 0.0) + HOLD_COST * len(held_r)
    # the resting hand is pushed aside where the other passes it
    if left and not right and win_r is not None and win_r[0] <= left[-1].pitch:
        travel, win_r = _move(win_r, left[-1].pitch + 1, max(win_r[1], left[-1].pitch + 1), reach)
        cost += travel
    if right and not left and win_l is not None and win_l[1] >= right[0].pitch:
        travel, win_l = _move(win_l, min(win_l[0], right[0].pitch - 1), right[0].pitch - 1, reach)
        cost += travel
    # notes struck across the other hand's held notes
    if left and held_r:
        cost += CROSS_COST * sum(1 for n in left if n.pitch >= min(h.pitch for h in held_r))
    if right and held_l:
        cost += CROSS_COST * sum(1 for n in right if n.pitch <= max(h.pitch for h in held_l))
    # held notes of the same hand: fingers to spare and within reach
    for held, part, hand in ((held_l, left, "left"), (held_r, right, "right")):
        if held and part and not reaches([n.pitch for n in (*held, *part)], hand, spec):
            cost += HELD_COST * len(held)
    return cost, (win_l, win_r, held_l + tuple(left), held_r + tuple(right), (bool(left), bool(right)))


def assign_hands(piece: Piece, spec: HandSpec = HandSpec()) -> HandAssignment:
    """Every note of ``piece`` given to a hand by the dynamic programme in the module's notes;
    notes that have a hand keep it. ``spec`` is each hand's fingers (the left hand mirrors the right)."""
    notes = piece.notes
    groups = group_chords(piece)
    centre = middle(piece, groups, spec)
    layers: list[list[_State | None]] = []
    previous = [_State(0.0, -1, None, None, (), (), (False, False))]
    for group in groups:
        chord = [notes[i] for i in group]
        layer: list[_State | None] = []
        for k in range(len(chord) + 1):
            local = _local_cost(chord, k, spec, centre)
            best = None
            if local != float("inf"):
                for b, state in enumerate(previous):
                    if state is None:
                        continue
                    step, new = _step(state, chord, k, spec)
                    total = state.cost + local + step
                    if best is None or total < best.cost:
                        best = _State(total, b, *new)
            layer.append(best)
        if all(s is None for s in layer):  # notes fixed to hands that cross inside one chord
            raise PianobotError(
                f"the notes at {chord[0].onset:.3f} s have hands that cross (a left-hand note at or above a "
                "right-hand one): the robot's two hands cannot cross"
            )
        layers.append(layer)
        previous = layer
    if not layers:
        return HandAssignment(piece, 0.0, 0)
    k = min((s.cost, k) for k, s in enumerate(layers[-1]) if s is not None)[1]
    hands: list[str | None] = [None] * len(notes)
    unplayable = 0
    for group, layer in zip(reversed(groups), reversed(layers)):
        state = layer[k]
        chord = [notes[i] for i in group]
        unplayable += _local_cost(chord, k, spec, None) >= FORBIDDEN
        for j, i in enumerate(group):
            hands[i] = "left" if j < k else "right"
        k = state.back
    return HandAssignment(piece.with_hands(hands), min(s.cost for s in layers[-1] if s is not None), unplayable)


def thin_for_hands(piece: Piece, spec: HandSpec = HandSpec()) -> tuple[Piece, int]:
    """Chords of more notes than two hands have fingers keep their lowest and highest notes (the
    bass and the melody), as many as each hand has fingers; returns the piece and how many were dropped."""
    fingers = len(spec.fingers)
    drop: set[int] = set()
    for group in group_chords(piece):
        if len(group) > 2 * fingers:
            drop.update(group[fingers:-fingers])
    if not drop:
        return piece, 0
    return Piece(tuple(n for i, n in enumerate(piece.notes) if i not in drop), bpm=piece.bpm), len(drop)


def load_two_hands(
    path: str | Path | midi_io.MidiSource, options: LoadOptions = LoadOptions(), spec: HandSpec = HandSpec()
) -> Piece:
    """A two-hand piece with every note's hand: :func:`~pianobot.music.load.load_hands` (hands
    from track names, bad input refused in one line), chords of more notes than both hands' fingers
    thinned (one warning), the notes without a hand given one by :func:`assign_hands`, and, for a hand
    model that lends notes, those of a chord one hand cannot reach given to the other hand where it
    reaches them (:func:`~pianobot.pianist.lend.lend_if_more`, one warning)."""
    piece, dropped = thin_for_hands(load_hands(path, options), spec)
    if dropped:
        warnings.warn(
            PianobotWarning(
                f"{midi_io.source_path(path).name} has chords of more than {2 * len(spec.fingers)} notes, more than two hands of "
                f"{len(spec.fingers)} fingers hold: kept their lowest and highest {len(spec.fingers)}, "
                f"dropped {dropped} inner note(s)"
            )
        )
    if len(named := {n.hand for n in piece.notes}) == 1 and None not in named:  # the names give one hand every note
        out = next((g for g in group_chords(piece) if not reaches([piece.notes[i].pitch for i in g], *named, spec)), [])
        if out:  # (the names and the fingering written for that one hand are not taken)
            chord, file = " ".join(pitch_name(piece.notes[i].pitch) for i in out), midi_io.source_path(path)
            warnings.warn(
                PianobotWarning(
                    f"{file.name}: its {'channel' if file.suffix.lower() == '.txt' else 'tracks'} name every note for "
                    f"the {min(named)} hand, which cannot reach all of its chords (the first: {chord} at "
                    f"{piece.notes[out[0]].onset:.3f} s): the fingering planner gives every note a hand"
                    + (" and a finger" if any(n.finger is not None for n in piece.notes) else "")
                )
            )
            piece = piece.with_hands(None).without_fingering()
    if any(n.hand is None for n in piece.notes):
        piece = assign_hands(piece, spec).piece
    from pianobot.pianist.lend import lend_if_more  # (lend.py builds on this module)

    piece, lent = lend_if_more(piece, spec)
    if lent:
        warnings.warn(
            PianobotWarning(
                f"{midi_io.source_path(path).name} has chords wider than one hand reaches: gave {lent} of their "
                "notes to the other hand, which reaches them"
            )
        )
    return piece


@dataclass(frozen=True)
class HandsFingering:
    """Both hands' parts, reduced to what each hand can play and fingered, as one piece, and each hand's plan."""

    piece: Piece
    plans: dict[str, FingeringPlan | None]


MIRRORED_WORDS = (
    ("kept their top notes", "kept their lowest notes"),
    ("lower note(s)", "upper note(s)"),
    ("lower notes of chords first", "upper notes of chords first"),
)
"""How :func:`~pianobot.pianist.reduce.reduce_part`'s lines read for a left hand's part, reduced
as its mirror image (where its top notes are the written bass)."""


def reduce_hand(part: Piece, keyboard: KeyboardSpec, spec: HandSpec, hand: str) -> Piece:
    """:func:`~pianobot.pianist.reduce.reduce_part` of ``hand``'s part (the left hand's mirrored),
    its warning lines worded for the written part."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PianobotWarning)
        reduced = reduce_part(part, keyboard, spec, f"the {hand} hand's part").piece
    for warning in caught:
        line = str(warning.message)
        if hand == "left" and issubclass(warning.category, PianobotWarning):
            for mirrored, written in MIRRORED_WORDS:
                line = line.replace(mirrored, written)
        warnings.warn(warning.category(line))
    return reduced


def reduced_part(piece: Piece, hand: str, spec: HandSpec) -> tuple[KeyboardSpec, Piece]:
    """``hand``'s part of ``piece`` as a right hand's (the left hand's mirrored), thinned to the
    fingers and reduced to what the hand can play (one warning per kind of change), on the keys it
    needs; and those keys."""
    part = piece.part(hand)
    part = part.mirror() if hand == "left" else part  # now a right hand's part
    thinned = thin_hand(part, hand, spec, "lowest" if hand == "left" else "highest")
    keyboard = keyboard_for(thinned)
    return keyboard, reduce_hand(thinned.with_hands(None), keyboard, spec, hand)


def finger_hands(piece: Piece, spec: HandSpec = HandSpec(), refinger: bool = False) -> HandsFingering:
    """Each hand's part of ``piece`` (every note has a hand) thinned and reduced to what the hand
    can play (:func:`~pianobot.music.load.thin_hand`, :func:`~pianobot.pianist.reduce.reduce_part`,
    one warning per kind of change and hand) and fingered by the planner, both hands planned so
    that their wrists keep apart where a fingering allows (:func:`finger_apart`; a hand's part that
    keeps the file's fingering, ``refinger`` False, is not fingered again). The left hand's part is
    planned as its mirror image, a right hand's part, and mirrored back."""
    if any(n.hand is None for n in piece.notes):
        raise ValueError("finger_hands needs every note's hand: call assign_hands first")
    notes: list[Note] = []
    plans: dict[str, FingeringPlan | None] = {}
    views: dict[str, tuple[windows.Window, Piece]] = {}
    for hand in piece.hands:
        keyboard, reduced = reduced_part(piece, hand, spec)
        fingered, plan = ensure_fingering(reduced, keyboard, spec, refinger=refinger)
        views[hand] = (windows.Window(hand, keyboard, 0), fingered)
        plans[hand] = plan
    if len(views) == 2 and any(plans.values()):  # fingerings planned here keep the wrists apart
        kept = tuple(hand for hand, plan in plans.items() if plan is None)  # (the file's fingering)
        apart = finger_apart(views, spec, fixed=kept)
        plans = {hand: apart[hand] or plans[hand] for hand in plans}
        views = {hand: (window, apart[hand].piece if apart[hand] else part) for hand, (window, part) in views.items()}
    for hand, (_, fingered) in views.items():
        fingered = fingered.with_hands("right")
        notes.extend((fingered.mirror() if hand == "left" else fingered).notes)
    return HandsFingering(Piece(tuple(notes), bpm=piece.bpm), plans)


IDLE = 0.5
"""A hand whose next chord is this much (s) after its notes end is idle until then: the world may
push it aside, so it leaves the other hand room only until its notes end (and :data:`LINGER` more)."""
LINGER = 0.1
"""How long (s) after its notes end an idle hand still stands where it played."""


def finger_apart(
    parts: dict[str, tuple[windows.Window, Piece]], spec: HandSpec = HandSpec(), fixed: tuple[str, ...] = ()
) -> dict[str, FingeringPlan | None]:
    """Both hands' parts, each in its window's keys (:class:`~pianobot.music.window.Window`:
    the left hand's mirrored) and fingered, fingered again so that the wrists keep the distance
    the world keeps between them (:attr:`~pianobot.sim.world.PianoWorld.min_separation`) where a
    fingering allows: the left hand's part planned to keep clear of the right hand's as it is
    fingered, then the right hand's to keep clear of that, then the left hand's again (the
    planner's ``room``, :meth:`~pianobot.pianist.fingering.Planner.plan`); the hands in ``fixed``
    keep their fingering (their plan: None). A hand stands where its fingers put the scripted
    pianist's wrist (straight over their keys, on average; the pianist may stand elsewhere where
    held keys or the keyboard's end keep it) from its planner's settle time
    (:attr:`~pianobot.pianist.tuning.PianistTuning.settle_time`) before each chord until the next, or, idle (:data:`IDLE`), until :data:`LINGER` after its
    notes end. Where no fingering keeps clear, the least crowding one is taken (the world then
    pushes the hands apart as they play)."""
    if set(parts) != {"right", "left"}:
        raise ValueError(f"finger_apart needs both hands' parts, not {', '.join(parts)}")
    if any(not part.notes or not part.has_fingering for _, part in parts.values()):
        raise ValueError("finger_apart needs both hands' parts with notes, every note fingered")
    gap = 2 * thumb_side_reach(hand_config(spec))
    fingered = {hand: part for hand, (_, part) in parts.items()}
    plans: dict[str, FingeringPlan | None] = dict.fromkeys(parts)
    planners = {
        hand: Planner(KeyboardConfig(spec=window.keyboard), hand_config(spec)) for hand, (window, _) in parts.items()
    }
    for hand, other in (("left", "right"), ("right", "left"), ("left", "right")):
        if hand in fixed:
            continue
        window, part = parts[hand]
        planner = planners[hand]
        others = stands(parts[other][0], fingered[other], spec)
        to_frame = _frame(window, part, planner)
        room = []
        for start, end, _ in stands(window, fingered[hand], spec):
            near = [x for s, e, x in others if s < end and e > start]
            if not near:
                room.append((-np.inf, np.inf))
            elif hand == "left":  # in the world: at most the right wrist's lowest less the gap
                room.append((to_frame(min(near) - gap), np.inf))
            else:
                room.append((to_frame(max(near) + gap), np.inf))
        plans[hand] = planner.plan(part.without_fingering(), room)
        fingered[hand] = plans[hand].piece
    return plans


def _world_x(pitch: int) -> float:
    """Where the key of MIDI ``pitch`` lies along a keyboard of every pitch (m from C-1's octave;
    only differences count): the keys repeat octave by octave, seven white keys each."""
    octave, step = divmod(pitch, 12)
    return float(_OCTAVE_X[step] + octave * 7 * _WHITE_PITCH)


_OCTAVE = KeyboardConfig(spec=KeyboardSpec(0, 12))
_OCTAVE_X = np.array([b.center[0] for b in key_boxes(_OCTAVE)])
_WHITE_PITCH = _OCTAVE.geometry.white_pitch


def _frame(window: windows.Window, part: Piece, planner: Planner):
    """The map from a wrist position in the world (m along the piano) to the same position in the
    frame of ``planner`` (``window``'s keys, mirrored for the left hand), as a function."""
    pitch = part.notes[0].pitch
    view, world = planner.key_x[planner.spec.index(pitch)], _world_x(window.outward(pitch))
    if window.hand == "left":
        return lambda x: view + world - x
    return lambda x: x - world + view


def stands(window: windows.Window, part: Piece, spec: HandSpec = HandSpec()) -> list[tuple[float, float, float]]:
    """Where a hand (``spec``)'s fingered ``part`` (in ``window``'s keys) puts its wrist in the world: for each
    chord (start s, end s, wrist m along the piano), in the module's :func:`finger_apart` terms."""
    chords = part.chords()
    sign = -1.0 if window.hand == "left" else 1.0  # (the left hand's finger bases lie mirrored)
    model = hand_model(spec.model)
    settle = tuning_for(hand_config(spec)).settle_time
    stands = []
    for i, chord in enumerate(chords):
        wrist = float(np.mean([_world_x(window.outward(n.pitch)) - sign * model.base_x(n.finger) for n in chord]))
        ends = max(n.offset for n in chord)
        following = chords[i + 1][0].onset if i + 1 < len(chords) else ends
        end = following if following - ends < IDLE else ends + LINGER
        stands.append((chord[0].onset - settle, max(end, chord[0].onset), wrist))
    return stands
