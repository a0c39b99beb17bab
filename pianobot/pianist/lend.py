"""Notes one hand cannot reach, lent to the other hand where it can take them, as pianists do.

A file that names each note's hand (tracks named for hands, a PIG file's channels) may write a
chord wider than the robot's hand spans: a tenth in the left hand, a right-hand chord whose
lowest note lies an octave under its melody. One hand's reduction
(:func:`~pianobot.pianist.reduce.reduce_part`) would drop what does not fit under the hand. A
pianist takes such a note with the other hand where that hand is near and has a finger free.
:func:`lend_notes` does the same, chord by chord (chords as
:func:`~pianobot.pianist.assign.group_chords` groups them):

1. the notes of one hand's chord that do not fit under the hand with its top note (the right
   hand's; the left hand's lowest), tried from the top down as the reduction tries them, are the
   ones that could be lent;
2. each goes to the other hand where, with the notes that hand plays or still holds at that
   onset, it fits under that hand at one position (:func:`~pianobot.pianist.assign.reaches`) and
   the hands do not cross (a note lent to the left hand lies at or above every note the left hand
   sounds then; one lent to the right hand at or below the right hand's);
3. a lent note loses its written finger (it was the other hand's) and the fingering planner
   fingers it for its new hand.

Whether the other hand also gets there in time is the reduction's to say: it drops a lent note
it cannot reach in time before any of that hand's own. The lending is kept only where both hands'
reductions then give the hands more notes than without it (:func:`lend_if_more`), so a file never
plays fewer notes for it. Only hand models that play as pianists do lend notes
(:attr:`~pianobot.sim.hand.HandModel.lends_notes`): the Allegro-like hand of the paper does not.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec, keyboard_for
from pianobot.music.load import thin_hand
from pianobot.music.piece import Piece
from pianobot.pianist.assign import group_chords, reaches, reduce_hand
from pianobot.sim.hand import hand_model

OTHER = {"right": "left", "left": "right"}


def lend_notes(piece: Piece, spec: HandSpec) -> tuple[Piece, int]:
    """``piece`` (every note with its hand) with the notes one hand cannot reach in a chord given to
    the other hand where it can take them (the module's rules); and how many were lent."""
    notes = list(piece.notes)
    lent = 0
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
            other = OTHER[hand]
            theirs = [n.pitch for n in notes if n.hand == other and n.onset <= onset + 1e-9 and n.offset > onset + 1e-9]
            theirs += [notes[i].pitch for i in group if notes[i].hand == other and notes[i].onset > onset + 1e-9]
            for i in left_over:
                pitch = notes[i].pitch
                crosses = any(p > pitch for p in theirs) if other == "left" else any(p < pitch for p in theirs)
                if crosses or not reaches(theirs + [pitch], other, spec):
                    continue
                notes[i] = replace(notes[i], hand=other, finger=None)
                theirs.append(pitch)
                lent += 1
    return (Piece(tuple(notes), bpm=piece.bpm) if lent else piece), lent


def given(piece: Piece, spec: HandSpec) -> int:
    """How many of ``piece``'s notes both hands' reductions give the hands (as each hand's part is reduced to play)."""
    total = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        for hand in piece.hands:
            part = piece.part(hand)
            part = part.mirror() if hand == "left" else part
            thinned = thin_hand(part, hand, spec, "lowest" if hand == "left" else "highest")
            total += len(reduce_hand(thinned.with_hands(None), keyboard_for(thinned), spec, hand))
    return total


def lend_if_more(piece: Piece, spec: HandSpec) -> tuple[Piece, int]:
    """:func:`lend_notes` where ``spec``'s hand model lends notes and the hands are then given more of
    them to play than without; else ``piece`` unchanged (and 0)."""
    if not hand_model(spec.model).lends_notes or len(piece.hands) < 2:
        return piece, 0
    lent_piece, lent = lend_notes(piece, spec)
    if not lent or given(lent_piece, spec) <= given(piece, spec):
        return piece, 0
    return lent_piece, lent
