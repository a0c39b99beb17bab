"""Issue 38: the scripted pianist holds each note as long as it is written.

A set of random melodies drawn in code (eighths, dotted rhythms, triplets, repeated notes, leaps
beyond the hand's reach, 60-144 bpm) with slurs (notes written to last until the next one
sounds), fingered by the planner and played by the scripted pianist in one continuous simulation.
The figures are docs/metrics.md's: the median played/written duration per note-length class over
every matched note of the set, note F1 with offsets and the per-step key-press F1.
"""

from pathlib import Path

import numpy as np
import pytest

from benchmarks import zeroshot
from pianobot.music.metrics import LENGTH_CLASSES, duration_ratios
from pianobot.perform.perform import PLAY_CONFIG, perform

ROOT = Path(__file__).resolve().parent.parent
MELODIES = 16


@pytest.fixture(scope="module")
def played():
    pieces, _ = zeroshot.melody_set(MELODIES, zeroshot.ARTICULATION_SEED, zeroshot.SLURS)
    return [perform(piece, "scripted", PLAY_CONFIG).report() for _, piece in pieces]


def test_the_set_has_what_it_claims():
    pieces = [piece for _, piece in zeroshot.melody_set(MELODIES, zeroshot.ARTICULATION_SEED, zeroshot.SLURS)[0]]
    notes = [n for piece in pieces for n in piece.notes]
    bpms = [piece.bpm for piece in pieces]
    assert min(bpms) < 80 and max(bpms) > 120
    legato = [a for piece in pieces for a, b in zip(piece.notes, piece.notes[1:]) if abs(a.offset - b.onset) < 1e-3]
    repeats = [a for piece in pieces for a, b in zip(piece.notes, piece.notes[1:]) if a.pitch == b.pitch]
    leaps = [a for piece in pieces for a, b in zip(piece.notes, piece.notes[1:]) if abs(a.pitch - b.pitch) >= 7]
    assert len(legato) > len(notes) / 3 and repeats and leaps
    short = sum(n.duration < LENGTH_CLASSES[0][2] for n in notes)
    assert short > len(notes) / 3  # most are eighths and triplets


@pytest.mark.slow
def test_the_scripted_pianist_holds_notes_as_long_as_they_are_written(played):
    """The teacher before issue 38 held the long notes of this set for a median of 0.86 of their length,
    scored note F1 with offsets 0.60 and per-step F1 0.78 on it. Issue 38 asks 0.9 for both: not met yet
    (0.80 and 0.87 here, docs/benchmarks.md's "Articulation" says what costs the rest); the bounds below
    keep what was won."""
    pooled = {
        name: [x for report in played for x in duration_ratios(report.rows)[name]] for name, _, _ in LENGTH_CLASSES
    }
    medians = {name: round(float(np.median(ratios)), 3) for name, ratios in pooled.items()}
    assert all(m >= 0.9 for m in medians.values()), medians
    assert np.mean([r.f1 for r in played]) >= 0.98
    assert np.mean([r.f1_with_offsets for r in played]) >= 0.75
    assert np.mean([r.step_f1 for r in played]) >= 0.85
