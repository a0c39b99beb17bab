"""Notes one hand cannot reach, lent to the other hand where it can take them, as pianists do.

A file that names each note's hand (tracks named for hands, a PIG file's channels) may write a
chord wider than the robot's hand spans: a tenth in the left hand, a right-hand chord whose
lowest note lies an octave under its melody. One hand's reduction
(:func:`~pianobot.pianist.reduce.reduce_part`) would drop what does not fit under the hand. A
pianist takes such a note with the other hand where that hand is near and has a finger free.
:func:`lend_notes` does the same, chord by chord (chords as
:func:`~pianobot.pianist.assign.group_chords` groups them):

1. the notes of one hand's chord that do not fit under the hand with its melody note (the right
   hand's top note, the left hand's lowest), tried from that note inwards as the reduction tries
   them, and lying beyond every note the hand keeps (below them for the right hand, above them for
   the left), are the ones that could be lent;
2. each goes to the other hand where, with the notes that hand plays or still holds at that
   onset, it fits under that hand at one position (:func:`~pianobot.pianist.assign.reaches`) and
   the hands do not cross (a note lent to the left hand lies at or above every note the left hand
   sounds then; one lent to the right hand at or below the right hand's);
3. a lent note loses its written finger (it was the other hand's) and the fingering planner
   fingers it for its new hand.

Whether the other hand also gets there in time, and what it then plays of its own, is the
reductions' to say (:func:`~pianobot.pianist.reduce.reduce_part`): each lending, in time order, is
kept only where both hands' reductions then give the hands more notes than without it
(:func:`lend_if_more`), so a file never plays fewer notes for it. Only what sounds at the chord's
onset is checked: a lent note the other hand must let go early for its own next notes is ended
there by its reduction. Only hand models that play as pianists do lend notes
(:attr:`~pianobot.sim.hand.HandModel.lends_notes`): the Allegro-like hand of the paper does not.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.piece import Piece
from pianobot.pianist.assign import group_chords, reaches, reduced_part
from pianobot.sim.hand import hand_model

OTHER = {"right": "left", "left": "right"}


def lendings(piece: Piece, spec: HandSpec) -> list[int]:
    """The indices into ``piece.notes`` (every note with its hand) of the notes the module's rules 1
    and 2 would give to the other hand, in time order, each judged as if those before it were lent."""
    notes = list(piece.notes)
    lent = []
    for group in group_chords(piece):
        onset = min(notes[i].onset for i in group)
        for hand in ("right", "left"):
            mine = sorted((i for i in group if notes[i].hand == hand), key=lambda i: notes[i].pitch)
            if len(mine) < 2 or reaches([notes[i].pitch for i in mine], hand, spec):
                continue
            order = mine[::-1] if hand == "right" else mine  # from the melody's side, as the reduction keeps them
            kept, left_over = [order[0]], []
            for i in order[1:]:
                if reaches([notes[j].pitch for j in kept + [i]], hand, spec):
                    kept.append(i)
                else:
                    left_over.append(i)
            lowest, highest = min(notes[i].pitch for i in kept), max(notes[i].pitch for i in kept)
            other = OTHER[hand]
            theirs = [n.pitch for n in notes if n.hand == other and n.onset <= onset + 1e-9 and n.offset > onset + 1e-9]
            theirs += [notes[i].pitch for i in group if notes[i].hand == other and notes[i].onset > onset + 1e-9]
            for i in left_over:
                pitch = notes[i].pitch
                beyond = pitch < lowest if hand == "right" else pitch > highest  # (else it crosses its own hand's)
                crosses = any(p > pitch for p in theirs) if other == "left" else any(p < pitch for p in theirs)
                if not beyond or crosses or not reaches(theirs + [pitch], other, spec):
                    continue
                notes[i] = replace(notes[i], hand=other)
                theirs.append(pitch)
                lent.append(i)
    return lent


def lend(piece: Piece, indices: list[int]) -> Piece:
    """``piece`` with the notes at ``indices`` given to the other hand, without their written finger."""
    lent = set(indices)
    return Piece(
        tuple(replace(n, hand=OTHER[n.hand], finger=None) if i in lent else n for i, n in enumerate(piece.notes)),
        bpm=piece.bpm,
    )


def lend_notes(piece: Piece, spec: HandSpec) -> tuple[Piece, int]:
    """``piece`` with every note rules 1 and 2 allow given to the other hand (no reduction asked); and how many."""
    indices = lendings(piece, spec)
    return (lend(piece, indices) if indices else piece), len(indices)


def notes_given(piece: Piece, spec: HandSpec) -> int:
    """How many of ``piece``'s notes both hands' reductions give the hands (:func:`~pianobot.pianist.assign.reduced_part`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        return sum(len(reduced_part(piece, hand, spec)[1]) for hand in piece.hands)


def lend_if_more(piece: Piece, spec: HandSpec) -> tuple[Piece, int]:
    """``piece`` with each lending of :func:`lendings` that gives the hands more notes to play (both hands'
    reductions, :func:`notes_given`) than without it, in time order, where ``spec``'s hand model lends
    notes; and how many were lent (0: ``piece`` unchanged)."""
    if not hand_model(spec.model).lends_notes or len(piece.hands) < 2:
        return piece, 0
    candidates = lendings(piece, spec)
    if not candidates:
        return piece, 0
    kept: list[int] = []
    best = notes_given(piece, spec)
    for index in candidates:
        count = notes_given(lend(piece, kept + [index]), spec)
        if count > best:
            kept, best = kept + [index], count
    return (lend(piece, kept) if kept else piece), len(kept)
