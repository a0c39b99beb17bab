"""What the instrument and the hand can do, as plain data: the keyboard's range and the fingers.

These specs are shared by every layer (score tensor, simulator, metrics), so they live here,
below the simulator, with no physics in them.
"""

from __future__ import annotations

from dataclasses import dataclass

from pianobot.errors import PianobotError, SettingError
from pianobot.music.piece import FINGER_NAMES, Piece, pitch_name

_BLACK = {1, 3, 6, 8, 10}


@dataclass(frozen=True)
class KeyboardSpec:
    """A contiguous range of piano keys."""

    lowest: int = 60
    """MIDI pitch of the lowest key (60 = C4, the paper's keyboard)."""
    count: int = 24
    """Number of keys (24 = two octaves: 14 white + 10 black)."""

    def __post_init__(self) -> None:
        if not 1 <= self.count <= 88:
            raise SettingError(f"keyboard.count {self.count}: a keyboard has 1 to 88 keys", "keyboard.count")
        if not 0 <= self.lowest or self.lowest + self.count - 1 > 127:
            raise SettingError(
                f"a keyboard of {self.count} keys from {pitch_name(self.lowest)} goes past MIDI's "
                "highest pitch G9: lower keyboard.lowest or use fewer keyboard.count",
                "keyboard.lowest",
                "keyboard.count",
            )

    @property
    def highest(self) -> int:
        return self.lowest + self.count - 1

    @property
    def pitches(self) -> range:
        return range(self.lowest, self.lowest + self.count)

    def __contains__(self, pitch: int) -> bool:
        return self.lowest <= pitch <= self.highest

    def index(self, pitch: int) -> int:
        """Key index 0..count-1 of a pitch on this keyboard."""
        if pitch not in self:
            raise PianobotError(f"{pitch_name(pitch)} is not on the keyboard {self.describe()}")
        return pitch - self.lowest

    @staticmethod
    def is_black(pitch: int) -> bool:
        return pitch % 12 in _BLACK

    def describe(self) -> str:
        return f"{pitch_name(self.lowest)}-{pitch_name(self.highest)} ({self.count} key{'s' * (self.count != 1)})"


PIANO = KeyboardSpec(21, 88)
"""The piano's 88 keys, A0 to C8."""


def keyboard_for(piece: Piece, within: KeyboardSpec | None = None) -> KeyboardSpec:
    """The keys ``piece`` needs, rounded out to whole octaves (C to B) within MIDI's range and within
    ``within`` where every note lies on it (the piano's 88 keys, say: a part down to A0 does not
    reach below it); where that would pass 88 keys, just the piece's own range (at most 88 keys,
    from its lowest note)."""
    lowest, highest = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
    low, high = lowest // 12 * 12, min(127, highest // 12 * 12 + 11)
    if within is not None and lowest in within and highest in within:
        low, high = max(low, within.lowest), min(high, within.highest)
    if high - low + 1 > 88:
        return KeyboardSpec(lowest, min(88, highest - lowest + 1))
    return KeyboardSpec(low, high - low + 1)


def keys_for(piece: Piece, default: KeyboardSpec = KeyboardSpec()) -> KeyboardSpec:
    """The keys a one-hand piece is played on where none are named: ``default`` where every note
    lies on it (or where a note lies beyond the piano's 88 keys, for the reading to refuse), else
    the piece's own octaves (:func:`keyboard_for`), at least as many keys as ``default`` (a general
    policy plays any keyboard of at least its own keys), within the piano."""
    pitches = [n.pitch for n in piece.notes]
    if not pitches or all(p in default for p in pitches) or not all(p in PIANO for p in pitches):
        return default
    own = keyboard_for(piece)
    low, high = max(own.lowest, PIANO.lowest), min(own.highest, PIANO.highest)
    if high - low + 1 < default.count:  # (grow up, then down, within the piano)
        high = min(low + default.count - 1, PIANO.highest)
        low = max(high - default.count + 1, PIANO.lowest)
    return KeyboardSpec(low, high - low + 1)


@dataclass(frozen=True)
class HandSpec:
    """Which hand model plays, with which of its fingers, in pianists' numbering (1 thumb ... 5 little).
    The model's body is the simulator's (:func:`pianobot.sim.hand.hand_model`), which checks that
    it has these fingers."""

    fingers: tuple[int, ...] = (2, 3, 4)
    """The Allegro hand's index, middle and ring fingers; add 1 for its thumb."""
    model: str = "allegro"
    """The hand model's name (:data:`pianobot.sim.hand.HAND_MODELS`): 'allegro', the paper's Allegro-like hand."""

    def __post_init__(self) -> None:
        if not self.fingers or len(set(self.fingers)) != len(self.fingers):
            raise PianobotError(f"hand fingers {self.fingers} must be distinct and at least one")
        if any(f not in FINGER_NAMES for f in self.fingers):
            raise PianobotError(f"hand fingers {self.fingers} must be numbers 1-5")
        object.__setattr__(self, "fingers", tuple(sorted(self.fingers)))

    def slot(self, finger: int) -> int:
        """Position of a finger in the one-hot fingering vector."""
        return self.fingers.index(finger)

    def describe(self) -> str:
        fingers = ", ".join(f"{f} ({FINGER_NAMES[f]})" for f in self.fingers)
        return fingers if self.model == "allegro" else f"{fingers} of the {self.model} hand"


THUMB = HandSpec(fingers=(1,) + HandSpec.fingers)
"""The hand with its thumb too (``--thumb``: fingers 1-4)."""


def suggest_transpose(piece: Piece, keyboard: KeyboardSpec) -> int | None:
    """The smallest shift (octaves preferred) that brings every note onto the keyboard, if any."""
    low = min(n.pitch for n in piece.notes)
    high = max(n.pitch for n in piece.notes)
    if high - low >= keyboard.count:
        return None
    fits = [s for s in range(keyboard.lowest - low, keyboard.highest - high + 1)]
    octaves = [s for s in fits if s % 12 == 0]
    return min(octaves or fits, key=abs)


def octave_shifts(piece: Piece) -> list[int]:
    """The shifts by whole octaves (semitones, -120 to 120) that put every note of ``piece`` on the piano's 88 keys."""
    low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
    return [s for s in range(-120, 121, 12) if PIANO.lowest <= low + s and high + s <= PIANO.highest]


def beyond_piano(piece: Piece, transposed: int = 0) -> str:
    """'' where every note of ``piece`` lies on the piano's 88 keys, else which lie beyond and what
    to do: 'N note(s) beyond the piano's 88 keys A0-C8 (88 keys): ...; use load.transpose -12'
    (``transposed``: the semitones the piece was already moved by, which the shift adds to)."""
    outside = [n for n in piece.notes if n.pitch not in PIANO]
    if not outside:
        return ""
    names = ", ".join(n.describe() for n in outside[:3]) + (" ..." if len(outside) > 3 else "")
    shifts = octave_shifts(piece)
    fix = (
        f"use load.transpose {min(shifts, key=abs) + transposed}"
        if shifts
        else "no octave shift brings them all on: move or cut them"
    )
    return f"{len(outside)} note(s) beyond the piano's 88 keys {PIANO.describe()}: {names}; {fix}"


def check_playable(piece: Piece, keyboard: KeyboardSpec, hand: HandSpec, transposed: int = 0) -> None:
    """Raise a one-line :class:`PianobotError` if this hand cannot play ``piece`` on ``keyboard``.

    Checks: at least one note; every note on the keyboard; no more notes sounding at once than
    the hand has fingers; every finger number one the hand has; no finger holding two notes
    at once. ``transposed``: the semitones the piece was already moved by (``load.transpose``),
    which a suggested transposition adds to.
    """
    if not piece.notes:
        raise PianobotError("the piece has no notes: give a MIDI file with at least one note")
    outside = [n for n in piece.notes if n.pitch not in keyboard]
    if outside and (said := beyond_piano(piece, transposed)):  # (no piano's keyboard holds them)
        raise SettingError(f"the piece has {said}", "load.transpose")
    if outside:
        names = ", ".join(n.describe() for n in outside[:4]) + (" ..." if len(outside) > 4 else "")
        shift = suggest_transpose(piece, keyboard)
        low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
        fix = (
            f"use load.transpose {shift + transposed}"
            if shift is not None
            else f"the piece spans {pitch_name(low)}-{pitch_name(high)}, more than the keyboard: if it holds both "
            "hands' parts, play one with load.hand right (or load.hand left)"
        )
        raise SettingError(
            f"{len(outside)} note(s) outside the keyboard {keyboard.describe()}: {names}; "
            f"{fix}, or widen the keyboard with keyboard.lowest / keyboard.count",
            "keyboard.lowest",
            "keyboard.count",
            "load.transpose" if shift is not None else "load.hand",
        )
    polyphony, when = piece.max_polyphony()
    if polyphony > len(hand.fingers):
        sounding = [n.name for n in piece.notes if n.onset <= when < n.offset]
        raise SettingError(
            f"{polyphony} notes sound at once at {when:.3f} s ({', '.join(sounding)}) but the hand has "
            f"{len(hand.fingers)} fingers: drop notes from that chord (e.g. with load.track), let the part be reduced "
            "to what one hand can play (load.hand right or load.hand left)"
            + (", or enable the thumb with hand.fingers" if 1 not in hand.fingers else ""),
            "hand.fingers",
            "load.track",
            "load.hand",
        )
    for note in piece.notes:
        if note.finger is not None and note.finger not in hand.fingers:
            raise PianobotError(
                f"{note.describe()} is fingered {note.finger} ({FINGER_NAMES[note.finger]}) but the hand "
                f"plays with fingers {hand.describe()}: change that note's fingering, or let the fingering planner "
                "finger the piece with load.refinger"
                + (", or enable the thumb with hand.fingers" if note.finger == 1 and hand.model == "allegro" else "")
                + (
                    ", or play it with the pianist's five fingers (hand.model pianist)"
                    if hand.model != "pianist"
                    else ""
                )
            )
    busy: dict[int, float] = {}
    for note in piece.notes:
        if note.finger is None:
            continue
        if busy.get(note.finger, -1.0) > note.onset:
            raise PianobotError(
                f"finger {note.finger} is asked to play {note.describe()} while it still holds an earlier "
                "note: give one of the two notes another finger"
            )
        busy[note.finger] = note.offset
