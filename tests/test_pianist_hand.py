"""The pianist's hand (``--hand-model pianist``): five fingers of human size, a thumb that passes
under the fingers, chosen on the command line and recorded in every report."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from conftest import assert_one_line_error, run

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.piece import Note, Piece
from pianobot.perform.plan import perform_plan, plan_performance
from pianobot.pianist.fingering import Planner, plan_fingering
from pianobot.pianist.tuning import PianistTuning, tuning_for
from pianobot.sim.hand import ALLEGRO, HandConfig, HandModel, default_fingers, hand_config, joint_limits
from pianobot.sim.keyboard import KeyboardConfig
from pianobot.sim.pianist_hand import PIANIST
from pianobot.sim.world import PianoWorld, WorldConfig

FIVE = default_fingers("pianist")


def _scale(seconds: float = 0.3) -> Piece:
    """C major up an octave and down again, one note every ``seconds``."""
    up = [60, 62, 64, 65, 67, 69, 71, 72]
    pitches = up + up[-2::-1]
    return Piece(tuple(Note(seconds * i, p, seconds * (i + 1), 80) for i, p in enumerate(pitches)), bpm=100)


def test_the_pianist_s_hand_has_five_fingers_a_white_key_apart_and_a_thumb_that_turns_farther():
    assert FIVE == HandSpec((1, 2, 3, 4, 5), model="pianist")
    gaps = [b - a for a, b in zip(PIANIST.fingers[:-1], PIANIST.fingers[1:])]
    assert gaps == [1, 1, 1, 1]
    spacing = [PIANIST.base_x(f + 1) - PIANIST.base_x(f) for f in (1, 2, 3, 4)]
    assert spacing == pytest.approx([0.022] * 4)  # the Shadow hand's knuckles, 22 mm apart
    low, high = joint_limits(hand_config(FIVE))
    assert high[0] == pytest.approx(0.6) and high[4] == pytest.approx(PIANIST.geometry.abduction_limit)  # thumb, index
    config = hand_config(FIVE)
    assert (config.palm_height, config.max_joint_speed) == (0.0575, 8.0)  # the model's body, not the Allegro's
    assert hand_config(HandSpec()).palm_height == 0.070


def test_its_world_builds_five_fingers_and_its_mirror_image_for_the_left_hand():
    world = PianoWorld(WorldConfig(hand=hand_config(FIVE), keyboard=KeyboardConfig(spec=KeyboardSpec(36, 48))))
    try:
        assert sorted(world.hands[0].tips) == [1, 2, 3, 4, 5] and len(world.finger_joints) == 20
    finally:
        world.close()


@pytest.mark.parametrize("seconds", [0.15, 0.3, 1.0])
def test_the_planner_passes_the_thumb_under_in_a_scale_where_the_allegro_hand_cannot(seconds):
    fingers = [n.finger for n in plan_fingering(_scale(seconds), KeyboardConfig(), hand_config(FIVE)).piece.notes]
    assert fingers[:8] == [1, 2, 3, 1, 2, 3, 4, 5]  # the thumb under after E, as pianists finger it
    assert fingers[8:] == [4, 3, 2, 1, 3, 2, 1]  # and the third finger over it on the way down
    planner = Planner(KeyboardConfig(), hand_config(FIVE))
    assert (1, 3) in planner.passes and (3, 1) in planner.passes and (4, 5) not in planner.passes
    assert Planner().passes == set()  # the Allegro-like hand: no finger passes another, as before


def test_a_thumb_that_stretches_as_dearly_as_a_finger_shifts_the_hand_in_a_slow_scale_instead():
    """``thumb_stretch`` is what turns the thumb under: at the fingers' full stretch cost a slow
    scale is played by shifting the whole hand after the fifth finger (1 2 3 4 5 3 4 5 ...)."""
    assert tuning_for(hand_config(FIVE)).thumb_stretch == 0.5 and PianistTuning().thumb_stretch == 1.0
    dear = replace(tuning_for(hand_config(FIVE)), thumb_stretch=1.0)
    plan = Planner(KeyboardConfig(), hand_config(FIVE), dear).plan(_scale(0.3))
    fingers = [n.finger for n in plan.piece.notes]
    assert fingers[:5] == [1, 2, 3, 4, 5] and 1 not in fingers[5:8] and plan.moves >= 1  # no thumb under: a shift


def test_a_model_refuses_passes_between_fingers_it_lacks():
    with pytest.raises(ValueError, match="passes"):
        HandModel(name="bad", bases=ALLEGRO.bases, finger_sets=((2, 3, 4),), passes=frozenset({(1, 5)}))


def test_the_scripted_pianist_plays_the_scale_with_the_thumb_under():
    piece = plan_fingering(_scale(), KeyboardConfig(), hand_config(FIVE)).piece
    assert [n.finger for n in piece.notes][:4] == [1, 2, 3, 1]
    performance = perform_plan(plan_performance(piece, "scripted", hand=FIVE))
    report = performance.report()
    assert report.f1 == 1.0 and report.fingering_accuracy == 1.0


def test_the_planner_uses_95_percent_of_the_pianist_s_reach_and_75_of_the_allegro_s():
    forward = {
        hand: config.palm_y - 0.110 for hand, config in (("allegro", HandConfig()), ("pianist", hand_config(FIVE)))
    }
    allegro, pianist = Planner(), Planner(KeyboardConfig(), hand_config(FIVE))
    white = int(np.flatnonzero(~allegro.black)[0])
    assert allegro.reach[2][white] == pytest.approx(0.75 * forward["allegro"] * math.tan(0.47), abs=1e-12)
    assert pianist.reach[5][white] == pytest.approx(0.95 * forward["pianist"] * math.tan(0.349), abs=1e-12)
    assert pianist.reach[1][white] == pytest.approx(0.95 * forward["pianist"] * math.tan(0.6), abs=1e-12)


def _fifth() -> list[Note]:
    return [Note(0.0, 60, 0.5, 80), Note(0.0, 67, 0.5, 80)]  # C4 and G4: a fifth, four white keys apart


def test_a_fifth_with_fingers_2_and_5_is_in_the_pianist_s_reach_and_played():
    hand = hand_config(HandSpec((2, 3, 4, 5), model="pianist"))  # without the thumb: only 2 and 5 span a fifth
    assert Planner(KeyboardConfig(), hand).place(_fifth()).possible
    narrow = replace(tuning_for(hand), reach_fraction=0.75)  # the margin before: a fifth 2-5 out of reach
    assert not Planner(KeyboardConfig(), hand, narrow).place(_fifth()).possible
    chords = [
        replace(n, onset=n.onset + 0.8 * i, offset=n.offset + 0.8 * i, finger=f)
        for i in range(3)
        for n, f in zip(_fifth(), (2, 5))
    ]
    report = perform_plan(plan_performance(Piece(tuple(chords), bpm=100), "scripted", hand=FIVE)).report()
    assert report.f1 == 1.0


def test_hand_model_pianist_plays_with_five_fingers_and_the_report_says_so(tmp_path):
    out = tmp_path / "out.mid"
    result = run(
        "play", "examples/midi/c-major-scale.mid", "-o", out, "--hand-model", "pianist", "--controller", "scripted"
    )
    assert result.exit_code == 0, result.output
    report = json.loads(out.with_suffix(".report.json").read_text())
    assert report["hand_model"] == "pianist" and report["fingers"] == [1, 2, 3, 4, 5]
    assert report["f1"] >= 0.9


def test_thumb_options_belong_to_the_allegro_hand(tmp_path):
    result = run("play", "examples/midi/mary.mid", "-o", tmp_path / "o.mid", "--hand-model", "pianist", "--no-thumb")
    assert_one_line_error(result, "--no-thumb", "leave --thumb/--no-thumb out")
    assert run("play", "examples/midi/mary.mid", "--hand-model", "shadow").exit_code == 2


def test_a_file_s_own_five_finger_fingering_plays_as_written_on_the_pianist_s_hand(tmp_path):
    """The file's fingering, written for a human hand (the thumb under after E), is the pianist's
    hand's own: played as written. The Allegro-like hand cannot play it as written: one line
    says so, and how to play it (its planner's fingering, or the pianist's hand)."""
    from pianobot.music.midi_out import write_midi
    from pianobot.music.pig import sidecar_for, write_pig

    written = [1, 2, 3, 1, 2, 3, 4, 5, 4, 3, 2, 1, 3, 2, 1]
    piece = _scale().with_fingers(written)
    song = write_midi(piece.without_fingering(), tmp_path / "scale.mid")
    write_pig(piece, sidecar_for(song))
    out = tmp_path / "out.mid"
    result = run("play", song, "-o", out, "--hand-model", "pianist", "--controller", "scripted", "--notes", "0")
    assert result.exit_code == 0, result.output
    report = json.loads(out.with_suffix(".report.json").read_text())
    assert report["f1"] == 1.0 and report["fingering_accuracy"] == 1.0
    assert [row["played_finger"] for row in report["notes"]] == written
    result = run("play", song, "-o", tmp_path / "allegro.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert_one_line_error(result, "fingered 1 (thumb)", "--refinger", "--hand-model pianist")
    # no hand model named: a fingering for five fingers is the pianist's hand's, played as written (it was refused)
    result = run("play", song, "-o", out, "--controller", "scripted", "--notes", "0")
    assert result.exit_code == 0, result.output
    assert [row["played_finger"] for row in json.loads(out.with_suffix(".report.json").read_text())["notes"]] == written


def test_a_fully_fingered_file_the_pianist_s_hand_cannot_play_as_written_keeps_every_mark_it_can(tmp_path):
    """C4 with the middle finger under E4 with the index (fingers that would cross): the planner fingers
    that chord anew and keeps the file's other marks, in one line (played as written before, two of its
    four notes sounded, note F1 0.571). A fingering it can play stays as written, and so do marks only its
    speed is against; the Allegro-like hand, whose fingers are no human's, keeps a full fingering as it always has."""
    from pianobot.music.pig import write_pig
    from pianobot.pianist.fingering import ensure_fingering

    crossed = Piece((Note(0.0, 60, 0.5, finger=3), Note(0.0, 64, 0.5, finger=2), Note(0.5, 67, 1.0, finger=5),
                     Note(1.0, 72, 1.5, finger=5)))  # fmt: skip
    fingered, plan = ensure_fingering(crossed, KeyboardSpec(), FIVE)
    assert plan is not None and [n.finger for n in fingered.notes][2:] == [5, 5]
    assert fingered.notes[0].finger < fingered.notes[1].finger  # (pitch order)
    scale = _scale().with_fingers([1, 2, 3, 1, 2, 3, 4, 5, 4, 3, 2, 1, 3, 2, 1])
    assert ensure_fingering(scale, KeyboardSpec(), FIVE) == (scale, None)
    # soft repeats by one finger, faster than the planner times them: kept (the scripted pianist plays them)
    repeats = Piece(tuple(Note(0.15 * i, 60, 0.15 * i + 0.12, 30, 2) for i in range(8)))
    timed = Planner(KeyboardConfig(), hand_config(FIVE)).plan(repeats)  # (as a partly fingered part's marks are)
    assert [n.finger for n in timed.piece.notes] != [2] * 8
    assert ensure_fingering(repeats, KeyboardSpec(), FIVE) == (repeats, None)
    assert ensure_fingering(crossed, KeyboardSpec(), HandSpec()) == (crossed, None)
    # the notes fingered anew are fingered in time: the thumb, D4's own at 0.1 s, is not given C4 too
    quick = Piece((Note(0.0, 60, 0.1, finger=3), Note(0.0, 64, 0.1, finger=2), Note(0.1, 62, 0.3, finger=1)))
    assert [n.finger for n in ensure_fingering(quick, KeyboardSpec(), FIVE)[0].notes][0] != 1
    # C4 held under A5, two octaves up: no fingering of the planner's plays it, so it plays as written, as before
    held = Piece((Note(0.0, 60, 0.7, finger=2), Note(0.5, 81, 1.0, finger=5), Note(0.7, 60, 1.0, finger=3)))
    assert ensure_fingering(held, KeyboardSpec(), FIVE) == (held, None)

    from pianobot.perform.together import play_hands

    both = Piece.of([*(replace(n, hand="right") for n in crossed.notes), Note(0.0, 48, 1.0, 80, 5, "left")])
    with pytest.warns(
        PianobotWarning, match="the right hand's part: this hand cannot play all of its fingering; kept 3"
    ):
        played = play_hands(both, "scripted", hand=FIVE, seed=0)
    assert played.report().f1 == 1.0 and [n.finger for n in played.hands[1].part.notes] == [5]
    partly = Piece.of([replace(n, finger=None) if n.pitch == 67 else n for n in both.notes])  # (one mark less)
    with pytest.warns(
        PianobotWarning, match="the right hand's part: this hand cannot play all of its fingering; kept 2 of"
    ):
        play_hands(partly, "scripted", hand=FIVE, seed=0)

    song = write_pig(crossed, tmp_path / "crossed.txt")
    out = tmp_path / "out.mid"
    result = run("play", song, "-o", out, "--hand-model", "pianist", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    assert "this hand cannot play all of its fingering; kept 3 of its 4 fingering marks" in result.output
    assert "pianobot finger" not in result.output  # (it would write the planner's own fingering, marks aside)
    assert json.loads(out.with_suffix(".report.json").read_text())["f1"] == 1.0


def test_under_position_control_each_finger_is_commanded_within_its_own_limits():
    """The thumb turns farther than the fingers: position commands map each finger's angles to its
    own limits (on the thumb's scale an index at its limit would be commanded short of it)."""

    import numpy as np

    from pianobot.pianist.layout import KeyLayout
    from pianobot.pianist.motion import Motion
    from pianobot.pianist.tuning import tuning_for

    world = WorldConfig(hand=hand_config(FIVE), control="position")
    motion = Motion(world, KeyLayout(world), tuning_for(world.hand))
    assert motion.limits[1][1][0] == pytest.approx(0.6) and motion.limits[2][1][0] == pytest.approx(0.349)
    index_at_limit = np.array([0.349, 0.5, 0.5, 0.5])
    command = motion._finger_command(2, None, index_at_limit, wrist_next=0.1)
    assert command[0] <= 1.0 and command[0] > 0.5  # near its own upper limit (+1), not mid-range on the thumb's


def test_a_partly_fingered_part_keeps_its_marks_on_the_pianist_s_hand_and_not_on_the_allegro_s():
    """Pianists mark a few fingers (the thumb under at F); the planner fills the rest around them.
    The Allegro-like hand's fingers are no human's: it plans anew, as it always has."""
    from pianobot.pianist.fingering import ensure_fingering

    marks = {0: 1, 3: 1, 7: 5, 9: 3}  # C thumb, F thumb (under), top C little finger, A on the way down middle
    scale = _scale(0.3)
    marked = scale.with_fingers([marks.get(i) for i in range(len(scale))])
    fingered, plan = ensure_fingering(marked, KeyboardSpec(), FIVE)
    assert plan is not None and all(fingered.notes[i].finger == f for i, f in marks.items())
    assert (
        ensure_fingering(marked, KeyboardSpec(), FIVE, refinger=True)[0]
        == ensure_fingering(scale, KeyboardSpec(), FIVE)[0]
    )
    allegro = HandSpec()
    assert ensure_fingering(marked, KeyboardSpec(), allegro)[0] == ensure_fingering(scale, KeyboardSpec(), allegro)[0]


def test_both_hands_play_the_file_s_own_marks_on_the_pianist_s_hand():
    from pianobot.perform.together import play_hands

    right = [Note(0.3 * i, p, 0.3 * i + 0.28, 80, f, "right") for i, (p, f) in
             enumerate(zip([60, 62, 64, 65, 67, 69, 71, 72], [1, None, None, 1, None, None, None, 5]))]  # fmt: skip
    left = [Note(0.6 * i, p, 0.6 * i + 0.55, 70, f, "left") for i, (p, f) in
            enumerate(zip([48, 52, 55, 48], [5, 3, 1, None]))]  # fmt: skip
    played = play_hands(Piece.of(right + left), "scripted", hand=FIVE, seed=0)
    report = played.report()
    assert report.f1 == 1.0 and report.fingering_accuracy == 1.0  # over the marked notes
    parts = {h.hand: [n.finger for n in h.part.notes] for h in played.hands}
    assert parts["right"][:4] == [1, 2, 3, 1] and parts["left"][:3] == [5, 3, 1]


def test_the_pianist_s_planner_leaves_one_control_step_around_a_wrist_move_and_the_allegro_s_four():
    """A C major scale in semiquavers at 120 bpm (0.125 s a note) needs its wrist moves between two
    notes: the pianist's planner fingers it whole, where with the Allegro-like hand's 0.2 s of
    settling every move would be too fast (and the reduction would drop notes)."""
    from pianobot.pianist.tuning import PianistTuning

    assert tuning_for(hand_config(FIVE)).settle_time == 0.05 and tuning_for(HandConfig()).settle_time == 0.2
    assert PianistTuning().settle_time == 0.2
    quick = Planner(KeyboardConfig(), hand_config(FIVE)).plan(_scale(0.125))
    assert quick.problems == () and quick.moves >= 2
    slow = replace(tuning_for(hand_config(FIVE)), settle_time=0.2)
    assert Planner(KeyboardConfig(), hand_config(FIVE), slow).plan(_scale(0.125)).problems


def test_an_alberti_bass_in_semiquavers_plays_whole_because_the_wrist_waits_for_a_striking_thumb(monkeypatch):
    """C3 G3 E3 G3 ... B2 G3 D3 G3 at 0.125 s a note: the thumb strikes B2 turned towards it, the
    little finger on G3 a sixth above. A wrist sliding straight over B2 while the thumb goes down
    dragged the thumb off its key (its abduction lags a 29 mm step), so the wrist moves at most
    ``strike_slide`` a step while a fingertip is on its way into its key (the Allegro-like hand's
    wrist: unlimited, as before). Since the little finger strikes its repeated G3 from just over where
    the key let it go (``repeat_rise``), the wrist no longer slides there as the thumb goes down, nor
    where a lone strike may begin before the wrist is in place (``lone_strike_wrist_steps``); the slide is
    shown with the repeats struck from the ready height and the wrist in place first, as they were."""
    from benchmarks.semiquavers import alberti, line, play

    assert tuning_for(hand_config(FIVE)).strike_slide == 0.004 and tuning_for(HandConfig()).strike_slide == math.inf
    assert play(line(alberti(), 0.125), FIVE) == (0, 1.0)
    import pianobot.pianist.scripted as scripted

    unlimited = scripted.tuning_for
    as_before = {"repeat_rise": math.inf, "lone_strike_wrist_steps": 0}
    monkeypatch.setattr(scripted, "tuning_for", lambda hand: replace(unlimited(hand), **as_before))
    assert play(line(alberti(), 0.125), FIVE) == (0, 1.0)
    as_before["strike_slide"] = math.inf
    problems, f1 = play(line(alberti(), 0.125), FIVE)
    assert problems == 0 and f1 < 1.0  # the wrist sliding under the thumb: a note lost


def test_a_held_key_is_let_go_in_time_for_its_finger_s_far_move_to_strike_on_time():
    """Four chords of the upper voices of Bach's chorale BWV 81.7 (the right hand's, as `play` gives
    them to it): the little finger holds G5, then strikes F#5, drawing back into the black keys' band.
    Counting a fingertip's whole positioning move a step, the scripted pianist let G5 go too late and
    F#5 sounded 100 ms late; counting three quarters (the pianist's ``travel_share``) it is on time."""
    from pianobot.perform.perform import PLAY_CONFIG, perform
    from pianobot.pianist.scripted import ScriptedPianist

    hand = hand_config(FIVE)
    config = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand))
    chords = [(71, 0.0, 0.5, 1), (76, 0.0, 0.5, 4), (71, 0.5, 1.0, 1), (79, 0.5, 1.0, 5)]
    chords += [(72, 1.0, 1.5, 2), (78, 1.0, 1.5, 5), (71, 1.5, 1.6, 1), (78, 1.5, 1.6, 5)]
    piece = Piece(tuple(Note(onset, pitch, end, 80, finger) for pitch, onset, end, finger in chords), bpm=60)
    assert tuning_for(hand).travel_share == 0.75 and PianistTuning().travel_share == 1.0  # (the Allegro-like hand's)

    def played(share: float):
        tuning = replace(tuning_for(hand), travel_share=share)
        return perform(piece, lambda env: ScriptedPianist(env.config, tuning), config).report()

    assert played(0.75).f1 == 1.0
    late = played(1.0)
    assert [(r.reference.pitch, r.reference.onset) for r in late.rows if r.played is None] == [(78, 1.0)]


def test_a_chord_whose_finger_must_move_the_wrist_for_its_own_next_note_is_held_until_that_move_begins():
    """C4 E4 G4 held by fingers 1, 3 and 5, then the little finger's own next note, D5, a ninth above the
    thumb's C4, out of the hand's reach while the chord is held: every key of the chord lets go for it.
    The pianist's hand lets go when the little finger's way there must begin (``lift_steps`` 0: that way
    starts with its rise, and the wrist slides while the finger moves on), a control step later than
    counting one more step for the rise before it (1, the Allegro-like hand's), and D5 still sounds on time."""
    from pianobot.perform.perform import PLAY_CONFIG, perform
    from pianobot.pianist.scripted import ScriptedPianist

    hand = hand_config(FIVE)
    config = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand))
    chord = [Note(0.0, pitch, 1.0, 80, finger) for pitch, finger in ((60, 1), (64, 3), (67, 5))]
    piece = Piece((*chord, Note(1.0, 74, 1.5, 80, 5)), bpm=60)
    assert tuning_for(hand).lift_steps == 0 and PianistTuning().lift_steps == 1

    def played(lift: int):
        tuning = replace(tuning_for(hand), lift_steps=lift)
        report = perform(piece, lambda env: ScriptedPianist(env.config, tuning), config).report()
        assert report.f1 == 1.0 and max(abs(r.onset_error) for r in report.rows) < 0.03
        return {r.reference.pitch: r.played.offset for r in report.rows}

    now, before = played(0), played(1)
    for pitch in (60, 64, 67):
        assert now[pitch] < 1.0 and now[pitch] - before[pitch] == pytest.approx(0.05, abs=0.01)


def test_a_key_held_before_a_lone_strike_that_moves_the_wrist_is_held_a_step_longer():
    """A4 held by the middle finger, then F4 by the index, a third below: the index reaches F4 from a
    wrist position that keeps A4 held, but the wrist must slide there first. The pianist's hand lets the
    strike begin a step before the wrist has arrived (``lone_strike_wrist_steps`` 1: it slides on as the
    finger goes down), so A4 is held a control step longer than with the wrist there first (0, the
    Allegro-like hand's), and F4 still sounds on time; likewise each note of an arpeggio C4 E4 G4 C5."""
    from pianobot.perform.perform import PLAY_CONFIG, perform
    from pianobot.pianist.scripted import ScriptedPianist

    hand = hand_config(FIVE)
    config = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand))
    assert tuning_for(hand).lone_strike_wrist_steps == 1 and PianistTuning().lone_strike_wrist_steps == 0

    def played(notes, steps: int) -> dict[int, float]:
        piece = Piece(tuple(Note(onset, pitch, end, 80, finger) for pitch, onset, end, finger in notes), bpm=60)
        tuning = replace(tuning_for(hand), lone_strike_wrist_steps=steps, end_rise=math.inf)  # (held to the end)
        report = perform(piece, lambda env: ScriptedPianist(env.config, tuning), config).report()
        assert report.f1 == 1.0 and max(abs(r.onset_error) for r in report.rows) < 0.03
        return {r.reference.pitch: r.played.offset for r in report.rows}

    third = [(69, 0.0, 0.5, 3), (65, 0.5, 1.0, 2)]
    now, before = played(third, 1), played(third, 0)
    assert now[69] - before[69] == pytest.approx(0.05, abs=0.01) and now[69] > 0.5 - 0.01
    arpeggio = [(60, 0.0, 0.4, 1), (64, 0.4, 0.8, 2), (67, 0.8, 1.2, 3), (72, 1.2, 1.6, 5)]
    now, before = played(arpeggio, 1), played(arpeggio, 0)
    assert [round(now[p] - before[p], 2) for p in (64, 67)] == [0.05, 0.05]


def test_a_held_key_rises_a_little_in_its_note_s_last_step_so_the_note_ends_on_time():
    """The pianist's hand lets a held key rise to 1 mm under the depth where it lets its note go in the
    note's last control step (``end_rise``), so that its note ends within the step's rounding of its
    written end; held at full depth to the end (``math.inf``, the Allegro-like hand's), a note with no
    note of its finger after it sounded 33 ms past its end. A note whose key is struck again right after
    it keeps its end: the score's gap before the repeat already lets that key rise."""
    from pianobot.perform.perform import PLAY_CONFIG, perform
    from pianobot.pianist.scripted import ScriptedPianist

    hand = hand_config(FIVE)
    config = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand))
    assert tuning_for(hand).end_rise == 0.001 and PianistTuning().end_rise == math.inf

    def ends(notes, rise: float) -> list[float]:
        piece = Piece(tuple(Note(onset, pitch, end, velocity, finger) for pitch, onset, end, finger, velocity in notes))
        tuning = replace(tuning_for(hand), end_rise=rise)
        report = perform(piece, lambda env: ScriptedPianist(env.config, tuning), config).report()
        assert report.f1 == 1.0
        return [r.played.offset - r.reference.offset for r in sorted(report.rows, key=lambda r: r.reference.onset)]

    line = [
        (60, 0.0, 0.5, 1, 80),
        (64, 0.5, 1.0, 3, 80),
        (67, 1.0, 1.5, 5, 40),
        (65, 1.5, 2.0, 4, 110),
        (61, 2.0, 2.5, 2, 80),
    ]
    now, before = ends(line, 0.001), ends(line, math.inf)
    assert max(abs(e) for e in now) < 0.025 and before[-1] > 0.025
    repeat = [(60, 0.0, 0.5, 3, 80), (60, 0.5, 1.0, 3, 80)]
    assert ends(repeat, 0.001)[0] == pytest.approx(ends(repeat, math.inf)[0], abs=0.002)
