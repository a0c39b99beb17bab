"""The `pianobot score` command."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from pianobot.cli.options import (
    AllFigures,
    HtmlReport,
    Reading,
    check_files,
    check_html,
    read_file,
    reads,
)
from pianobot.cli.terminal import err, out, said, write_json
from pianobot.errors import PianobotError
from pianobot.files import check_writable
from pianobot.music.metrics import DEFAULT_ONSET_TOLERANCE

SCORE_NOTES = 20
"""Rows of the per-note table ``score`` prints unless ``--notes N`` says (every row goes to ``--json``)."""


@reads(without=("refinger", "lowest_note", "keys"))
def score(
    played: Path = typer.Argument(..., help="The performance, a .mid file (e.g. written by `pianobot play`)."),
    reference: Path = typer.Argument(..., help="The reference score, a .mid file or a MusicXML score."),
    onset_tolerance: float = typer.Option(
        DEFAULT_ONSET_TOLERANCE, "--onset-tolerance", help="Seconds within which a played onset matches the reference."
    ),
    json_path: Optional[Path] = typer.Option(
        None, "--json", help="Also write every figure and the per-note table to this JSON file."
    ),
    plot: Optional[Path] = typer.Option(
        None, "--plot", help="Draw both piano rolls with the errors marked to this PNG file."
    ),
    html: Optional[Path] = HtmlReport,
    notes: int = typer.Option(
        SCORE_NOTES, "--notes", min=0, metavar="N", help="Print the per-note table's first N rows (0: none)."
    ),
    no_notes: bool = typer.Option(False, "--no-notes", hidden=True, help="The same as --notes 0 (older scripts)."),
    every: bool = AllFigures,
    reading: Reading = None,
):
    """Compare a performance with its reference: note F1, velocity and timing errors, fingering.

    The reading options apply to the reference, as `play` applied them to the piece it played:
    `pianobot score out.mid original.mid --hand right --transpose -3` compares like with like.
    A two-hand reference (as `play` reads it) is scored as a whole and for each hand."""
    from pianobot.cli import display
    from pianobot.music import midi_io
    from pianobot.music.metrics import plot_report
    from pianobot.music.per_hand import compare_hands

    if not 0 < onset_tolerance <= 1:
        raise PianobotError(f"--onset-tolerance {onset_tolerance}: give seconds between 0 and 1, e.g. 0.05")
    if plot is not None and plot.suffix.lower() != ".png":
        raise PianobotError(f"--plot {plot}: the plot is a PNG image, name the file *.png")
    to_stdout = json_path is not None and str(json_path) == "-"
    check_html(html)
    check_files(
        {"the performance": played, "the reference": reference, "the fingering file": reading.options.fingering},
        {"--json": json_path, "--plot": plot, "--html": html},
    )
    for target in (None if to_stdout else json_path, plot, html):
        if target is not None:
            check_writable(target)
    console = err if to_stdout else out  # standard output carries the JSON
    # the fingers and keys play chose (they may read the hands otherwise), nothing said again
    read = read_file(reference, reading, finger=False, quiet=True, fit=False)
    reference_piece = read.hands.piece if read.both else read.part  # as play scored it (with --hand, reduced)
    performance = midi_io.open_midi(played)  # (read once: its notes, then its pedal)
    played_piece = midi_io.read_midi(performance)
    pedals = (read.pedal, midi_io.read_pedal(performance) if reading.options.pedal else read.pedal)
    scores = compare_hands(reference_piece, played_piece, onset_tolerance=onset_tolerance, pedals=pedals)
    report = scores.whole
    if scores.hands:
        console.print(display.hands_scores_table(scores))
    display.print_all(console, display.report_tables(report, every, 0 if no_notes else notes))
    given = reading.options
    hint = mismatch_hint(reference_piece, played_piece, report.f1, onset_tolerance, given.transpose, given.tempo)
    if hint:
        console.print(f"[yellow]{hint}[/yellow]", soft_wrap=True)
    if json_path is not None:
        hands = {"hands": {hand: r.summary() for hand, r in scores.hands.items()}} if scores.hands else {}
        write_json(json_path, {**report.to_dict(), **hands})
        if not to_stdout:
            console.print(f"figures written to {said(json_path)}")
    if plot is not None:
        plot_report(reference_piece, played_piece, report, plot)
        console.print(f"piano rolls drawn to {said(plot)}")
    if html is not None:
        from pianobot.perform.report import write_html

        write_html(html, report, f"{played.name} against {reference.name}", scores=scores)
        console.print(f"report to open in a browser written to {said(html)}")


def mismatch_hint(
    reference, played, f1: float, tolerance: float, transpose: int = 0, tempo: float | None = None
) -> str:
    """Where a performance scores low against its reference (note F1 under 0.5), what reading
    option may differ: every note shifted by the same interval (``--transpose``), or a performance
    much longer or shorter than the reference (``--tempo``); '' where neither. ``transpose`` and
    ``tempo``: the options the reference was read with, so the hint names the value to give instead
    (none, where the performance was played without one)."""
    if f1 >= 0.5 or not reference.notes or not played.notes:
        return ""
    import bisect

    onsets = sorted((n.onset, n.pitch) for n in reference.notes)
    times = [t for t, _ in onsets]

    def matched(shift: int) -> int:
        count = 0
        for note in played.notes:
            low = bisect.bisect_left(times, note.onset - tolerance)
            high = bisect.bisect_right(times, note.onset + tolerance)
            count += any(pitch == note.pitch - shift for _, pitch in onsets[low:high])
        return count

    best = max(range(-48, 49), key=lambda shift: (matched(shift), -abs(shift)))
    if best != 0 and matched(best) >= 0.8 * min(len(played), len(reference)):
        lie = f"{matched(best)} of the {len(played)} played notes lie {abs(best)} semitones {'above' if best > 0 else 'below'} the reference's"
        if transpose + best == 0:
            return f"{lie} as read with --transpose {transpose}: if the piece was played without --transpose, score it without"
        return f"{lie}: if the piece was played with --transpose {transpose + best}, score it with the same option"
    ratio = played.duration / reference.duration if reference.duration else 1.0
    if not 0.8 <= ratio <= 1.25:
        lasts = f"the performance lasts {played.duration:.1f} s and the reference {reference.duration:.1f} s"
        if tempo is not None:
            return (
                f"{lasts} read with --tempo {tempo:g}: if the piece was played at another tempo, score it with that "
                "one, or without --tempo if it was played without"
            )
        return f"{lasts}: if the piece was played with --tempo, score it with the same option"
    return ""
