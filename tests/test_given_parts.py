"""`pianobot train --task parts --pieces DIR`: the parts family with hands' parts of real files given to it."""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_one_line_error, run

from pianobot.agent.tasks import GivenParts, draw_part
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotWarning, SettingError
from pianobot.music.instrument import THUMB, check_playable
from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece
from pianobot.sim.hand import HandConfig
from pianobot.sim.world import WorldConfig

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"


def _part(*pitches: int) -> Piece:
    return Piece(tuple(Note(0.5 * i, p, 0.5 * i + 0.4, 70, 2) for i, p in enumerate(pitches)))


def _duet(path: Path, shift: int = 0) -> Path:
    """A short two-hand file whose tracks are named for the hands."""
    right = [Note(0.5 * i, 72 + p + shift, 0.5 * i + 0.4, 80, None, "right") for i, p in enumerate((0, 2, 4, 5))]
    left = [Note(0.0, 48 + shift, 0.9, 70, None, "left"), Note(1.0, 43 + shift, 1.9, 70, None, "left")]
    return write_midi(Piece((*right, *left)), path)


def test_given_parts_are_drawn_at_their_share_and_the_rest_are_the_familys_own():
    given = GivenParts((_part(60, 62), _part(64, 65, 67)), share=0.5)
    rng = np.random.default_rng(3)
    draws = [draw_part(rng, EnvConfig(), given) for _ in range(60)]
    from_given = [d for d in draws if d in given.parts]
    assert 18 <= len(from_given) <= 42  # about half (binomial, 60 draws)
    assert {d for d in from_given} == set(given.parts)  # each given part is drawn
    for draw in (d for d in draws if d not in given.parts):  # the rest: the family's own, fingered parts
        check_playable(draw, EnvConfig().world.keyboard.spec, EnvConfig().world.hand.spec)
        assert draw.has_fingering and len(draw) > 3
    always = GivenParts(given.parts, share=1.0)
    assert all(draw_part(np.random.default_rng(s), EnvConfig(), always) in given.parts for s in range(5))
    # the same generator draws the same instances
    again = [draw_part(g, EnvConfig(), given) for g in [np.random.default_rng(3)] for _ in range(60)]
    assert again == draws


def test_given_parts_are_validated_and_named_by_what_is_drawn():
    part = _part(60, 62)
    with pytest.raises(ValueError, match="no parts"):
        GivenParts(())
    with pytest.raises(ValueError, match="share"):
        GivenParts((part,), share=0.0)
    with pytest.raises(ValueError, match="fingered"):
        GivenParts((Piece((Note(0.0, 60, 0.5),)),))
    digests = {GivenParts((part,)).digest, GivenParts((part,), share=0.75).digest, GivenParts((_part(60, 64),)).digest}
    assert len(digests) == 3
    assert GivenParts((part,), about={"folder": "a"}).digest == GivenParts((part,), about={"folder": "b"}).digest


def test_given_parts_read_each_hand_of_the_two_hand_files_and_say_what_they_leave_out(tmp_path):
    from pianobot.learn.jobs import given_parts

    _duet(tmp_path / "a.mid")
    _duet(tmp_path / "b.MID", shift=2)
    write_midi(_part(60, 62, 64), tmp_path / "one-hand.mid")
    (tmp_path / "broken.mid").write_bytes(b"not a midi file")
    (tmp_path / "notes.txt").write_text("not read")
    env = EnvConfig(world=WorldConfig(hand=HandConfig(spec=THUMB)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        given = given_parts(tmp_path, env)
    (said,) = [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]
    assert "1 file(s) that play one hand" in said and "4 parts" in said
    assert "1 file(s) the reading refuses (broken.mid:" in said  # named, so the user can look at it
    assert len(given.parts) == 4 and given.about == {"folder": str(tmp_path), "files": 4, "parts": 4, "share": 0.5}
    for part in given.parts:  # each as its player is given it: fingered, on the env's keys, from 0
        check_playable(part, env.world.keyboard.spec, THUMB)
        assert part.has_fingering and part.notes[0].onset == 0.0
    assert sorted(len(p) for p in given.parts) == [2, 2, 4, 4]
    with pytest.raises(SettingError, match="not a folder") as error:
        given_parts(tmp_path / "a.mid", env)
    assert error.value.fields == ("train.pieces",)
    (tmp_path / "empty").mkdir()
    with pytest.raises(SettingError, match="no .mid files"):
        given_parts(tmp_path / "empty", env)


def test_train_the_parts_family_with_pieces_stores_a_general_policy_that_says_what_it_was_given(tmp_path):
    from pianobot.agent.general import general_candidates
    from pianobot.agent.policy import policy_target
    from pianobot.agent.store import read_manifest

    pieces = tmp_path / "pieces"
    pieces.mkdir()
    _duet(pieces / "a.mid")
    models = tmp_path / "models"
    quick = ("--steps", "40", "--exploration-steps", "20", "--no-tactile", "--models", models)
    result = run("train", "--task", "parts", "--pieces", pieces, *quick, "--json", "-")
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    folder = Path(policy["folder"])
    manifest = read_manifest(folder)
    assert folder.name.startswith("task-parts-v3-pieces-") and policy_target(folder) == "parts"
    given = manifest["given"]
    assert given["folder"] == str(pieces) and given["parts"] == 2 and given["share"] == 0.5
    assert folder.name.startswith(f"task-parts-v3-pieces-{given['digest']}-")
    assert general_candidates(models)[0] == folder  # play and train find it as the general policy
    # the same pieces are the same parts: the same folder, already trained (a resume finds its checkpoint)
    same = run("train", "--task", "parts", "--pieces", pieces, *quick, "--json", "-")
    assert same.exit_code == 0 and json.loads(same.stdout)["policies"][0]["folder"] == str(folder)
    assert json.loads(same.stdout)["policies"][0]["trained_now"] is False
    # other pieces are another family: another folder, not the first one resumed or taken as trained
    _duet(pieces / "b.mid", shift=2)
    again = run("train", "--task", "parts", "--pieces", pieces, *quick, "--json", "-")
    assert again.exit_code == 0 and json.loads(again.stdout)["policies"][0]["folder"] != str(folder)


def test_pieces_without_the_parts_family_or_with_no_parts_is_one_line(tmp_path):
    assert_one_line_error(run("train", "--task", "melody", "--pieces", tmp_path, "--models", tmp_path), "--pieces")
    assert_one_line_error(run("train", EXAMPLES / "twinkle.mid", "--pieces", tmp_path), "--pieces")
    write_midi(_part(60, 62), tmp_path / "one-hand.mid")
    line = assert_one_line_error(
        run("train", "--task", "parts", "--pieces", tmp_path, "--models", tmp_path / "m"), "--pieces"
    )
    assert "1 file(s) that play one hand" in line and not (tmp_path / "m").exists()
