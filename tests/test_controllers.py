"""The scripted pianist proves the simulator playable: every example, F1 >= 0.95, velocity MAE <= 10."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from pianobot.controllers import RandomController, ScriptedPianist
from pianobot.env import EnvConfig
from pianobot.metrics import compare
from pianobot.errors import PianobotWarning
from pianobot.fingering import ensure_fingering
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions, load_part, load_piece
from pianobot.music.tasks import TASKS, make_task
from pianobot.perform import perform
from pianobot.sim.world import WorldConfig

EXAMPLES = sorted((Path(__file__).parent.parent / "examples" / "midi").glob("*.mid"))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_scripted_pianist_plays_every_example(path):
    """The performance-style file is read as `--hand right` would, and fingered by the planner."""
    options = LoadOptions(hand="right") if "performed" in path.stem else LoadOptions()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        reference, _ = ensure_fingering(load_part(path, options, HandSpec()), KeyboardSpec(), HandSpec())
    report = compare(reference, perform(reference, "scripted", seed=1).played)
    assert report.f1 >= 0.95, [(r.reference, r.played) for r in report.rows if r.reference is None or r.played is None]
    assert report.velocity_mae <= 10
    assert report.fingering_accuracy == 1.0  # touch tells which finger struck each key


@pytest.mark.parametrize("task", TASKS)
def test_scripted_pianist_plays_random_task_instances(task):
    piece = make_task(task, np.random.default_rng(11))
    report = compare(piece, perform(piece, "scripted", seed=2).played)
    assert report.f1 >= 0.95 and report.velocity_mae <= 10


def test_scripted_pianist_plays_with_the_thumb_too():
    from pianobot.music.instrument import HandSpec
    from pianobot.music.piece import Note, Piece
    from pianobot.sim.hand import HandConfig

    piece = Piece((Note(0.0, 60, 0.5, 80, 1), Note(0.5, 62, 1.0, 80, 2), Note(1.0, 64, 1.5, 80, 3)), bpm=60)
    world = WorldConfig(hand=HandConfig(spec=HandSpec((1, 2, 3, 4))))
    report = compare(piece, perform(piece, "scripted", EnvConfig(world=world, tactile=False)).played)
    assert report.f1 == 1.0 and report.fingering_accuracy == 1.0


def test_random_controller_is_a_poor_pianist():
    reference = load_piece(EXAMPLES[0])
    report = compare(reference, perform(reference, "random", seed=0).played)
    assert report.f1 < 0.5
    actions = RandomController(13, seed=0)
    assert all(np.abs(actions.act({})).max() <= 1 for _ in range(20))


def test_scripted_pianist_needs_velocity_control():
    with pytest.raises(ValueError, match="velocity"):
        ScriptedPianist(EnvConfig(world=WorldConfig(control="torque")))
