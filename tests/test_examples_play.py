"""The examples play as models/README.md (and the README) say: those figures are written by
`python -m benchmarks.examples` from its record, models/examples.json, and these tests play the
examples again through `pianobot play` and fail where a recorded figure no longer holds."""

from __future__ import annotations

import json

import pytest

from benchmarks.examples import (
    ALLEGRO,
    FLOOR,
    PHRASE_POLICIES,
    RECORD,
    ROOT,
    TWO_HANDS,
    main,
    play_all,
    problems,
    tables,
)


def _record() -> dict:
    return json.loads(RECORD.read_text())


def test_the_docs_hold_the_record_s_figures():
    """What lies between the markers is what the record gives: a figure typed by hand, or a
    record changed without its docs, fails here."""
    made = tables(_record())
    for path in (ROOT / "models" / "README.md", ROOT / "README.md"):
        text = path.read_text()
        for name, body in made.items():
            begin = f"<!-- examples:{name} -->"
            if begin in text:
                inside = text.split(begin, 1)[1].split(f"<!-- /examples:{name} -->", 1)[0]
                assert inside.strip() == body.strip(), f"{path.name}: examples:{name}"


def test_the_record_keeps_the_promises():
    record = _record()["examples"]
    assert set(record) == {*PHRASE_POLICIES, *TWO_HANDS, *ALLEGRO}
    for entry in record.values():
        assert [int(s) for s in entry["seeds"]] == [0, 1, 2, 3]
        assert all(v["f1"] >= FLOOR[entry["kind"]] for v in entry["seeds"].values())


def test_the_examples_with_phrase_policies_play_as_recorded_from_every_hand_start():
    played = play_all(list(PHRASE_POLICIES), say=lambda line: None)
    assert not problems(played, _record()["examples"])


def test_the_two_hand_examples_play_as_recorded_from_hand_start_0():
    """As `play` plays them (the pianist's hands; `make demo`'s second piece among them), and two of
    them with the Allegro-like hand. (Every entry from hand starts 0-3 with `python -m
    benchmarks.examples --check`: ten minutes more.)"""
    played = play_all([*TWO_HANDS, *ALLEGRO[:2]], seeds=(0,), say=lambda line: None)
    assert not problems(played, _record()["examples"])


def test_a_figure_that_falls_is_found():
    record = _record()["examples"]
    fallen = json.loads(json.dumps({"twinkle": record["twinkle"]}))
    fallen["twinkle"]["seeds"]["0"]["f1"] = 0.929
    assert problems(fallen, record) and problems(fallen, {})  # below the record and below the floor


def test_only_refuses_an_example_the_record_does_not_hold(capsys):
    """`--only` names entries of the record (spaces normalised); another name is one line and exit 2,
    before anything is played."""
    with pytest.raises(SystemExit) as raised:
        main(["--only", "ode-to-joy-performed  --hand-model allegro,no-such-piece"])
    assert raised.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--only no-such-piece: not an example of the record" in error
    assert "ode-to-joy-performed --hand-model allegro" in error  # (the known names listed; the spaced one accepted)
    assert "--only ode-to-joy" not in error
