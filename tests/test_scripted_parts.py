"""The scripted pianist's parts: reading a finger's notes, planning strikes, and its tuning."""

from dataclasses import fields, replace

import numpy as np

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.piece import Note, Piece
from pianobot.music.tensor import FINGER, NOTE, VELOCITY
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.pianist.strikes import Run, StrikePlanner, Tip, finger_runs
from pianobot.pianist.tuning import PianistTuning
from pianobot.sim.world import WorldConfig


def window(notes, rows=11, keys=20, fingers=3):
    """A score window with (key, first row, end row, velocity 0-1, slot) notes."""
    score = np.zeros((rows, keys, FINGER + fingers), dtype=np.float32)
    for key, start, end, velocity, slot in notes:
        score[start:end, key, NOTE] = 1
        score[start:end, key, VELOCITY] = velocity
        score[start:end, key, FINGER + slot] = 1
    return score


def test_finger_runs_are_one_fingers_notes_in_time_order():
    score = window([(5, 4, 6, 0.5, 1), (7, 0, 2, 1.0, 1), (9, 1, 3, 0.5, 0), (5, 8, 11, 0.25, 1)])
    runs = finger_runs(score, 1)
    assert runs == [Run(7, 0, 2, 127.0), Run(5, 4, 6, 63.5), Run(5, 8, 11, 31.75)]
    assert (runs[1].key, runs[1].start, runs[1].end, runs[1].velocity) == (5, 4, 6, 63.5)


def test_a_finger_strikes_now_holds_then_gets_ready_for_its_next_note():
    world = WorldConfig()
    planner = StrikePlanner(world, KeyLayout(world), PianistTuning())
    finger = world.hand.spec.fingers[0]
    tips = {f: Tip(height=0.01, y=0.11) for f in world.hand.spec.fingers}
    score = window([(5, 0, 3, 0.5, 0), (7, 8, 10, 0.5, 0)])
    now = planner.plan(score, None, tips)[finger]
    assert (now.phase, now.key, now.start) == ("strike", 5, 0)
    held = planner.plan(score, score[0], tips)[finger]  # the same note, begun the step before
    assert (held.phase, held.key, held.next_note) == ("hold", 5, Run(7, 8, 10, 63.5))
    later = planner.plan(window([(7, 8, 10, 0.5, 0)]), None, tips)[finger]
    assert (later.phase, later.key, later.start) == ("ready", 7, 8) and later.height > 0


def test_the_tuning_is_one_frozen_dataclass_that_the_pianist_uses():
    assert {f.name for f in fields(PianistTuning)} >= {"idle_height", "settle_steps", "tilt_step"}
    config = EnvConfig(tactile=False)
    env = PianoEnv(piece=Piece((Note(1.0, 60, 1.5, 80, 3),), bpm=60), config=config)
    observation, _ = env.reset(seed=0)
    env.close()
    default = ScriptedPianist(config).act(observation)
    assert np.array_equal(default, ScriptedPianist(config, PianistTuning()).act(observation))
    higher = ScriptedPianist(config, replace(PianistTuning(), idle_height=0.03)).act(observation)
    assert higher.shape == default.shape and not np.array_equal(higher, default)  # idle fingers wait higher


def test_a_held_key_stays_down_while_another_finger_strikes_within_reach_and_not_beyond():
    """Issue 38: the wrist may stand hold_reach from straight over a held key and strike_reach from
    straight over a key to strike; a strike both allow does not make the holding finger let go."""
    world = WorldConfig()
    layout = KeyLayout(world)
    planner = StrikePlanner(world, layout, PianistTuning())
    first, last = world.hand.spec.fingers[0], world.hand.spec.fingers[-1]
    tips = {f: Tip(height=0.01, y=0.11) for f in world.hand.spec.fingers}
    wrist = layout.wrist_for(first, 0)  # straight over the held key
    near = window([(0, 0, 11, 0.5, 0), (4, 6, 9, 0.5, 2)])  # two white keys up, with the outer finger
    plans = planner.plan(near, near[0], tips, wrist)
    assert plans[first].phase == "hold" and plans[last].key == 4
    far = window([(0, 0, 11, 0.5, 0), (19, 6, 9, 0.5, 2)], keys=20)  # out of the held key's reach
    assert first not in planner.plan(far, far[0], tips, wrist)


def test_a_repeated_key_is_let_go_later_than_one_the_finger_must_leave():
    """A finger holding a key lets go just long enough before striking it again for it to rise; before
    a different key it needs prepare_steps."""
    world = WorldConfig()
    planner = StrikePlanner(world, KeyLayout(world), PianistTuning())
    finger = world.hand.spec.fingers[1]
    tips = {f: Tip(height=0.01, y=0.11) for f in world.hand.spec.fingers}
    tips[finger] = planner._pressed(5)
    repeat = window([(5, 0, 3, 0.5, 1), (5, 4, 8, 0.5, 1)])
    hop = window([(5, 0, 3, 0.5, 1), (7, 4, 8, 0.5, 1)])
    assert planner.plan(repeat, repeat[0], tips)[finger].phase == "hold"
    assert planner.plan(hop, hop[0], tips)[finger].phase != "hold"
    assert planner.release_steps(5, 5, 64) < planner.release_steps(5, 7, 64) <= planner.hop_steps(5, 7, 64)


def test_a_finger_still_on_the_key_it_let_go_of_rises_before_striking_it_again():
    """A strike only goes down from where the fingertip is: a finger still pressing the key it let go
    of, its repeat due, must rise first (it hovers, 'ready'), whether the note it let go is still
    written or has ended; on its strike's path, or striking another key, it strikes. The pianist's
    hand's rule (``rise_before_repeat``); the Allegro-like hand's planner strikes as before."""
    world = WorldConfig()
    planner = StrikePlanner(world, KeyLayout(world), replace(PianistTuning(), rise_before_repeat=True))
    finger, slot = world.hand.spec.fingers[1], 1
    tips = {f: Tip(height=0.01, y=0.11) for f in world.hand.spec.fingers}
    soft = 0.25  # a strike from the ready height several steps long
    repeat = window([(5, 0, 2, soft, slot), (5, 3, 9, soft, slot)])  # (a row apart: two notes)
    lead = planner.ready(Run(5, 0, 1, soft * 127))[1]
    assert lead >= 3
    tips[finger] = planner._pressed(5)  # still at the bottom of the key
    released = frozenset({(finger, 5)})
    written = planner.plan(repeat[1:], repeat[0], tips, released=released)[finger]
    assert (written.phase, written.key) == ("ready", 5)  # the note let go is still written
    ended = window([(5, 1, 7, soft, slot)])  # its written end passed (the previous row held it)
    assert planner.plan(ended, repeat[0], tips)[finger].phase == "ready"
    tips[finger] = Tip(height=planner.layout.key_top[5] + planner._path_height(Run(5, 1, 7, soft * 127)), y=0.11)
    assert planner.plan(ended, repeat[0], tips)[finger].phase == "strike"  # on its path: it strikes
    tips[finger] = planner._pressed(5)
    other = window([(7, 1, 7, soft, slot)])
    assert planner.plan(other, repeat[0], tips)[finger].phase == "strike"  # another key: as before
    allegro = StrikePlanner(world, KeyLayout(world), PianistTuning())  # (the Allegro-like hand's: unchanged)
    assert allegro.plan(ended, repeat[0], tips)[finger].phase == "strike"


def test_a_finger_strikes_the_key_it_let_go_of_again_from_just_over_where_the_key_let_its_note_go():
    """A key lets its note go once it rises over the keyboard's release depth, so a finger striking
    it again need not rise to the ready height over its top (``repeat_rise``, the pianist's hand's):
    it strikes from 1 mm over the release depth, fewer steps, and so lets go of the held note later
    than for a strike from the ready height; another finger on that key, and a hand without
    ``repeat_rise`` (the Allegro-like hand's), as before."""
    world = WorldConfig()
    layout = KeyLayout(world)
    tuning = replace(PianistTuning(), rise_before_repeat=True, repeat_rise=0.001)
    planner = StrikePlanner(world, layout, tuning)
    soft = Run(5, 0, 1, 30.0)
    height, lead = planner.ready(soft, repeat=True)
    usual_height, usual_lead = planner.ready(soft)
    let_go_at = layout.contact_y(5) * np.tan(layout.release_angle)  # (m under the key's top)
    assert -let_go_at < planner.repeat_height(5) <= height < 0 < usual_height  # risen past it, still in the key
    assert lead < usual_lead
    assert planner.release_steps(5, 5, 30.0, same_finger=True) < planner.release_steps(5, 5, 30.0)
    assert planner.hop_steps(5, 5, 30.0) < planner.hop_steps(5, 7, 30.0)
    allegro = StrikePlanner(world, layout, replace(PianistTuning(), rise_before_repeat=True))
    assert allegro.ready(soft, repeat=True) == allegro.ready(soft)
    assert allegro.release_steps(5, 5, 30.0, same_finger=True) == allegro.release_steps(5, 5, 30.0)


def test_a_note_let_go_before_its_end_is_not_pressed_again():
    """A left hand holds C3 and G3 and strikes C3 again under the held G3 (a new user's organ
    file): the pianist let go of G3 for the repeat, then pressed it again while it was still
    written to sound, a second G3 (and, with the finger off its key, an F3) that nobody wrote."""
    from pianobot.perform.together import play_hands

    beat = 60 / 72

    def note(pitch, start, end, hand, velocity=60):
        return Note(start * beat, pitch, end * beat, velocity, hand=hand)

    left = [note(48, 0, 2, "left"), note(55, 0, 4, "left"), note(48, 2, 6, "left")]
    left += [note(43, 4, 8, "left"), note(50, 4, 8, "left")]
    right = [note(67, 0, 1, "right", 80), note(67, 1, 3, "right", 70), note(69, 3, 4.5, "right")]
    right += [note(72, 4, 5, "right", 80), note(71, 5, 6, "right", 70), note(67, 6, 8, "right", 70)]
    piece = Piece(tuple(sorted(left + right, key=lambda n: (n.onset, n.pitch))))
    performance = play_hands(piece, "scripted")
    report = performance.report("left")
    assert report.f1 == 1.0, [(r.played.name, round(r.played.onset, 2)) for r in report.rows if r.reference is None]
