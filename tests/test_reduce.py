"""Reading one hand's part with --hand: what the hand cannot play is reduced, with one warning per
kind of change; without --hand the planner still refuses it (pieces built in code)."""

import warnings
from dataclasses import replace

import pytest
from conftest import midi_file, off, on
from typer.testing import CliRunner

from pianobot.cli.app import app
from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions
from pianobot.music.metrics import compare
from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece, parse_pitch
from pianobot.perform.perform import perform
from pianobot.pianist.fingering import plan_fingering
from pianobot.pianist.reduce import load_for_hand, reduce_part


def piece(*notes: tuple[float, str, float]) -> Piece:
    """Notes as (onset, pitch name, offset), at velocity 70."""
    return Piece(tuple(Note(a, parse_pitch(name), b, 70) for a, name, b in notes), bpm=60)


def reduce(p: Piece):
    """The reduction of ``p`` for the default hand, and the warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = reduce_part(p, KeyboardSpec(), HandSpec(), "the part")
    return result, [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]


def tops(p: Piece) -> list[tuple[float, int]]:
    """The top voice: the highest note of each chord."""
    return [(c[0].onset, max(n.pitch for n in c)) for c in p.chords()]


def test_a_chord_wider_than_the_hand_keeps_its_top_voice_and_what_fits_under_it():
    """C4+C5 (16.4 cm) and E4+G4+E5 (an octave) are out of reach: C4 and E4 go, G4 stays."""
    part = piece((0, "C4", 0.5), (0, "C5", 0.5), (0.5, "D5", 1), (1, "E4", 2), (1, "G4", 2), (1, "E5", 2))
    result, said = reduce(part)
    assert [n.name for n in result.piece.notes] == ["C5", "D5", "G4", "E5"]
    assert tops(result.piece) == tops(part)
    assert result.wide == 2
    assert said == ["the part has chords wider than this hand reaches: kept their top notes, dropped 2 lower note(s)"]
    assert not plan_fingering(result.piece).problems


def test_a_note_held_under_a_leap_ends_where_the_leap_lands():
    part = piece((0, "E4", 2), (0, "C5", 0.5), (0.5, "G5", 1), (1, "A5", 2))
    with pytest.raises(PianobotError, match="no fingering lets this hand go from E4 C5 to G5"):
        plan_fingering(part)
    result, said = reduce(part)
    assert [(n.name, n.offset) for n in result.piece.notes] == [("E4", 0.5), ("C5", 0.5), ("G5", 1), ("A5", 2)]
    assert result.held == 1 and len(said) == 1 and "1 held note(s) now end earlier" in said[0]


def test_a_note_is_held_under_the_hand_until_the_next_chord_only():
    """The planner keeps a held note in reach up to the next onset: C5, held under D5 and E5, ends at E5."""
    part = piece((0, "C5", 3), (0, "E5", 1), (1, "D5", 2), (2, "E5", 3))
    result, _ = reduce(part)
    assert next(n for n in result.piece.notes if n.name == "C5").offset == 2
    assert result.held == 1 and len(result.piece) == 4


@pytest.mark.parametrize(
    "notes",
    [
        # a grace note before a three-note chord: every finger strikes the chord, one of them the grace note too
        ((0, "E5", 1.0), (0.9, "D5", 1.0), (1.0, "A4", 2.0), (1.0, "C5", 2.0), (1.0, "F5", 2.0)),
        # a grace note a leap below its note: the wrist must move between them
        ((0, "C5", 1.0), (0.9, "C4", 1.0), (1.0, "A5", 2.0)),
    ],
    ids=["before-a-chord", "a-leap-away"],
)
def test_grace_notes_are_played_as_fast_as_the_hand_allows_and_sound(notes):
    """Moved earlier, not dropped; the scripted pianist then sounds every note."""
    part = piece(*notes)
    result, said = reduce(part)
    grace = next(n for n in result.piece.notes if n.pitch == parse_pitch(notes[1][1]))
    assert len(result.piece) == len(part)  # nothing dropped
    assert notes[0][0] < grace.onset < notes[1][0] and result.graces == 1  # moved earlier, after the note before
    assert [n for n in result.piece.notes if n.onset >= 1.0] == [n for n in part.notes if n.onset >= 1.0]
    assert any("grace notes faster than this hand moves: played 1 of them as fast as it can" in s for s in said)
    fingered = plan_fingering(result.piece)
    assert not fingered.problems
    report = compare(fingered.piece, perform(fingered.piece, "scripted", seed=0).played)
    assert report.f1 == 1.0, [(r.reference, r.played) for r in report.rows]


def test_a_run_faster_than_the_hand_loses_notes_but_keeps_its_ends():
    run = [(1 + 0.16 * i, name, 1.16 + 0.16 * i) for i, name in enumerate("D4 E4 F4 G4 A4 B4 C5 D5".split())]
    part = piece((0, "C4", 1.0), *run, (2.28, "E5", 3.5))
    assert plan_fingering(part).problems
    result, said = reduce(part)
    assert 0 < result.fast < len(run) and len(result.piece) == len(part) - result.fast
    assert set(result.piece.notes) <= set(part.notes)  # dropped, nothing moved
    assert result.piece.notes[0] == part.notes[0] and result.piece.notes[-1] == part.notes[-1]
    assert said == [
        f"the part has notes faster than this hand can move: dropped {result.fast} note(s) "
        "(lower notes of chords first, then the shorter note of a fast pair)"
    ]
    assert not plan_fingering(result.piece).problems


def test_a_part_the_hand_can_play_is_left_as_it_is():
    part = piece(*[(0.5 * i, name, 0.5 * i + 0.5) for i, name in enumerate("C4 D4 E4 F4 G4 A4 B4 C5 E5 G5".split())])
    result, said = reduce(part)
    assert result.piece == part and not said


def _two_voices(path):
    """One unnamed track, as a recording: the octave C4+C5, then E4 held under a leap C5 -> G5."""
    events = [(0, on(60)), (0, on(72)), (470, off(60)), (470, off(72))]
    events += [(480, on(64)), (480, on(72)), (940, off(72)), (960, on(79)), (1400, off(79)), (1900, off(64))]
    return midi_file(path, [("", events)])


def test_warnings_say_each_change_once_with_its_count(tmp_path):
    path = _two_voices(tmp_path / "two.mid")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        part = load_for_hand(path, LoadOptions(hand="right"), KeyboardSpec(), HandSpec())
    said = [str(w.message) for w in caught]
    assert [n.name for n in part.notes] == ["C5", "E4", "C5", "G5"]
    assert (
        "the right hand's part has chords wider than this hand reaches: kept their top notes, dropped 1 lower note(s)"
        in said
    )
    assert sum("held note(s) now end earlier" in s for s in said) == 1 and any("1 held note(s)" in s for s in said)


def test_without_hand_a_fingered_file_one_hand_cannot_play_is_both_hands_and_with_it_reduced(tmp_path):
    """A file fingered for one hand that no fingering of one hand plays (a chord wider than it spans, a
    note held under a leap) was refused; both hands now play it, fingered anew, said in one line.
    With --hand, that hand's part is reduced to what it can play, as before."""
    runner = CliRunner()

    def fingered(p: Piece, *fingers: int) -> Piece:
        return Piece(tuple(replace(n, finger=f) for n, f in zip(p.notes, fingers)), bpm=p.bpm)

    wide = write_midi(fingered(piece((0, "C4", 0.5), (0, "C5", 0.5), (0.5, "D5", 1)), 2, 4, 4), tmp_path / "wide.mid")
    held = write_midi(fingered(piece((0, "E4", 2), (0, "C5", 0.5), (0.5, "G5", 1)), 2, 3, 4), tmp_path / "held.mid")
    for song, why in ((wide, "the chord C4 C5 at 0.000 s spans 16.4 cm"), (held, "no fingering lets this hand go")):
        result = runner.invoke(app, ["finger", str(song), "-o", str(tmp_path / "out.mid")])
        assert result.exit_code == 0, result.output
        said = " ".join(result.stderr.split())
        assert why in said and "given to both hands and fingered anew (its fingering is one hand's)" in said, said
        assert "fingering for both hands written" in " ".join(result.stdout.split())
        result = runner.invoke(app, ["finger", str(song), "-o", str(tmp_path / "out.mid"), "--hand", "right"])
        assert result.exit_code == 0, result.output
        assert "the right hand's part" in " ".join(result.stderr.split())
