from dataclasses import replace

import mir_eval
import numpy as np
import pytest

from pianobot.music.metrics import compare, key_press_f1
from pianobot.music.piece import Note, Piece


@pytest.fixture
def reference():
    return Piece(tuple(Note(float(i), 60 + 2 * i, i + 1.0, 60 + 10 * i, 2 + i % 3) for i in range(6)), bpm=60)


def flawed(reference):
    """One note dropped, one velocity changed by +20, one onset shifted by 30 ms."""
    notes = list(reference.notes)
    notes[3] = replace(notes[3], velocity=notes[3].velocity + 20)
    notes[4] = replace(notes[4], onset=notes[4].onset + 0.03)
    del notes[1]
    return Piece(tuple(notes))


def test_a_piece_against_itself_is_perfect(reference):
    report = compare(reference, reference)
    assert report.f1 == report.precision == report.recall == 1.0
    assert report.f1_with_offsets == report.velocity_f1 == report.step_f1 == 1.0
    assert report.velocity_mae == 0 and report.velocity_max_error == 0
    assert report.onset_error_mean == 0 and report.onset_error_max == 0
    assert report.fingering_accuracy == 1.0


def test_exact_figures_for_a_known_set_of_mistakes(reference):
    report = compare(reference, flawed(reference))
    assert report.matched_notes == 5
    assert report.precision == 1.0
    assert report.recall == pytest.approx(5 / 6)
    assert report.f1 == pytest.approx(10 / 11)
    assert report.f1_with_offsets == pytest.approx(10 / 11)
    assert report.velocity_mae == pytest.approx(20 / 5)
    assert report.velocity_max_error == 20
    assert report.onset_error_mean == pytest.approx(0.03 / 5)
    assert report.onset_error_max == pytest.approx(0.03)
    # 120 steps; the dropped note empties 20 of them and the late onset one more
    assert report.step_f1 == pytest.approx(99 / 120)
    assert [r.played is None for r in report.rows].count(True) == 1


def arrays(piece):
    """A piece as mir_eval takes it: intervals, frequencies, velocities."""
    return (
        np.array([[n.onset, n.offset] for n in piece]),
        mir_eval.util.midi_to_hz(np.array([n.pitch for n in piece], dtype=float)),
        np.array([n.velocity for n in piece], dtype=float),
    )


def test_figures_agree_with_mir_eval_called_directly(reference):
    played = flawed(reference)
    played = Piece(played.notes + (Note(2.5, 71, 3.0, 50),))  # an extra note too
    report = compare(reference, played, onset_tolerance=0.02)

    (ri, rp, rv), (ei, ep, ev) = arrays(reference), arrays(played)
    p, r, f, _ = mir_eval.transcription.precision_recall_f1_overlap(
        ri, rp, ei, ep, onset_tolerance=0.02, offset_ratio=None
    )
    assert (report.precision, report.recall, report.f1) == pytest.approx((p, r, f))
    _, _, f_off, _ = mir_eval.transcription.precision_recall_f1_overlap(ri, rp, ei, ep, onset_tolerance=0.02)
    assert report.f1_with_offsets == pytest.approx(f_off)
    _, _, f_vel, _ = mir_eval.transcription_velocity.precision_recall_f1_overlap(
        ri, rp, rv, ei, ep, ev, onset_tolerance=0.02, offset_ratio=None
    )
    assert report.velocity_f1 == pytest.approx(f_vel)
    # the 30 ms late note no longer matches at a 20 ms tolerance
    assert report.matched_notes == 4 and report.recall == pytest.approx(4 / 6)


def _performed(seed: int, notes: int) -> tuple[Piece, Piece]:
    """A reference of ``notes`` (chords, repeated keys, a few pitches) and a performance of it with
    onsets off by up to 70 ms, offsets off, notes dropped, extra notes and velocities of its own."""
    rng = np.random.default_rng(seed)
    onsets = np.sort(rng.integers(0, notes // 2, notes)) * 0.125 + rng.choice([0.0, 0.03], notes)
    reference = tuple(
        Note(float(t), int(p), float(t + d), int(v))
        for t, p, d, v in zip(
            onsets, rng.integers(60, 66, notes), rng.uniform(0.05, 0.6, notes), rng.integers(30, 110, notes)
        )
    )
    reference = tuple({(n.onset, n.pitch): n for n in reference}.values())  # (no two of a key at once)
    played = [
        replace(
            n, onset=n.onset + shift, offset=n.offset + shift + stretch, velocity=int(np.clip(n.velocity + dv, 1, 127))
        )
        for n, shift, stretch, dv in zip(
            reference, rng.uniform(-0.07, 0.07, notes), rng.uniform(-0.1, 0.1, notes), rng.integers(-25, 25, notes)
        )
        if rng.random() > 0.1 and n.offset + shift + stretch > n.onset + shift + 0.01
    ]
    played += [
        Note(float(t), int(p), float(t) + 0.1, 64)
        for t, p in zip(rng.uniform(0, notes / 16, notes // 10), rng.integers(60, 66, notes // 10))
    ]
    return Piece(reference), Piece(tuple(sorted(played, key=lambda n: (n.onset, n.pitch))))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_notes_matched_group_by_group_score_as_mir_eval_matching_them_all_at_once(seed):
    """compare matches each pitch's notes in groups no match can join (onsets farther apart than the
    tolerance): the figures of mir_eval given every note at once, on performances with near misses."""
    reference, played = _performed(seed, 400)
    report = compare(reference, played)

    (ri, rp, rv), (ei, ep, ev) = arrays(reference), arrays(played)
    p, r, f, _ = mir_eval.transcription.precision_recall_f1_overlap(ri, rp, ei, ep, offset_ratio=None)
    assert 0.6 < f < 0.95  # (near misses and extras: a real test of the matching)
    assert (report.precision, report.recall, report.f1) == (p, r, f)
    assert report.f1_with_offsets == mir_eval.transcription.precision_recall_f1_overlap(ri, rp, ei, ep)[2]
    velocity = mir_eval.transcription_velocity.precision_recall_f1_overlap(ri, rp, rv, ei, ep, ev, offset_ratio=None)
    assert report.velocity_f1 == pytest.approx(velocity[2])


def test_a_long_performance_is_matched_in_small_groups(monkeypatch):
    """Memory follows the largest group of notes mir_eval is given, not the piece's length squared (an
    hour's notes at once took gigabytes): 3,670 notes are never matched more than a few at a time."""
    import mir_eval.transcription as transcription

    reference, played = _performed(3, 4000)
    largest = []
    match_notes = transcription.match_notes
    monkeypatch.setattr(
        transcription,
        "match_notes",
        lambda ref, rp, est, ep, **kw: largest.append(len(ref) * len(est)) or match_notes(ref, rp, est, ep, **kw),
    )
    report = compare(reference, played)
    assert report.matched_notes > 2000 and max(largest) <= 16


def test_fingering_accuracy_counts_matched_notes_only(reference):
    wrong = reference.with_fingers([2, 2, 2, 2, 3, 4])
    expected = sum(a == b for a, b in zip([n.finger for n in reference], [2, 2, 2, 2, 3, 4])) / 6
    assert compare(reference, wrong).fingering_accuracy == pytest.approx(expected)
    assert compare(reference, reference.without_fingering()).fingering_accuracy is None


def test_nothing_played():
    reference = Piece((Note(0, 60, 1),))
    report = compare(reference, Piece(()))
    assert report.f1 == 0 and report.velocity_mae is None and report.step_f1 == 0
    assert [r.played for r in report.rows] == [None]


def test_key_press_f1_scores_empty_steps_as_one():
    reference = Piece((Note(0.0, 60, 0.5), Note(1.0, 62, 1.5)))  # 30 steps, 10 of them silent
    played = Piece((Note(0.0, 60, 0.5),))
    precision, recall, f1 = key_press_f1(reference, played)
    assert f1 == pytest.approx(20 / 30)
    assert precision == 1.0
    assert recall == pytest.approx(20 / 30)
    extra = Piece(reference.notes + (Note(0.5, 64, 1.0),))
    assert key_press_f1(reference, extra)[0] == pytest.approx(20 / 30)


def test_duration_ratio_is_the_median_of_played_over_written_by_length_class():
    # written: two short notes (0.2 s), one medium (0.5 s), no long one
    reference = Piece((Note(0.0, 60, 0.2), Note(0.5, 62, 0.7), Note(1.0, 64, 1.5)))
    # played: the first short note held half its length, the second in full, the medium one 80 %
    played = Piece((Note(0.0, 60, 0.1), Note(0.5, 62, 0.7), Note(1.0, 64, 1.4)))
    report = compare(reference, played)
    assert report.duration_ratio_short == pytest.approx(0.75)  # median of 0.5 and 1.0
    assert report.duration_ratio_medium == pytest.approx(0.8)
    assert report.duration_ratio_long is None
    # a missed note has no ratio; a note of exactly 0.35 s is medium
    missed = compare(Piece((Note(0.0, 60, 0.35), Note(1.0, 62, 1.2))), Piece((Note(0.0, 60, 0.7),)))
    assert missed.duration_ratio_medium == pytest.approx(2.0) and missed.duration_ratio_short is None
