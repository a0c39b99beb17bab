"""Both hands of a piece played (pianobot/perform/together.py): in one simulation and hand by hand, and the random two-hand
pieces they are measured on (pianobot/music/duets.py)."""

import itertools
import warnings
from pathlib import Path

import numpy as np
import pytest

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.duets import TEXTURES, duet_set, random_duet
from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable
from pianobot.music.piece import Note, Piece
from pianobot.music.window import Window, window_for
from pianobot.perform.together import play_hands

BLACK = {1, 3, 6, 8, 10}


@pytest.mark.parametrize("hand", ["right", "left"])
def test_a_window_maps_written_keys_onto_the_simulated_hand_and_back_keeping_their_colour(hand):
    window = Window(hand, KeyboardSpec(), -2)
    for pitch in range(21, 104):
        inside = window.inward(pitch)
        assert window.outward(inside) == pitch
        assert (inside % 12 in BLACK) == (pitch % 12 in BLACK)
    # the left hand's lowest note is the simulated right hand's highest: the mirror, not a shift
    assert Window("left", KeyboardSpec(), 0).inward(36) > Window("left", KeyboardSpec(), 0).inward(48)


def test_a_window_says_which_written_keys_it_plays_and_which_way_it_moved_them():
    """What a hand's row says ('played as'): the piece's own keys, not its player's (a left hand's
    player on C4-B5 plays the left hand's F2-E4), and the octave move in the piece's terms."""
    keys = KeyboardSpec(60, 24)  # C4-B5, the player's keys
    assert Window("right", keys, 0).written_keys() == keys and Window("right", keys, 0).moved() == ""
    assert Window("left", keys, 0).written_keys() == KeyboardSpec(41, 24)  # F2-E4
    # moved up onto the player's keys: the right hand's part was written an octave lower than its player's keys ...
    assert Window("right", keys, 1).written_keys() == KeyboardSpec(48, 24)
    assert Window("right", keys, 1).moved() == "its player's keys 1 octave up"
    # ... and the left hand's mirror image moved up stands for keys an octave higher than its unmoved
    # mirror image (F2-E4): its player's keys lie an octave below the part's
    assert Window("left", keys, 1).written_keys() == KeyboardSpec(53, 24)  # F3-E5
    assert Window("left", keys, 1).moved() == "its player's keys 1 octave down"
    for window in (Window("left", keys, -2), Window("right", keys, 3)):
        written = sorted(window.outward(key) for key in keys.pitches)
        assert KeyboardSpec(written[0], len(written)) == window.written_keys()  # every key, end to end
    assert Window("right", keys, -2).moved() == "its player's keys 2 octaves down"


def test_the_window_keeps_the_most_notes_on_the_keyboard_the_player_knows():
    bass = Piece(tuple(Note(i, p, i + 0.9, hand="left") for i, p in enumerate([36, 40, 43, 48, 55])))
    window = window_for(bass, "left", KeyboardSpec())  # mirrored: E6 C6 A5 E5 A4; C4-B5 is known

    def kept(octaves: int) -> int:
        return sum(Window("left", KeyboardSpec(), octaves).inward(n.pitch) in KeyboardSpec() for n in bass.notes)

    assert kept(window.octaves) == 4 and all(kept(k) < 4 for k in range(-5, 6) if k != window.octaves)
    wide = Piece(tuple(Note(i, p, i + 0.9, hand="right") for i, p in enumerate([48, 60, 72, 84])))
    window = window_for(wide, "right", KeyboardSpec())
    assert sum(window.inward(n.pitch) in KeyboardSpec() for n in wide.notes) == 2  # 36 keys span, 24 known
    # the scripted pianist's window is the part's own range, rounded out to octaves
    own = window_for(wide, "right", None)
    assert (own.keyboard.lowest, own.keyboard.highest, own.octaves) == (48, 95, 0)


def test_parts_down_to_a0_and_up_to_c8_are_played_on_the_pianos_keys_in_one_simulation():
    """Rounded out to octaves past A0 and C8, the windows spanned 103 keys together, and the hands
    were played apart, each in a simulation of its own."""
    from pianobot.env.two_hands import world_keyboard

    right = Piece((Note(0, 71, 1, hand="right"), Note(1, 108, 2, hand="right")))  # B4, C8
    left = Piece((Note(0, 21, 1, hand="left"), Note(1, 67, 2, hand="left")))  # A0, G4
    windows = [window_for(right, "right", None), window_for(left, "left", None)]
    assert world_keyboard(windows) == KeyboardSpec(21, 88)
    assert [w.keyboard.describe() for w in windows] == ["C4-C8 (49 keys)", "C3-G7 (56 keys)"]  # the left's mirrored


def test_the_scripted_pianist_plays_both_hands_of_a_duet_at_the_written_pitches():
    (name, piece), *_ = [d for d in duet_set(0, 8) if "broken" in d[0]]
    performance = play_hands(piece, "scripted")
    assert [h.hand for h in performance.hands] == ["right", "left"]
    played = performance.played
    assert {n.hand for n in played.notes} == {"right", "left"}
    assert max(n.pitch for n in played.part("left").notes) < 60 <= min(n.pitch for n in played.part("right").notes)
    assert performance.report("left").f1 == 1.0 and performance.report("right").f1 == 1.0, name
    assert performance.report().reference_notes == len(piece)


def test_what_each_hand_was_given_reads_back_at_the_written_pitches_and_scores_what_the_reduction_left():
    """The given notes (mirrored, moved and reduced for the hand) back at the written pitches and times:
    a duet the hands play as written is given whole; a note held under a two-octave leap is given
    ending where the leap begins, which its note F1 keeps and its offsets and per-step F1 do not; a
    piece that begins after a rest is given at its own times."""
    (name, piece), *_ = [d for d in duet_set(0, 8) if "broken" in d[0]]
    performance = play_hands(piece, "scripted")
    given = {(n.pitch, round(n.onset, 6), n.hand) for h in performance.hands for n in h.given.notes}
    assert given == {(n.pitch, round(n.onset, 6), n.hand) for n in piece.notes}, name
    whole = performance.given_report()
    assert (whole.f1, whole.f1_with_offsets, whole.step_f1) == (1.0, 1.0, 1.0)

    leap = Piece(  # (beginning after a rest: the hands' parts are moved to start at 0, and back)
        (
            Note(1.0, 60, 3.0, hand="right"),
            Note(1.5, 84, 2.0, hand="right"),
            Note(1.0, 48, 2.0, hand="left"),
        )
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        performance = play_hands(leap, "scripted")
    held = [n for n in performance.hands[0].given.notes if n.pitch == 60]
    assert [(n.onset, n.offset) for n in held] == [(1.0, 1.5)]
    whole = performance.given_report()
    assert whole.f1 == 1.0 and whole.f1_with_offsets < 1.0 and whole.step_f1 < 1.0


def test_both_hands_share_one_simulation_unless_asked_apart_and_play_alike_there():
    (name, piece), *_ = [d for d in duet_set(2, 8) if "block" in d[0]]
    together = play_hands(piece, "scripted")
    apart = play_hands(piece, "scripted", together=False)
    assert together.together and not apart.together and "one simulation" in together.performer
    assert "simulation of its own" in apart.performer
    for performance in (together, apart):
        assert performance.report("right").f1 == 1.0 and performance.report("left").f1 == 1.0, name
    # the right hand's notes are the right hand's: none credited to the other in one world
    assert {(n.pitch, n.hand) for n in together.played.notes} == {(n.pitch, n.hand) for n in piece.notes}


def test_parts_too_far_apart_for_one_keyboard_play_apart_and_say_so():
    """A general policy's window is the keys it knows (C4-B5 here) moved by octaves: C8 on them
    stands for written keys up to B8, A0 (mirrored) for keys down to F-1, more than 88 together, so
    each hand plays in a simulation of its own. (The scripted pianist's windows, the parts' own
    ranges, stay on the piano's keys: the test above.)"""
    piece = Piece((Note(0.0, 108, 0.5, hand="right"), Note(0.0, 21, 0.5, hand="left")))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        performance = play_hands(piece, "sac", keyboard=KeyboardSpec())
    said = [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]
    assert any("more than a piano's 88" in line and "simulation of its own" in line for line in said), said
    assert not performance.together and performance.report().f1 == 1.0
    # each row names the written keys its window stands for, and where its player's keys lie from them
    right, left = sorted(performance.hands, key=lambda h: h.hand != "right")
    assert right.describe() == "on C7-B8 (24 keys), its player's keys 3 octaves down"
    assert left.describe() == "mirrored about D, on F0-E2 (24 keys), its player's keys 2 octaves up"


def test_notes_outside_the_keys_named_are_said_and_count_as_missed():
    notes = [Note(0.5 * i, p, 0.5 * i + 0.4, hand="right") for i, p in enumerate([36, 62, 64, 65, 67, 96])]
    piece = Piece(tuple(notes))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        performance = play_hands(piece, "sac", keyboard=KeyboardSpec())  # (the keys named: --lowest-note/--keys)
    said = [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]
    assert any("left out 2 note(s)" in line for line in said), said
    (right,) = performance.hands
    assert right.left_out == 2 and len(right.part) == 4
    report = performance.report()
    assert report.reference_notes == 6 and report.recall <= 4 / 6


def test_a_part_wider_than_the_policys_keys_is_played_whole_on_its_own_octaves():
    """By default the general policy is given a part wider than its 24 keys on the part's own range
    (it plays any keyboard of at least its keys): nothing is left out, and it plays the notes
    beyond its 24 keys."""
    pitches = [55, 62, 64, 65, 67, 72, 76, 79, 81]  # G3-A5: no 24 keys of whole octaves hold it
    notes = [Note(0.6 * i, p, 0.6 * i + 0.5, 80, hand="right") for i, p in enumerate(pitches)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        performance = play_hands(Piece(tuple(notes), bpm=100), "sac")
    assert not [w for w in caught if "left out" in str(w.message)]
    (right,) = performance.hands
    assert right.left_out == 0 and right.describe() == "on C3-B5 (36 keys)"
    assert right.performance.plan.config.world.keyboard.spec == KeyboardSpec(48, 36)
    assert right.performer.startswith("general policy task-parts-")
    played = {n.pitch for n in performance.played.notes}
    assert {55, 81} <= played and performance.report().f1 >= 0.85  # (G3 and A5: 26 keys apart)


def test_a_policy_that_reads_no_key_count_plays_any_keyboard_of_at_least_its_keys(tmp_path):
    from dataclasses import replace

    from pianobot.agent.general import PACKAGED, PARTS_KEY, find_general, plays_keyboard
    from pianobot.agent.policy import policy_configs

    env, sac = policy_configs(next(PACKAGED.glob(f"{PARTS_KEY}-*")))
    wide, narrow = KeyboardSpec(48, 36), KeyboardSpec(60, 12)
    assert plays_keyboard(env, sac, wide) and not plays_keyboard(env, sac, narrow)
    assert not plays_keyboard(env, replace(sac, score_input=True), wide)  # a score window's size is the keys'
    assert not plays_keyboard(replace(env, key_observations=True), sac, wide)
    assert plays_keyboard(env, replace(sac, score_input=True), env.world.keyboard.spec)
    on_wide = replace(env, world=replace(env.world, keyboard=replace(env.world.keyboard, spec=wide)))
    assert find_general(tmp_path, on_wide) is not None  # a run on 36 keys starts from the packaged policy
    on_narrow = replace(env, world=replace(env.world, keyboard=replace(env.world.keyboard, spec=narrow)))
    assert find_general(tmp_path, on_narrow) is None


def test_train_gives_a_wide_part_its_own_keys_as_play_does(tmp_path):
    from pianobot.learn.config import TrainConfig
    from pianobot.learn.plan import hand_groups

    right = [Note(0.6 * i, p, 0.6 * i + 0.5, 80, hand="right") for i, p in enumerate([55, 62, 67, 72, 81])]
    piece = Piece((*right, Note(0.0, 48, 1.0, 70, hand="left")), bpm=100)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        parts, _, offered, groups = hand_groups(
            piece, "wide", tmp_path, TrainConfig(), None, 6, KeyboardSpec(), HandSpec(), False
        )
    keys = {g.hand: g.config.env.world.keyboard.spec for g in groups}
    assert keys == {"right": KeyboardSpec(48, 36), "left": KeyboardSpec()}
    assert {side: parts[side][0].keyboard for side in parts} == keys
    assert all(g.start is not None and g.start.name.startswith("task-parts-") for g in groups)


def test_a_note_without_a_hand_is_refused():
    with pytest.raises(PianobotError, match="every note needs a hand"):
        play_hands(Piece((Note(0.0, 60, 1.0, hand="right"), Note(0.0, 48, 1.0))), "scripted")


def test_random_duets_are_seeded_and_keep_the_hands_apart():
    assert duet_set(3, 4) == duet_set(3, 4) and duet_set(3, 4) != duet_set(4, 4)
    for texture in TEXTURES:
        piece = random_duet(np.random.default_rng(1), texture)
        chords = max(len(c) for c in piece.part("left").chords())
        assert chords == {"block": 3, "voices": 2}.get(texture, 1), texture
    voiced = 0
    for seed, texture in itertools.product(range(200), TEXTURES):
        piece = random_duet(np.random.default_rng(seed), texture)
        left, right = piece.part("left"), piece.part("right")
        assert len(left) + len(right) == len(piece) and left.notes and right.notes
        assert max(n.pitch for n in left.notes) < min(n.pitch for n in right.notes), seed  # never a shared key
        # only a right hand in two voices holds a note while another sounds: its lower voice, a
        # minor third to a fifth under each melody note it sounds with
        held = [
            (a, b)
            for a in right.notes
            for b in right.notes
            if a.onset < b.onset < a.offset or a.onset == b.onset < a.pitch - b.pitch
        ]
        assert bool(held) <= (texture == "right-voices"), seed
        assert all(3 <= abs(a.pitch - b.pitch) <= 7 for a, b in held), seed
        voiced += bool(held)
    assert voiced >= 150  # of the 200 right hands in two voices


def test_the_parts_family_draws_fingered_whole_hand_parts_by_its_seed():
    from pianobot.agent.tasks import task_sampler
    from pianobot.env.piano import EnvConfig
    from pianobot.music.tasks import FAMILIES, PARTS

    assert PARTS in FAMILIES
    draw = task_sampler(PARTS, EnvConfig())
    pieces = [draw(np.random.default_rng(seed)) for seed in range(40)]
    assert pieces == [draw(np.random.default_rng(seed)) for seed in range(40)]
    keys = KeyboardSpec()
    for piece in pieces:
        assert piece.has_fingering and all(n.pitch in keys and n.finger in (2, 3, 4) for n in piece.notes)
        assert piece.notes[0].onset == 0.0
        check_playable(piece, keys, HandSpec())  # no finger asked to play while it holds a note
    # whole parts, as play gives a hand its part (a phrase is at most 6 notes): bars of 4 beats
    assert min(len(p) for p in pieces) >= 4 and sum(len(p) > 12 for p in pieces) >= 10
    assert max(p.notes[-1].offset for p in pieces) > 6.0
    # held notes under a moving voice and three-note chords: what melodies alone seldom hold
    assert sum(p.max_polyphony()[0] >= 2 for p in pieces) >= 8


def test_the_parts_familys_versions_train_into_folders_of_their_own(tmp_path):
    from pianobot.agent import general, store
    from pianobot.learn.config import TrainConfig
    from pianobot.learn.jobs import plan_jobs, task_job
    from pianobot.music.tasks import MELODY, PARTS, VERSIONS

    config = TrainConfig()
    job = task_job(PARTS, config, tmp_path)
    assert VERSIONS[PARTS] == 3 and job.folder.name == f"task-parts-v3-{store.config_hash(config)}"
    assert task_job(MELODY, config, tmp_path).folder.name.startswith("task-melody-")  # version 1: as before
    # earlier versions' policies trained with the same options are not taken for this version's
    older = [
        tmp_path / f"task-parts-{store.config_hash(config)}",
        tmp_path / f"task-parts-v2-{store.config_hash(config)}",
    ]
    for folder in older:
        folder.mkdir()
        (folder / store.MANIFEST_FILE).write_text("{}")
        (folder / store.POLICY_FILE).write_bytes(b"")
    todo, done = plan_jobs([job], force=False)
    assert todo == [job] and not done
    # and every version's folders count as the parts family's (general policies, the left hand's key)
    job.folder.mkdir()
    (job.folder / store.MANIFEST_FILE).write_text("{}")
    (job.folder / store.POLICY_FILE).write_bytes(b"")
    assert set(store.find_policies(tmp_path, general.PARTS_KEY)) == {*older, job.folder}


def test_pianobot_play_plays_both_hands_of_a_piece_with_both_and_one_hand_as_before():
    import pianobot
    from pianobot.perform.plan import Performance
    from pianobot.perform.together import HandsPerformance

    right = [Note(0.5 * i, p, 0.5 * i + 0.4, hand="right") for i, p in enumerate([72, 74, 76])]
    both = Piece((*right, Note(0.0, 48, 0.9, hand="left")))
    performance = pianobot.play(both, controller="scripted")
    assert isinstance(performance, HandsPerformance) and performance.report().reference_notes == 4
    assert performance.report("left").f1 == 1.0 and performance.report("right").reference_notes == 3
    assert performance.to_dict()["hands"]["left"]["performer"] == "scripted pianist"
    one = pianobot.play(Piece(tuple(right)).with_fingers([2, 3, 4]), controller="scripted")  # one hand, as before
    assert isinstance(one, Performance) and one.report().f1 == 1.0
    assert performance.together and "one simulation" in performance.performer
    filmed = pianobot.play(both, controller="scripted", video=True)  # one frame a step, the first before it
    assert filmed.frames[0].shape == (320, 720, 3) and len(filmed.frames) > 30 and filmed.report().f1 == 1.0
    with pytest.raises(PianobotError, match="a video of both hands needs them in one simulation"):
        pianobot.play(both, controller="scripted", video=True, together=False)


def test_general_policies_may_be_given_by_hand(tmp_path):
    """``general_policy`` as a dict names each hand's policy (one left out keeps its default, the
    packaged parts policy); a
    key that is not a hand is refused before anything plays."""
    from pianobot.agent.general import PACKAGED

    melody = next(PACKAGED.glob("task-melody-*"))
    piece = Piece((Note(0.0, 72, 0.5, hand="right"), Note(0.5, 74, 1.0, hand="right"), Note(0.0, 48, 1.0, hand="left")))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        performance = play_hands(piece, "sac", tmp_path, general_policy={"left": melody})  # (an empty store)
    right, left = (h.performer for h in performance.hands)
    assert right.startswith("general policy task-parts-") and left == f"general policy {melody.name}"
    with pytest.raises(PianobotError, match="middle is not a hand"):
        play_hands(piece, "sac", tmp_path, general_policy={"middle": melody})


def test_judging_both_hands_after_training_says_a_warning_of_its_plays_once(tmp_path, monkeypatch):
    """`train`'s judgement plays the piece from three hand starts, and again for each phrase
    policy: a warning those plays give (hands that cannot share one simulation) is said once."""
    from types import SimpleNamespace

    import pianobot.learn.accept as accept
    from pianobot.agent.general import GENERAL_KEY, PACKAGED
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.together import prepare_parts

    general = next(PACKAGED.glob(f"{GENERAL_KEY}-*"))
    right = [Note(float(i), 72 + 2 * i, i + 1.0, 80, hand="right") for i in range(3)]
    piece = Piece((*right, Note(0.0, 48, 2.0, 70, hand="left")), bpm=120)
    parts = prepare_parts(piece, KeyboardSpec(), HandSpec())
    phrases = {hand: split_phrases(part[1], 6) for hand, part in parts.items()}
    plays = []

    def apart(piece, parts, plans, seed):
        plays.append(seed)
        warnings.warn(PianobotWarning("the hands play apart"))
        return SimpleNamespace(report=lambda: SimpleNamespace(f1=0.5))

    monkeypatch.setattr(accept, "perform_hands", apart)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        verdict = accept.settle_hands(piece, parts, phrases, tmp_path, dict.fromkeys(parts, general), {})
    assert plays == list(accept.JUDGE_SEEDS) and verdict.before == verdict.after == (0.5, 0.5, 0.5)
    assert [str(w.message) for w in caught] == ["the hands play apart"]
    assert verdict.general_plays == ("right 0", "left 0") and not verdict.used


def test_hands_a_third_apart_play_whole_where_their_fingerings_keep_the_wrists_apart():
    from test_hands import interleaved

    piece = interleaved()
    performance = play_hands(piece, "scripted")  # fingered on its own, each hand: F1 0.39, the wrists pushed aside
    assert performance.report().f1 >= 0.95


def test_both_hands_take_their_thumbs_only_where_the_thumbs_keep_more_notes():
    """A right-hand chord of four notes: three fingers are given three of its notes, hands with
    their thumbs all four; play_hands then plays with the thumbs (said in one warning line), and
    a piece three fingers are given whole keeps three fingers, silently."""
    from pianobot.music.instrument import THUMB
    from pianobot.perform.together import thumbs_keep_more

    chord = [Note(0.0, p, 2.0, 80, hand="right") for p in (72, 76, 79, 84)]
    bass = [Note(0.0, 48, 2.0, 80, hand="left"), Note(2.0, 43, 4.0, 80, hand="left")]
    piece = Piece(tuple(chord + bass + [Note(2.0, 81, 4.0, 80, hand="right")]), bpm=60)
    assert thumbs_keep_more(piece) == (6, 7)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        performance = play_hands(piece, "scripted")
    said = [str(w.message) for w in caught if "thumbs" in str(w.message)]
    assert said == [
        "both hands play with their thumbs too: they are given 7 of the notes, three fingers 6 (hand=HandSpec() plays with three)"
    ]
    assert performance.report().f1 == 1.0
    assert all(h.performance.plan.config.world.hand.spec == THUMB for h in performance.hands)
    three = play_hands(piece, "scripted", hand=HandSpec())  # named: no choice made
    assert sum(len(h.part) for h in three.hands) == 6
    whole = Piece(tuple(chord[:3] + bass), bpm=60)
    assert thumbs_keep_more(whole) is None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        performance = play_hands(whole, "scripted")
    assert not [w for w in caught if "thumbs" in str(w.message)]
    assert all(h.performance.plan.config.world.hand.spec == HandSpec() for h in performance.hands)


def test_the_finger_set_is_chosen_among_the_model_s_sets_in_its_order_of_preference():
    """keeps_more: the first set, unless a later one gives the hands more notes (then the one that
    gives the most, the earlier on a tie); a hand model with one set plays it, nothing compared."""
    from pianobot.music.instrument import THUMB
    from pianobot.music.load import LoadOptions
    from pianobot.pianist.parts import keeps_more
    from pianobot.pianist.reading import fingers_for_file
    from pianobot.sim.hand import default_fingers

    chord = [Note(0.0, p, 2.0, 80, hand="right") for p in (72, 76, 79, 84)]
    bass = [Note(0.0, 48, 2.0, 80, hand="left"), Note(2.0, 43, 4.0, 80, hand="left")]
    piece = Piece(tuple(chord + bass + [Note(2.0, 81, 4.0, 80, hand="right")]), bpm=60)
    three = HandSpec()
    assert keeps_more([(three, piece), (THUMB, piece)]) == (1, (6, 7))
    assert keeps_more([(THUMB, piece), (three, piece)]) == (0, None)  # the preferred set keeps more: kept
    assert keeps_more([(three, piece), (three, piece), (THUMB, piece), (THUMB, piece)]) == (2, (6, 7))
    pianist = default_fingers("pianist")
    examples = Path(__file__).parent.parent / "examples" / "midi"
    assert fingers_for_file(examples / "prelude-performed.mid", LoadOptions(), "pianist") == (
        pianist,
        None,
    )
