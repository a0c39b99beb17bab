"""The `melody` task family (issue 20): random one-hand phrases, fingered by the planner, drawn by the env's generator."""

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from pianobot.agent import tasks
from pianobot.agent.tasks import draw_melody, make_env, task_sampler
from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.melodies import MelodyKey, random_melody, random_phrase
from pianobot.music.phrases import DEFAULT_MAX_NOTES, split_phrases
from pianobot.music.tasks import FAMILIES
from pianobot.pianist.fingering import plan_fingering

KEYBOARD = KeyboardSpec()


@pytest.fixture(scope="module")
def drawn():
    """300 phrases drawn one after another from one generator."""
    rng = np.random.default_rng(0)
    return [draw_melody(rng) for _ in range(300)]


def test_a_seed_fixes_every_phrase_and_the_environment_draws_them_from_its_own_generator():
    first = [draw_melody(np.random.default_rng(seed)) for seed in range(5)]
    assert first == [draw_melody(np.random.default_rng(seed)) for seed in range(5)]
    assert len(set(first)) == 5
    env = make_env("melody", EnvConfig(tactile=False))
    pieces = [env.reset(seed=3)[1]["piece"], env.reset()[1]["piece"]]
    again = make_env("melody", EnvConfig(tactile=False))
    assert [again.reset(seed=3)[1]["piece"], again.reset()[1]["piece"]] == pieces  # a seed fixes the episodes
    assert pieces[0] != pieces[1]  # a fresh phrase each episode


def test_every_phrase_has_the_planners_fingering_and_fits_one_phrase(drawn):
    for piece in drawn[:100]:
        plan = plan_fingering(piece.without_fingering())
        assert piece.has_fingering and not plan.problems and plan.piece == piece  # the planner's, without problems
        assert 1 <= len(piece) <= DEFAULT_MAX_NOTES and len(split_phrases(piece)) == 1
    assert {len(piece) for piece in drawn} == set(range(1, DEFAULT_MAX_NOTES + 1))
    assert any(plan_fingering(piece.without_fingering()).moves for piece in drawn[:50])  # the wrist moves


def test_tempi_velocities_rhythms_and_chords_lie_in_their_ranges(drawn):
    notes = [n for piece in drawn for n in piece.notes]
    assert all(60 <= piece.bpm <= 144 for piece in drawn) and min(p.bpm for p in drawn) < 70 < 130 < max(
        p.bpm for p in drawn
    )
    assert min(n.velocity for n in notes) == 30 and max(n.velocity for n in notes) == 120
    assert all(piece.max_polyphony()[0] <= 2 for piece in drawn)
    assert sum(piece.max_polyphony()[0] == 2 for piece in drawn) > len(drawn) / 5  # two-note chords
    beats, moves, rests = set(), set(), 0
    for piece in drawn:
        chords = piece.chords()
        for a, b in zip(chords, chords[1:]):
            beats.add(round((b[0].onset - a[0].onset) * piece.bpm / 60, 1))
            moves.add(abs(b[0].pitch - a[0].pitch))
            rests += b[0].onset - max(n.offset for n in a) >= 0.5 * 60 / piece.bpm - 0.002
    assert {0.3, 0.5, 1.0, 1.5, 2.0} <= beats  # triplet eighth, eighth, quarter, dotted quarter, half
    assert 0 in moves and {1, 2} & moves and max(moves) >= 7  # repeated notes, steps, leaps
    assert rests > 10


def test_black_keys_in_every_key_and_every_black_key_of_the_keyboard(drawn):
    rng = np.random.default_rng(1)
    for tonic in range(12):
        for minor in (False, True):
            key = MelodyKey(tonic, minor)
            notes = [n.pitch for _ in range(12) for n in draw_melody(rng, key=key).notes]
            scale = set(key.pitches(KEYBOARD)) | set(key.pitches(KEYBOARD, raised_seventh=True))
            assert set(notes) <= scale, key.name
            if key.name != "C major":  # the one key without black keys
                assert any(KeyboardSpec.is_black(p) for p in notes), key.name
    played = {n.pitch for piece in drawn for n in piece.notes}
    assert {p for p in KEYBOARD.pitches if KeyboardSpec.is_black(p)} <= played


def test_a_phrase_the_planner_turns_down_is_drawn_again_from_the_same_generator(monkeypatch):
    """Two draws with problems and one the planner refuses outright: the fourth draw is the instance."""
    real, calls = tasks.plan_fingering, []

    def planner(piece, keyboard, hand):
        calls.append(piece)
        plan = real(piece, keyboard, hand)
        if len(calls) == 3:
            raise tasks.PianobotError("a chord wider than the hand")
        return plan if len(calls) > 3 else replace(plan, problems=("too fast",))

    monkeypatch.setattr(tasks, "plan_fingering", planner)
    piece = draw_melody(np.random.default_rng(7))
    rng = np.random.default_rng(7)
    expected = [random_phrase(rng) for _ in range(4)]
    assert calls == expected and piece.without_fingering() == expected[3]


def test_the_phrase_options_keep_every_seeds_melody():
    """benchmarks/melodies.py and test_melodies.py rely on the melodies their seeds draw."""
    rng = np.random.default_rng(0)
    assert [n.pitch for n in random_melody(rng).notes][:8] == [61, 66, 63, 73, 73, 77, 82, 80]
    same = random_melody(np.random.default_rng(5), velocities=(20, 127), chords=0.0, max_notes=None)
    assert same == random_melody(np.random.default_rng(5))
    chords = random_melody(np.random.default_rng(5), chords=1.0, max_notes=20)
    assert len(chords) == 20 and chords.max_polyphony()[0] == 2


def test_every_family_has_a_sampler_and_the_environment_takes_one():
    config = EnvConfig(tactile=False)
    for name in FAMILIES:
        piece = task_sampler(name, config)(np.random.default_rng(0))
        assert piece.has_fingering
    with pytest.raises(ValueError, match="unknown task 'sonata'"):
        task_sampler("sonata", config)
    with pytest.raises(ValueError, match="sampler="):
        PianoEnv(task="melody", config=config)  # the environment alone knows only the paper's families
    with pytest.raises(ValueError, match="exactly one of"):
        PianoEnv(sampler=task_sampler("melody", config), task="one-note", config=config)


def test_the_environment_imports_nothing_above_it():
    code = "import sys, pianobot.env.piano; print(sorted(m for m in sys.modules if m.startswith(('pianobot.pianist', 'pianobot.agent', 'torch'))))"
    assert (
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "[]"
    )


def test_slurs_keep_every_seeds_melody_and_hold_notes_to_the_next():
    plain = random_melody(np.random.default_rng(11))
    slurred = random_melody(np.random.default_rng(11), slurs=1.0)
    assert [(n.onset, n.pitch, n.velocity) for n in slurred] == [(n.onset, n.pitch, n.velocity) for n in plain]
    pairs = list(zip(slurred.notes, slurred.notes[1:]))
    legato = [a for a, b in pairs if a.pitch != b.pitch and a.offset == pytest.approx(b.onset, abs=1e-3)]
    assert len(legato) >= len(pairs) / 2
    # a repeated note leaves the key time to rise; no slurred note reaches past the next onset
    assert all(a.offset <= b.onset + 1e-3 for a, b in pairs)
    assert all(a.offset < b.onset - 1e-3 for a, b in pairs if a.pitch == b.pitch)
