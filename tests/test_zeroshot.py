"""benchmarks/zeroshot.py's breakdown of where the general policy loses notes (by phrase and by
onset within a phrase): the figure the docs use to tell weak phrases from weak hand-overs."""

from pathlib import Path

from benchmarks import zeroshot
from pianobot.music.phrases import split_phrases
from pianobot.music.piece import Note, Piece
from pianobot.perform.rollout import Rollout

ROOT = Path(__file__).resolve().parent.parent


def test_placed_hits_name_each_missed_note_by_its_phrase_and_onset():
    # 8 quarter notes, the 4th and the 2nd-to-last left out, one extra note and one late note
    notes = tuple(Note(0.5 * i, 60 + i, 0.5 * i + 0.4, 80, 1 + i % 5) for i in range(8))
    reference = Piece(notes)
    phrases = split_phrases(reference, 6)
    late = Note(notes[1].onset + 0.2, notes[1].pitch, notes[1].offset + 0.2, 80)  # 200 ms late: a miss
    played = Piece(tuple(n for i, n in enumerate(notes) if i not in (1, 3, 6)) + (late, Note(0.1, 50, 0.3, 80)))
    hits = zeroshot.placed_hits(phrases, Rollout(reference, played, 0.0, 0))

    assert len(hits) == 8
    missed = [(phrase, onset) for phrase, onset, ok in hits if not ok]
    where = {n: (p.index, sorted(x.onset for x in p.notes).index(n.onset)) for p in phrases for n in p.notes}
    assert missed == [where[notes[i]] for i in (1, 3, 6)]

    table = zeroshot.where_table([{"general": {"hits": hits}}])
    by_phrase, by_onset = ([cell.strip() for cell in line.split("|")[2:-1]] for line in table.splitlines()[-2:])
    assert [len(p.notes) for p in phrases] == [4, 4]
    assert by_phrase == ["0.50 (4)", "0.75 (4)", "", ""]
    assert by_onset == ["1.00 (2)", "0.50 (2)", "0.50 (2)", "0.50 (2)"]

    # a long piece's ninth phrase gets a column of its own
    table = zeroshot.where_table([{"general": {"hits": hits + [(8, 0, True)]}}])
    assert table.splitlines()[-2].split("|")[-2].strip() == "1.00 (1)"


def test_sets_plays_only_the_sets_named_and_draws_no_others():
    """`--sets`: only the named sets are built, in the benchmark's order; melodies left out are not drawn."""
    sets, rejected = zeroshot.chosen_sets(["tasks", "examples"], ROOT / "examples" / "midi", 50, 2026, 1)
    assert list(sets) == ["examples", "tasks"] and rejected == 0
    assert [name for name, _ in sets["examples"]] == list(zeroshot.EXAMPLES)
    assert len(sets["tasks"]) == len(zeroshot.TASKS)
    melodies, _ = zeroshot.chosen_sets(["melodies"], ROOT / "examples" / "midi", 2, 2026, 1)
    assert list(melodies) == ["melodies"] and len(melodies["melodies"]) == 2


def test_held_duration_is_one_median_over_every_note_of_the_set():
    """The table's held/written columns pool the notes of all pieces (not a mean of each piece's median)."""

    def row(short: list[float]) -> dict:
        figures = {"f1": 1.0, "velocity_mae": 0.0, "f1_offsets": 1.0, "step_f1": 1.0}
        ratios = {"short": short, "medium": [], "long": [1.0]}
        return {
            "notes": len(short) + 1,
            "general": {**figures, "ratios": ratios},
            "scripted": {**figures, "ratios": ratios},
        }

    rows = [row([0.2]), row([0.5, 0.6, 0.9])]  # per-piece medians 0.2 and 0.6; pooled median 0.55
    s = zeroshot.summary(rows)
    assert s["scripted"]["held_short"] == 0.55 and s["general"]["held_long"] == 1.0
    assert s["scripted"]["held_medium"] != s["scripted"]["held_medium"]  # no medium notes: nan
    line = zeroshot.table({"melodies": rows}).splitlines()[-1]
    assert line.split("|")[-2].strip() == "0.55, nan, 1.00"


def test_the_two_hand_examples_table_counts_an_example_only_if_every_hand_start_reaches_0_9():
    """benchmarks/hands.py --examples: each start's note F1, their mean and per-step F1 beside the
    scripted pianist's; an example whose mean passes 0.9 but one start does not is not counted."""
    from benchmarks import hands

    def play(f1, step=0.8):
        return {"f1": f1, "step_f1": step}

    rows = [
        {"piece": "steady", "notes": 10, "sac": [play(0.95), play(0.93), play(0.94)], "scripted": play(1.0, 0.9)},
        {"piece": "one-slip", "notes": 12, "sac": [play(0.99), play(0.85), play(0.99)], "scripted": play(0.98, 0.7)},
    ]
    lines = hands.example_table(rows).splitlines()
    steady = [cell.strip() for cell in lines[4].split("|")[1:-1]]
    assert steady == ["`steady`", "10", "0.950, 0.930, 0.940", "0.940", "0.800", "1.000", "0.900"]
    mean = [cell.strip() for cell in lines[6].split("|")[1:-1]]
    assert mean[3] == "0.942" and mean[5] == "0.990" and mean[6] == "0.800"  # one-slip's own mean is 0.943
    assert lines[-1] == "examples at note F1 0.9 or more from every hand start: 1 of 2"


def test_the_corpus_table_counts_what_was_given_and_what_was_refused():
    """benchmarks.corpus's table (music21 is not needed for it): the mean over the played rows only,
    the share of notes given over all of them, a refusal as its own row, no division by a zero F1."""
    from benchmarks import corpus

    def row(name, notes, given, general, scripted):
        figures = {"f1": general, "f1_right": general, "f1_left": general, "step_f1": 0.5, "given": given}
        held = {"step_f1": scripted / 2, "f1_offsets": scripted / 4}
        return {
            "piece": name,
            "source": f"x/{name}",
            "measures": "1-4",
            "notes": notes,
            "sac": figures,
            "scripted": {**figures, "f1": scripted, **held, "as_given": {"f1": 1.0, "step_f1": 0.9, "f1_offsets": 0.8}},
            "fingers": [1, 2, 3, 4] if name == "a" else [2, 3, 4],
        }

    rows = [
        row("a", 100, 90, 0.8, 1.0),
        row("b", 100, 60, 0.0, 0.0),
        {"piece": "c", "source": "x/c", "measures": "1-2", "refused": "read as one hand's file"},
    ]
    text = corpus.table(rows)
    assert "| c | `x/c` (1-2) | | | | refused: read as one hand's file |" in text
    assert "| b | `x/b` (1-4) | 2-4 | 100 | 60 | 0.000 |" in text and "| n/a |" in text
    assert (
        "| mean (2 played) | | | | 75% given | 0.400 | | | 0.500 | 0.500 | 80% | 0.250, 0.125 | 0.900, 0.800 |" in text
    )
    assert "| a | `x/a` (1-4) | 1-4 | 100 | 90 | 0.800 | 0.800 | 0.800 | 0.500 | 1.000 | 80% | 0.500, 0.250 |" in text
    # --thumb: the scripted pianist alone played; what it was given counts
    thumbs = [{**r, "sac": None} for r in rows[:2]]
    text = corpus.table(thumbs)
    assert "| a | `x/a` (1-4) | 1-4 | 100 | 90 | n/a | | | n/a | 1.000 | n/a |" in text
    assert "| mean (2 played) | | | | 75% given | n/a | | | n/a | 0.500 | n/a |" in text


def test_the_corpus_options_reach_the_players(monkeypatch, tmp_path):
    """--apart plays each hand in a simulation of its own, --thumb gives each hand its thumb and
    --no-thumb three fingers (default: chosen per file), --only names the excerpts; --json writes
    what was played (music21 stood in for: the run is not made)."""
    import json
    import sys
    import types

    from benchmarks import corpus
    from pianobot.music.instrument import HandSpec

    asked = {}

    def play_corpus(folder, only=(), together=True, hand=None, general=None, excerpts=corpus.EXCERPTS, hold_guard=None):
        asked.update(folder=folder, only=only, together=together, hand=hand, general=general, excerpts=excerpts)
        asked.update(hold_guard=hold_guard)
        return []

    monkeypatch.setitem(sys.modules, "music21", types.SimpleNamespace(__version__="test"))
    monkeypatch.setattr(corpus, "play_corpus", play_corpus)
    out = tmp_path / "c.json"
    argv = ["corpus", "--out", str(tmp_path), "--only", "aloha-oe", "--apart", "--thumb", "--json", str(out)]
    monkeypatch.setattr(sys, "argv", [*argv, "--general", str(tmp_path / "policy")])
    corpus.main()
    assert asked == {
        "folder": tmp_path,
        "only": ("aloha-oe",),
        "together": False,
        "hand": HandSpec((1, 2, 3, 4)),
        "general": tmp_path / "policy",
        "excerpts": corpus.EXCERPTS,
        "hold_guard": None,
    }
    record = json.loads(out.read_text())
    assert record["apart"] is True and record["thumb"] is True and record["rows"] == []
    assert record["hold_guard"] == "as play plays it"
    assert record["general"] == str(tmp_path / "policy")
    monkeypatch.setattr(sys, "argv", ["corpus", "--out", str(tmp_path)])
    corpus.main()
    assert asked["together"] is True and asked["hand"] is None and asked["only"] == ()
    assert asked["general"] is None
    assert json.loads(out.read_text())["thumb"] is True  # (no --json: the record is not written again)
    monkeypatch.setattr(sys, "argv", ["corpus", "--out", str(tmp_path), "--no-thumb", "--json", str(out)])
    corpus.main()
    assert asked["hand"] == HandSpec() and json.loads(out.read_text())["thumb"] is False
    monkeypatch.setattr(sys, "argv", ["corpus", "--out", str(tmp_path), "--no-hold-guard", "--json", str(out)])
    corpus.main()
    assert asked["hold_guard"] is False and json.loads(out.read_text())["hold_guard"] is False
    monkeypatch.setattr(sys, "argv", ["corpus", "--set", "validation"])
    corpus.main()
    assert asked["excerpts"] == corpus.VALIDATION and asked["folder"] == Path("out/corpus-validation")
    assert not {name for name, *_ in corpus.VALIDATION} & {name for name, *_ in corpus.EXCERPTS}
    assert not {path for _, path, *_ in corpus.VALIDATION} & {path for _, path, *_ in corpus.EXCERPTS}
    monkeypatch.setattr(sys, "argv", ["corpus", "--set", "more"])
    corpus.main()
    assert asked["excerpts"] == corpus.MORE and asked["folder"] == Path("out/corpus-more")
    paths = {path for _, path, *_ in corpus.MORE}
    assert len(paths) == len(corpus.MORE) == 35  # (a second test set: none of the others' pieces)
    assert not paths & {path for _, path, *_ in corpus.EXCERPTS + corpus.VALIDATION}
    monkeypatch.setattr(sys, "argv", ["corpus", "--set", "reductions"])
    corpus.main()
    assert asked["excerpts"] == corpus.REDUCTIONS and asked["folder"] == Path("out/corpus-reductions")
    third = {path for _, path, *_ in corpus.REDUCTIONS}
    assert len(third) == len(corpus.REDUCTIONS) == 12
    assert not third & {path for _, path, *_ in corpus.EXCERPTS + corpus.VALIDATION + corpus.MORE}
    # (a test set of music the policies never learnt from: none of the training pieces' composers)
    assert not {path.split("/")[0] for path in third} & {"bach", *corpus.QUARTETS}


def test_the_corpus_plays_the_general_policy_alone_with_no_hold_guard(monkeypatch, tmp_path):
    """play_corpus hands --hold-guard/--no-hold-guard to the general policy's player only (the
    scripted pianist has no guard; the excerpt's writing and reading stood in for)."""
    import types

    from benchmarks import corpus
    from pianobot.music.instrument import HandSpec
    from pianobot.music.piece import Note, Piece

    played = []
    piece = Piece.of([Note(0.0, 60, 0.5, 80, None, "right"), Note(0.0, 48, 0.5, 80, None, "left")])
    monkeypatch.setattr(corpus, "write_excerpt", lambda path, parts, first, out: {"source": path, "measures": "1-2"})
    monkeypatch.setattr(corpus, "two_hands", lambda file, options, fingers: types.SimpleNamespace(piece=piece))

    def figures(piece, controller, models, general=None, together=True, hold_guard=None, seed=0, hand=None):
        played.append((controller, hold_guard))
        return {"f1": 1.0, "given": len(piece)}

    monkeypatch.setattr(corpus, "figures", figures)
    five = HandSpec((1, 2, 3, 4, 5), model="pianist")
    excerpt = corpus.EXCERPTS[:1]
    for guard in (None, False, True):
        corpus.play_corpus(tmp_path, hand=five, general=tmp_path, excerpts=excerpt, hold_guard=guard)
    assert played == [
        ("sac", None),
        ("scripted", None),
        ("sac", False),
        ("scripted", None),
        ("sac", True),
        ("scripted", None),
    ]


def test_benchmarks_hands_thumb_gives_every_player_and_the_examples_reading_each_hands_thumb(monkeypatch, tmp_path):
    import sys

    from benchmarks import hands
    from pianobot.music.instrument import HandSpec

    asked = []
    monkeypatch.setattr(hands, "figures", lambda *args, hand=None, **kw: asked.append(hand) or {"f1": 1.0})
    monkeypatch.setattr(hands, "table", lambda name, rows, players=None: "")
    monkeypatch.setattr(hands, "example_table", lambda rows: "")
    read = []
    monkeypatch.setattr(hands, "two_hands", lambda path, options, spec: read.append(spec))
    (tmp_path / "x.mid").write_bytes(b"")
    argv = ["hands", "--duets", "1", "--polyphonic", "0", "--examples", str(tmp_path), "--thumb"]
    monkeypatch.setattr(sys, "argv", argv)
    hands.main()
    thumb = HandSpec((1, 2, 3, 4))
    assert read == [thumb]  # (the example file was read for that hand; here it is no two-hand file)
    assert asked == [thumb, thumb]  # both players of the one duet


def test_benchmarks_hands_hand_model_pianist_plays_both_players_with_five_fingers(monkeypatch):
    """The pianist's hand: its packaged parts policy and the scripted pianist play, each with its five fingers."""
    import sys

    from benchmarks import hands
    from pianobot.sim.hand import default_fingers

    asked = []
    monkeypatch.setattr(
        hands, "figures", lambda piece, player, *args, hand=None, **kw: asked.append((player, hand)) or {"f1": 1.0}
    )
    monkeypatch.setattr(hands, "table", lambda name, rows, players=None: "")
    monkeypatch.setattr(sys, "argv", ["hands", "--duets", "1", "--polyphonic", "0", "--hand-model", "pianist"])
    hands.main()
    assert asked == [
        ("sac", default_fingers("pianist")),
        ("scripted", default_fingers("pianist")),
    ]  # (its packaged policy)
