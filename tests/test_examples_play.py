"""The examples play as models/README.md (and the README) say: those figures are written by
`python -m benchmarks.examples` from its record, models/examples.json, and these tests play the
examples again through `pianobot play` and fail where a recorded figure no longer holds."""

from __future__ import annotations

import json

from benchmarks.examples import FLOOR, PHRASE_POLICIES, PIANIST, RECORD, ROOT, TWO_HANDS, play_all, problems, tables


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
    assert set(record) == {*PHRASE_POLICIES, *TWO_HANDS, *PIANIST}
    for entry in record.values():
        assert [int(s) for s in entry["seeds"]] == [0, 1, 2, 3]
        assert all(v["f1"] >= FLOOR[entry["kind"]] for v in entry["seeds"].values())


def test_the_examples_with_phrase_policies_play_as_recorded_from_every_hand_start():
    played = play_all(list(PHRASE_POLICIES), say=lambda line: None)
    assert not problems(played, _record()["examples"])


def test_the_two_hand_examples_play_as_recorded_from_hand_start_0():
    """Either hand model's (`make demo`'s second piece, the pianist's hands, among them). (Hand
    starts 1-3 too with `python -m benchmarks.examples --check`: four minutes more.)"""
    played = play_all([*TWO_HANDS, *PIANIST], seeds=(0,), say=lambda line: None)
    assert not problems(played, _record()["examples"])


def test_a_figure_that_falls_is_found():
    record = _record()["examples"]
    fallen = json.loads(json.dumps({"twinkle": record["twinkle"]}))
    fallen["twinkle"]["seeds"]["0"]["f1"] = 0.929
    assert problems(fallen, record) and problems(fallen, {})  # below the record and below the floor
