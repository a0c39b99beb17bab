"""The paper's score representation: one L x (2 + F) matrix per control step.

For each of the L keys: note on/off (0 or 1), target velocity in [0, 1] (MIDI velocity / 127),
and the finger as a one-hot vector over the hand's F fingers (F = 3 gives the paper's L x 5).

A note occupies the control steps from round(onset * hz) to round(offset * hz), at least one.
A key must rise before it can sound again, so when the same key is struck again right where the
previous note ends, the previous note gives up its last step: the gap is what tells two
repeated notes apart in the tensor. :func:`tensor_to_piece` is the inverse; for a piece whose
times lie on the control grid (and whose repeated notes last at least two steps) the round trip
is exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.piece import Note, Piece

NOTE, VELOCITY, FINGER = 0, 1, 2
"""Channel indices: note on/off, velocity, first finger channel."""


@dataclass(frozen=True)
class ScoreSpec:
    """The keyboard, the hand and the control rate that a score tensor is laid out for."""

    keyboard: KeyboardSpec = field(default_factory=KeyboardSpec)
    """Which keys the L rows stand for."""
    hand: HandSpec = field(default_factory=HandSpec)
    """Which fingers the one-hot finger channels stand for."""
    control_hz: float = 20.0
    """Control steps per second (RoboPianist found 20 Hz best)."""

    @property
    def channels(self) -> int:
        return 2 + len(self.hand.fingers)

    @property
    def dt(self) -> float:
        return 1.0 / self.control_hz

    def step_of(self, seconds: float) -> int:
        """The control step nearest to a time."""
        return int(round(seconds * self.control_hz + 1e-9))


def note_steps(piece: Piece, spec: ScoreSpec) -> list[tuple[Note, int, int]]:
    """Each note with its first step and its end step (exclusive), re-strike gaps applied."""
    spans = []
    by_key: dict[int, list[list]] = {}
    for note in piece.notes:
        start = spec.step_of(note.onset)
        end = max(start + 1, spec.step_of(note.offset))
        span = [note, start, end]
        earlier = by_key.setdefault(note.pitch, [])
        if earlier and earlier[-1][2] >= start:
            earlier[-1][2] = max(earlier[-1][1] + 1, start - 1)
        earlier.append(span)
        spans.append(span)
    return [(n, s, e) for n, s, e in spans]


def score_tensor(piece: Piece, spec: ScoreSpec = ScoreSpec(), steps: int | None = None) -> np.ndarray:
    """The piece as a float32 array of shape (steps, L, 2 + F).

    ``steps`` defaults to enough steps to cover the last note. Notes must be on the keyboard.
    """
    spans = note_steps(piece, spec)
    total = max((e for _, _, e in spans), default=0) if steps is None else steps
    out = np.zeros((total, spec.keyboard.count, spec.channels), dtype=np.float32)
    for note, start, end in spans:
        key = spec.keyboard.index(note.pitch)
        out[start:end, key, NOTE] = 1.0
        out[start:end, key, VELOCITY] = note.velocity / 127.0
        if note.finger is not None:
            out[start:end, key, FINGER + spec.hand.slot(note.finger)] = 1.0
    return out


def tensor_to_piece(tensor: np.ndarray, spec: ScoreSpec = ScoreSpec()) -> Piece:
    """The inverse of :func:`score_tensor`: runs of 'on' steps become notes."""
    steps, keys, channels = tensor.shape
    if keys != spec.keyboard.count or channels != spec.channels:
        raise ValueError(f"tensor of shape {tensor.shape} does not fit {spec}")
    notes = []
    on = tensor[:, :, NOTE] > 0.5
    for key in range(keys):
        column = np.concatenate([[False], on[:, key], [False]]).astype(np.int8)
        edges = np.diff(column)
        for start, end in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            fingers = tensor[start, key, FINGER:]
            finger = spec.hand.fingers[int(fingers.argmax())] if fingers.max() > 0.5 else None
            velocity = int(np.clip(round(float(tensor[start, key, VELOCITY]) * 127), 1, 127))
            notes.append(
                Note(
                    onset=start * spec.dt,
                    pitch=spec.keyboard.lowest + key,
                    offset=end * spec.dt,
                    velocity=velocity,
                    finger=finger,
                )
            )
    return Piece(tuple(notes))


def steps_for(seconds: float, spec: ScoreSpec) -> int:
    """Control steps needed to cover ``seconds``."""
    return int(math.ceil(seconds * spec.control_hz - 1e-9))
