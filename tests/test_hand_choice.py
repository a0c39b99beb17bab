"""Which hand plays where no `--hand-model` is named: the pianist's hands for a file both hands
play, the Allegro-like hand for one hand's part; a hand the options, a named general policy or the
store's phrase policies for the file name instead."""

import json
import shutil
import warnings
from pathlib import Path

import pytest
from conftest import midi_file, off, on, run

from pianobot.agent.general import piece_hand_models
from pianobot.cli.options import make_reading, read_file
from pianobot.errors import PianobotWarning
from pianobot.pianist.reading import choose_model, open_song, read_piece

ROOT = Path(__file__).parent.parent
ALLEGRO_POLICY = ROOT / "pianobot" / "policies" / "task-parts-v2-92ae607013d9"
A_PHRASE_POLICY = next(f for f in sorted((ROOT / "models").iterdir()) if (f / "manifest.json").exists())


def _track(*notes):
    return [event for p, a, b in notes for event in ((round(a * 480), on(p)), (round(b * 480), off(p)))]


def _duet(path):
    right = _track((72, 0, 1), (74, 1, 2), (76, 2, 3), (77, 3, 4))
    left = _track((48, 0, 2), (55, 2, 4))
    return midi_file(path, [("Right Hand", right), ("Left Hand", left)])


def _melody(path):
    return midi_file(path, [("Melody", _track((60, 0, 1), (62, 1, 2), (64, 2, 3)))])


def _played_by(tmp_path, song, *options) -> tuple[str, list[int]]:
    out = tmp_path / "out.mid"
    result = run("play", song, "-o", out, "--controller", "scripted", *options)
    assert result.exit_code == 0, result.output
    report = json.loads(out.with_suffix(".report.json").read_text())
    report = report["hands"]["right"] if "hands" in report else report  # (both hands: each hand's)
    return report["hand_model"], report["fingers"]


def test_both_hands_of_a_file_are_the_pianist_s_and_one_hand_s_part_the_allegro_s(tmp_path):
    duet, melody = _duet(tmp_path / "duet.mid"), _melody(tmp_path / "melody.mid")
    assert _played_by(tmp_path, duet)[0] == "pianist"
    assert _played_by(tmp_path, melody) == ("allegro", [2, 3, 4])
    # a model or the Allegro-like hand's thumb named: that hand, whatever the file holds
    assert _played_by(tmp_path, duet, "--hand-model", "allegro")[0] == "allegro"
    assert _played_by(tmp_path, duet, "--thumb") == ("allegro", [1, 2, 3, 4])
    assert _played_by(tmp_path, melody, "--hand-model", "pianist") == ("pianist", [1, 2, 3, 4, 5])
    # one hand's part of a two-hand file is one hand's: the Allegro-like hand's
    assert _played_by(tmp_path, duet, "--hand", "right")[0] == "allegro"
    # inspect says which hand plays both
    inspected = run("inspect", duet, "--json", tmp_path / "i.json")
    assert inspected.exit_code == 0 and "of the pianist hand" in " ".join(inspected.stdout.split())
    assert json.loads((tmp_path / "i.json").read_text())["hand_model"] == "pianist"


def test_the_library_chooses_the_same_way_and_keeps_its_allegro_default(tmp_path):
    duet = _duet(tmp_path / "duet.mid")
    assert read_piece(duet, model=None).fingers.model == "pianist"
    assert read_piece(duet).fingers.model == "allegro"  # (the library's default hand, as before)
    assert choose_model(open_song(_melody(tmp_path / "m.mid")), make_reading().options) == ("allegro", None)


def _store_for(tmp_path, piece: str, model: str | None = None) -> Path:
    """A store holding one phrase policy (a committed one's manifest) trained for ``piece``."""
    store = tmp_path / "store"
    folder = store / A_PHRASE_POLICY.name
    shutil.copytree(A_PHRASE_POLICY, folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["piece"] = piece
    if model is not None:
        manifest["config"]["env"]["world"]["hand"]["spec"]["model"] = model
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return store


def test_a_store_trained_for_the_file_with_the_allegro_hand_keeps_it_playing_with_that_hand(tmp_path):
    duet = _duet(tmp_path / "duet.mid")
    store = _store_for(tmp_path, "duet.mid (right hand)")
    assert piece_hand_models(store, "duet.mid") == {"allegro"}
    assert piece_hand_models(store, "duet") == set() and piece_hand_models(store, "duet.mid.mid") == set()
    with pytest.warns(
        PianobotWarning, match="played with the allegro hand, the hand its policies in .* were trained for"
    ):
        assert read_file(duet, make_reading(), finger=False, models=store).fingers.model == "allegro"
    with warnings.catch_warnings():
        warnings.simplefilter("error", PianobotWarning)  # (a hand named: nothing chosen, nothing said)
        named = read_file(duet, make_reading(hand_model=None, thumb=False), finger=False, models=store)
    assert named.fingers.model == "allegro"
    # policies for another file, or none: the file chooses
    other = read_file(duet, make_reading(), finger=False, models=_store_for(tmp_path / "b", "other.mid"))
    assert other.fingers.model == "pianist"
    assert read_file(duet, make_reading(), finger=False, models=tmp_path / "none").fingers.model == "pianist"
    # the pianist's policies for a one-hand file: the pianist's hand plays it, said
    melody = _melody(tmp_path / "melody.mid")
    store = _store_for(tmp_path / "c", "melody.mid", model="pianist")
    with pytest.warns(PianobotWarning, match="played with the pianist hand"):
        assert read_file(melody, make_reading(), models=store).fingers.model == "pianist"


def test_a_store_s_own_general_policy_for_hands_parts_keeps_its_hand_and_a_matching_one_is_not_said(tmp_path):
    duet = _duet(tmp_path / "duet.mid")
    store = tmp_path / "store"
    shutil.copytree(ALLEGRO_POLICY, store / ALLEGRO_POLICY.name)
    assert piece_hand_models(store, None) == {"allegro"} and piece_hand_models(store, "duet.mid") == set()
    with pytest.warns(PianobotWarning, match="duet.mid: played with the allegro hand"):
        assert read_file(duet, make_reading(), finger=False, models=store).fingers.model == "allegro"
    melody = _melody(tmp_path / "melody.mid")  # (the Allegro-like hand's anyway: nothing to say)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PianobotWarning)
        assert read_file(melody, make_reading(), finger=False, models=store).fingers.model == "allegro"


def test_a_chordal_part_the_allegro_hand_would_give_to_both_hands_is_the_pianist_s_one_hand(tmp_path):
    """One unnamed track of five-note chords: the Allegro-like hand's fingers are too few (its
    reading gives the notes to both hands), the pianist's one hand plays them."""
    chords = _track(*[(p, 0, 1) for p in (60, 62, 64, 65, 67)], *[(p, 1, 2) for p in (60, 62, 64, 65, 67)])
    song = midi_file(tmp_path / "five.mid", [("Piano", chords)])
    assert choose_model(open_song(song), make_reading().options) == ("pianist", None)
    read = read_piece(song, model=None)
    assert read.fingers.model == "pianist" and not read.both
    assert read_piece(song, model="allegro").both  # (the Allegro-like hand needs both)


def test_a_legato_line_the_allegro_hand_s_one_hand_refuses_is_the_pianist_s_one_hand(tmp_path):
    """An arpeggio, each note held into the next (C4 E4 G4 C5 ...): the Allegro-like hand's three
    fingers cannot hold one note and strike the next past it, so its one hand refuses the file (and
    its planner gives every note to one hand); the pianist's one hand plays it, as written."""
    pitches = (60, 64, 67, 72, 67, 64, 60)
    song = midi_file(tmp_path / "legato.mid", [("Piano", _track(*[(p, i, i + 2) for i, p in enumerate(pitches)]))])
    assert choose_model(open_song(song), make_reading().options) == ("pianist", None)
    assert _played_by(tmp_path, song) == ("pianist", [1, 2, 3, 4, 5])
    out = tmp_path / "out.mid"
    assert json.loads(out.with_suffix(".report.json").read_text())["f1"] == 1.0
    refused = run("play", song, "-o", tmp_path / "a.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert refused.exit_code == 2 and "no fingering lets this hand go from G4 to C5" in " ".join(refused.output.split())
    # a line its one hand plays stays the Allegro-like hand's
    melody = _melody(tmp_path / "melody.mid")
    assert choose_model(open_song(melody), make_reading().options) == ("allegro", None)


def test_a_general_policy_named_plays_the_hand_it_was_trained_for(tmp_path):
    duet = _duet(tmp_path / "duet.mid")
    out = tmp_path / "out.mid"
    result = run("play", duet, "-o", out, "--policy", ALLEGRO_POLICY)
    assert result.exit_code == 0, result.output
    report = json.loads(out.with_suffix(".report.json").read_text())
    assert {h["hand_model"] for h in report["hands"].values()} == {"allegro"} and report["f1"] > 0.5


@pytest.mark.parametrize("model", ["allegro", "pianist"])
def test_inspect_json_of_one_hand_names_its_hand_model(tmp_path, model):
    """One hand's `inspect --json` records the hand model, as both hands' does and play's report."""
    result = run(
        "inspect", ROOT / "examples" / "midi" / "ode-to-joy.mid", "--hand-model", model, "--json", tmp_path / "i.json"
    )
    assert result.exit_code == 0, result.output
    data = json.loads((tmp_path / "i.json").read_text())
    assert data["hand_model"] == model and data["fingers"] == ([2, 3, 4] if model == "allegro" else [1, 2, 3, 4, 5])
