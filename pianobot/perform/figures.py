"""What a performance's figures mean.

:data:`FIGURES` is every figure of a :class:`~pianobot.music.metrics.Report` with one line
saying what it means; the first few (:attr:`Figure.first`) are what a newcomer reads first. The
terminal's tables (`pianobot play`, `pianobot score`) and the HTML page
(:mod:`pianobot.perform.report`) both read them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from pianobot.music.metrics import Report


def _opt(value, fmt: str, unit: str = "", absent: str = "n/a") -> str:
    """``value`` formatted, or ``absent`` for None."""
    return absent if value is None else format(value, fmt) + unit


def _ms(seconds: float | None) -> float | None:
    return None if seconds is None else seconds * 1000


@dataclass(frozen=True)
class Figure:
    """One figure of a report: its name, its value as text, and what it means in a line."""

    label: str
    value: Callable[[Report], str]
    meaning: str
    first: bool = False
    """Among the figures a newcomer needs first (the rest: `--all`, and the HTML report)."""
    applies: Callable[[Report], bool] = lambda r: True
    """Whether the report has it (the pedal's figures: where either piece uses the pedal)."""


FIGURES = (
    Figure(
        "notes played",
        lambda r: f"{r.matched_notes} of {r.reference_notes}, {r.played_notes - r.matched_notes} extra",
        "score notes struck on time (±onset tolerance); extra: not in the score",
        first=True,
    ),
    Figure(
        "note F1",
        lambda r: f"{r.f1:.3f}",
        "1: every note on time and nothing extra; 0: none",
        first=True,
    ),
    Figure(
        "velocity error",
        lambda r: f"{_opt(r.velocity_mae, '.1f')} mean, {_opt(r.velocity_max_error, 'd')} max",
        "loudness off from the score's, in MIDI velocity (1-127)",
        first=True,
    ),
    Figure(
        "timing error",
        lambda r: (
            f"{_opt(_ms(r.onset_error_mean), '.0f', ' ms')} mean, {_opt(_ms(r.onset_error_max), '.0f', ' ms')} max"
        ),
        "how early or late the notes started",
        first=True,
    ),
    Figure(
        "fingering",
        lambda r: _opt(r.fingering_accuracy, ".3f"),
        "share of notes struck with the score's finger",
        first=True,
    ),
    Figure(
        "notes (reference / played / matched)",
        lambda r: f"{r.reference_notes} / {r.played_notes} / {r.matched_notes}",
        "the score's notes, the notes played, the pairs matched one to one",
    ),
    Figure("note precision", lambda r: f"{r.precision:.3f}", "share of the played notes that the score has"),
    Figure("note recall", lambda r: f"{r.recall:.3f}", "share of the score's notes that were played"),
    Figure(
        "note F1 with offsets",
        lambda r: f"{r.f1_with_offsets:.3f}",
        "note F1, each note also let go on time (±20 % of its length, at least 50 ms)",
    ),
    Figure(
        "velocity-aware note F1 (mir_eval)",
        lambda r: f"{r.velocity_f1:.3f}",
        "note F1, each note also as loud as the score's after mir_eval refits all played velocities to the "
        "score's with one line: can be far below note F1, read the velocity error beside it",
    ),
    Figure(
        "key-press F1 per step (RoboPianist)",
        lambda r: f"{r.step_f1:.3f}",
        "whether exactly the right keys are down, each 50 ms step, averaged (RoboPianist's measure)",
    ),
    Figure(
        "held / written duration, median (< 0.35 s / 0.35-0.7 s / longer)",
        lambda r: " / ".join(
            _opt(x, ".2f") for x in (r.duration_ratio_short, r.duration_ratio_medium, r.duration_ratio_long)
        ),
        "how long notes were held against their written length: 1 as written, 0.5 half as long",
    ),
    Figure(
        "note F1 with offsets, sounding (pedal)",
        lambda r: _opt(r.sounding_f1_with_offsets, ".3f"),
        "note F1 with offsets, each note lasting as long as it sounds: until its key rises and the sustain pedal "
        "is up (each file's own pedal)",
        first=True,
        applies=lambda r: r.pedal_f1 is not None,
    ),
    Figure(
        "sustain pedal",
        lambda r: f"F1 {_opt(r.pedal_f1, '.3f')}, timing error {_opt(_ms(r.pedal_error_mean), '.0f', ' ms')} mean",
        "presses and releases matched one to one within the onset tolerance; how far off the matched ones were",
        first=True,
        applies=lambda r: r.pedal_f1 is not None,
    ),
    Figure(
        "onset tolerance",
        lambda r: f"{r.onset_tolerance * 1000:.0f} ms",
        "how far from its time a note may start and still count",
    ),
)


# -- the HTML report -------------------------------------------------------------------------------


def figures_for(report: Report, every: bool = False) -> list[Figure]:
    """The figures ``report`` has, the first few (``every``: all of them)."""
    return [f for f in FIGURES if (every or f.first) and f.applies(report)]
