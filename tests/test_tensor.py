import numpy as np
import pytest

from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.piece import Note, Piece
from pianobot.music.tensor import FINGER, NOTE, VELOCITY, ScoreSpec, score_tensor, tensor_to_piece

SPEC = ScoreSpec()


def test_shape_is_the_papers_L_by_5_at_20_hz(scale):
    tensor = score_tensor(scale, SPEC)
    assert tensor.shape == (80, 24, 5)  # 4 s at 20 Hz, 24 keys, note + velocity + 3 fingers
    assert tensor.dtype == np.float32


def test_content_of_one_step(scale):
    tensor = score_tensor(scale, SPEC)
    step = tensor[25]  # 1.25 s: D4 (key 2), velocity 90, finger 3 (middle = slot 1)
    assert step[:, NOTE].nonzero()[0].tolist() == [2]
    assert step[2, VELOCITY] == pytest.approx(90 / 127)
    assert step[2, FINGER:].tolist() == [0, 1, 0]
    assert tensor[:, :, NOTE].sum() == 80  # one key down at every step


def test_round_trip_for_a_piece_on_the_control_grid():
    piece = Piece(
        (
            Note(0.0, 60, 0.5, 64, 2),
            Note(0.0, 64, 0.25, 100, 4),
            Note(0.5, 61, 0.65, 1, 3),
            Note(1.0, 83, 2.0, 127, None),
            Note(2.0, 60, 2.5, 30, 3),
        )
    )
    assert tensor_to_piece(score_tensor(piece, SPEC), SPEC) == piece


def test_repeated_notes_stay_apart():
    piece = Piece((Note(0.0, 60, 0.5, 80, 2), Note(0.5, 60, 1.0, 90, 2)))
    tensor = score_tensor(piece, SPEC)
    assert tensor[9, 0, NOTE] == 0  # the first note gives up its last step
    back = tensor_to_piece(tensor, SPEC)
    assert [(n.onset, n.offset, n.velocity) for n in back] == [(0.0, 0.45, 80), (0.5, 1.0, 90)]


def test_thumb_and_other_keyboards_change_the_layout():
    spec = ScoreSpec(keyboard=KeyboardSpec(lowest=48, count=12), hand=HandSpec((1, 2, 3, 4)), control_hz=10)
    piece = Piece((Note(0.0, 50, 0.3, 80, 1),))
    tensor = score_tensor(piece, spec)
    assert tensor.shape == (3, 12, 6)
    assert tensor[0, 2, FINGER:].tolist() == [1, 0, 0, 0]
    assert tensor_to_piece(tensor, spec) == piece


def test_short_notes_get_at_least_one_step_and_steps_can_be_padded():
    piece = Piece((Note(0.0, 60, 0.01),))
    tensor = score_tensor(piece, SPEC, steps=10)
    assert tensor.shape[0] == 10 and tensor[:, 0, NOTE].tolist() == [1] + [0] * 9
