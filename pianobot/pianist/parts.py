"""Each hand's part of a two-hand piece as its simulated hand is given it: moved onto the keys its
player knows, thinned and reduced to what the hand can play, and fingered (:func:`prepare_part`);
how many notes that leaves (:func:`given_notes`), and so which finger set leaves most (:func:`keeps_more`,
by which the reading chooses fingers); and why one hand cannot play a piece (:func:`one_hand_refusal`),
by which the reading gives it to both."""

from __future__ import annotations

import warnings
from dataclasses import replace

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.instrument import THUMB, HandSpec, KeyboardSpec, check_playable, suggest_transpose
from pianobot.music.load import thin_hand
from pianobot.music.piece import Piece
from pianobot.music.window import Window, window_for
from pianobot.pianist.assign import reduce_hand
from pianobot.pianist.fingering import ensure_fingering
from pianobot.sim.hand import hand_model


def prepare_part(
    piece: Piece,
    hand: str,
    keyboard: KeyboardSpec | None,
    fingers: HandSpec,
    start: float | None = None,
    grow: bool = False,
) -> tuple[Window, Piece, float, int]:
    """``hand``'s part of ``piece`` as the simulated hand is given it: (window, part, start, notes
    left out), the part moved ``start`` seconds earlier (default: to its first note); ``grow``: a
    part wider than ``keyboard`` is given its own range instead (:func:`~pianobot.music.window.window_for`).
    Each kind of change is one :class:`PianobotWarning`, worded for the written part (the file's
    fingering marks the hand cannot play all of too: :func:`ensure_fingering`)."""
    window, reduced, start, left_out = _reduced_part(piece, hand, keyboard, fingers, start, grow)
    written = hand_model(fingers.model).written_fingering  # (the file's marks kept where the hand can)
    fingered, _ = ensure_fingering(reduced, window.keyboard, fingers, refinger=not written)
    marks = [(a.finger, b.finger) for a, b in zip(reduced.notes, fingered.notes) if a.finger is not None]
    if written and any(a != b for a, b in marks):  # (the file's marks the hand cannot play all of)
        warnings.warn(
            PianobotWarning(
                f"the {hand} hand's part: this hand cannot play all of its fingering; "
                f"kept {sum(a == b for a, b in marks)} of its {len(marks)} fingering marks"
            )
        )
    return window, fingered, start, left_out


def _reduced_part(
    piece: Piece, hand: str, keyboard: KeyboardSpec | None, fingers: HandSpec, start: float | None, grow: bool
) -> tuple[Window, Piece, float, int]:
    """:func:`prepare_part`'s part before it is fingered."""
    part = piece.part(hand)
    window = window_for(part, hand, keyboard, grow)
    inside = [n for n in part.notes if window.inward(n.pitch) in window.keyboard]
    left_out = len(part) - len(inside)
    if left_out:
        warnings.warn(
            PianobotWarning(
                f"the {hand} hand's part spans more than the {window.keyboard.count} keys its player knows: "
                f"left out {left_out} note(s) outside them"
            )
        )
    if not inside:
        raise PianobotError(f"none of the {hand} hand's notes fits the keyboard its player knows")
    marks = hand_model(fingers.model).written_fingering and all(n.finger in (None, *fingers.fingers) for n in inside)
    moved = Piece(tuple(replace(n, pitch=window.inward(n.pitch), hand=None) for n in inside), bpm=piece.bpm)
    moved = moved if marks else moved.without_fingering()
    start = moved.notes[0].onset if start is None else start
    # (the simulated hand is a right hand: its top notes are a left hand's lowest)
    thinned = thin_hand(moved.shift(-start), hand, fingers, "lowest" if hand == "left" else "highest")
    return window, reduce_hand(thinned, window.keyboard, fingers, hand), start, left_out


def given_notes(piece: Piece, fingers: HandSpec, keyboard: KeyboardSpec | None = None) -> int | None:
    """How many of ``piece``'s notes both hands are given with ``fingers`` (:func:`prepare_part`), on
    ``keyboard`` (default: 24 keys or a wider part's own octaves); None where a part is refused."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        try:
            return sum(
                len(_reduced_part(piece, h, keyboard or KeyboardSpec(), fingers, None, keyboard is None)[1])
                for h in piece.hands
            )
        except PianobotError:
            return None


def keeps_more(
    readings: list[tuple[HandSpec, Piece]], keyboard: KeyboardSpec | None = None
) -> tuple[int, tuple[int, int] | None]:
    """Which of ``readings`` (a hand model's finger sets, each with the piece as read for it, in its order of
    preference) both hands play with where none are named: the first, unless a later one gives more notes
    (:func:`given_notes`), then the one giving most: (its index, (notes given with the first, with it)), else (0, None)."""
    (_, first), *others = readings
    given = given_notes(first, readings[0][0], keyboard)
    if given is None:
        return 0, None
    best, most = 0, given
    for index, (fingers, piece) in enumerate(others, start=1):
        if most >= len(piece):  # (a later set's reading may keep notes of a chord the first thins)
            continue
        more = given_notes(piece, fingers, keyboard)
        if more is not None and more > most:
            best, most = index, more
    return (best, (given, most)) if best else (0, None)


def thumbs_keep_more(
    three: Piece, thumbs: Piece | None = None, keyboard: KeyboardSpec | None = None
) -> tuple[int, int] | None:
    """(notes both hands are given with three fingers, with thumbs) where the thumbs keep more, else None:
    :func:`keeps_more` of the Allegro-like hand's sets, ``three``/``thumbs`` (default: the same) as read for each."""
    return keeps_more([(HandSpec(), three), (THUMB, three if thumbs is None else thumbs)], keyboard)[1]


def one_hands_fingering(piece: Piece) -> bool:
    """Whether ``piece`` has fingering and it could be one hand's: no note has a hand, and the notes
    struck together have distinct fingers."""
    if any(n.hand is not None for n in piece.notes) or all(n.finger is None for n in piece.notes):
        return False
    marked = [[n.finger for n in chord if n.finger is not None] for chord in piece.chords()]
    return all(len(fingers) == len(set(fingers)) for fingers in marked)


def one_hand_refusal(piece: Piece, spec: HandSpec, keyboard: KeyboardSpec, refinger: bool = False) -> str:
    """Why one hand with ``spec``'s fingers cannot play ``piece`` (unfingered, spanning fewer keys
    than ``keyboard`` has), in words; '' where it can. It is asked on ``keyboard`` moved by the
    transposition one hand's reading would suggest (:func:`~pianobot.music.instrument.suggest_transpose`):
    notes a transposition brings onto the keys are no reason for two hands. A single line of notes is
    always one hand's (the fingering planner only slows what is fast); chords and held notes are
    asked of the planner."""
    shift = suggest_transpose(piece, keyboard) or 0  # (0 where the notes fit: the plan is then reused)
    under = KeyboardSpec(max(0, min(keyboard.lowest - shift, 128 - keyboard.count)), keyboard.count)
    try:
        check_playable(piece, under, spec)  # (more notes at once than fingers)
        if piece.max_polyphony()[0] > 1:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # (one hand's reading says them, where one hand plays)
                ensure_fingering(piece, under, spec, refinger)
    except PianobotError as refused:
        return str(refused).split(": ")[0]
    return ""
