"""Random single-voice melodies in all 12 keys (issue 19): the generator, and the scripted pianist on them.

Targets: every melody note F1 >= 0.95, velocity MAE <= 5 and no extra notes; mean F1 >= 0.98.
The full set (4 per key) is ``python benchmarks/melodies.py``; this plays 2 per key.
"""

import numpy as np
import pytest

from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.melodies import MelodyKey, melody_set, random_melody
from pianobot.perform.perform import perform
from pianobot.pianist.fingering import ensure_fingering


def _playable(piece):
    """Fingered by the planner; None (draw again) where it says the hand cannot play it at this tempo."""
    fingered, plan = ensure_fingering(piece, KeyboardSpec(), HandSpec())
    return None if plan is not None and plan.problems else fingered


def test_a_melody_is_a_seeded_single_voice_in_its_key():
    keyboard = KeyboardSpec()
    for tonic in range(12):
        key = MelodyKey(tonic, minor=tonic % 2 == 1)
        piece = random_melody(np.random.default_rng(tonic), keyboard, key)
        assert piece == random_melody(np.random.default_rng(tonic), keyboard, key)  # a seed fixes it
        assert 8 <= len(piece) <= 16 and 60 <= piece.bpm <= 144
        assert all(n.pitch in keyboard and 20 <= n.velocity <= 127 and n.finger is None for n in piece.notes)
        assert piece.max_polyphony()[0] == 1  # one voice
        allowed = set(key.pitches(keyboard)) | set(key.pitches(keyboard, raised_seventh=True))
        assert {n.pitch for n in piece.notes} <= allowed


def test_the_set_has_black_keys_leaps_repeats_and_rests():
    melodies = melody_set(2, _playable)
    assert len(melodies) == 24 and {m.key.tonic for m in melodies} == set(range(12))
    notes = [n for m in melodies for n in m.piece.notes]
    assert sum(KeyboardSpec.is_black(n.pitch) for n in notes) > len(notes) / 5
    steps = [
        (b.pitch - a.pitch, b.onset - a.offset) for m in melodies for a, b in zip(m.piece.notes, m.piece.notes[1:])
    ]
    assert any(abs(d) >= 5 for d, _ in steps) and any(d == 0 for d, _ in steps)  # leaps, repeated notes
    assert any(gap >= 60 / 144 * 0.5 for _, gap in steps)  # rests
    assert min(n.velocity for n in notes) <= 30 and max(n.velocity for n in notes) >= 120
    hops = [
        (a.pitch, b.pitch)
        for m in melodies
        for a, b in zip(m.piece.notes, m.piece.notes[1:])
        if a.finger == b.finger and a.pitch != b.pitch
    ]
    assert any(KeyboardSpec.is_black(a) != KeyboardSpec.is_black(b) for a, b in hops)  # hops onto and off black keys


@pytest.mark.slow
def test_the_scripted_pianist_plays_a_random_melody_in_every_key():
    results = []
    for melody in melody_set(2, _playable):
        report = perform(melody.piece, "scripted", seed=melody.index).report()
        extra = sum(r.reference is None for r in report.rows)
        results.append((melody.key.name, melody.seed, report.f1, report.velocity_mae, extra))
    failing = [r for r in results if r[2] < 0.95 or (r[3] or 0) > 5 or r[4] > 0]
    assert not failing, failing
    assert np.mean([r[2] for r in results]) >= 0.98


def test_the_benchmark_says_what_came_after_each_note_let_go_early():
    """benchmarks.melodies counts each note let go too early for note F1 with offsets by what comes
    at the next onset: its key again (in a chord too), a move of the hand (the planner's wrist),
    neither, or nothing (the last note)."""
    from benchmarks.melodies import early_causes
    from pianobot.music.metrics import NoteRow
    from pianobot.music.piece import Note, Piece

    written = Piece(
        (
            Note(0.0, 62, 0.5, 80, finger=3),  # D4, then a chord with D4 in it (not its lowest): the key must rise
            Note(0.5, 60, 1.0, 80, finger=2),
            Note(0.5, 62, 1.0, 80, finger=3),
            Note(1.0, 62, 1.5, 80, finger=3),  # D4, then E4 a step up: the hand stays
            Note(1.5, 64, 2.0, 80, finger=4),  # E4, then A5: far out of reach, the hand moves
            Note(2.0, 81, 2.5, 80, finger=3),  # the last note: nothing follows
        ),
        bpm=120,
    )

    def early(n: Note) -> Note:
        return Note(n.onset, n.pitch, n.offset - 0.2, n.velocity, n.finger)

    notes = written.notes
    rows = (
        NoteRow(notes[0], early(notes[0])),
        NoteRow(notes[1], Note(0.5, 60, 0.97, 80, finger=2)),  # within 50 ms of its end: not early
        NoteRow(notes[2], None),  # missed: not counted
        NoteRow(notes[3], early(notes[3])),
        NoteRow(notes[4], early(notes[4])),
        NoteRow(notes[5], early(notes[5])),
        NoteRow(None, early(notes[1])),  # an extra note counts for nothing here
    )
    counts = early_causes(written, rows, HandSpec())
    assert counts == {"repeated key": 1, "hand move": 1, "other": 1, "last note": 1}
