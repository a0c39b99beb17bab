"""The `pianobot finger` command."""

from __future__ import annotations

from pathlib import Path

import typer

from pianobot.cli.flags import phrase
from pianobot.cli.options import (
    AllRows,
    Reading,
    check_midi_output,
    reads,
)
from pianobot.cli.terminal import out, said
from pianobot.files import check_writable
from pianobot.music.phrases import DEFAULT_MAX_NOTES


@reads(without=("fingering", "refinger"))
def finger(
    song: Path = typer.Argument(..., help="A .mid file, with or without fingering."),
    output: Path = typer.Option(..., "--output", "-o", help="Write the fingered piece to this .mid file."),
    all_rows: bool = AllRows,
    reading: Reading = None,
):
    """Plan a fingering for the robot hand (least wrist travel within its reach) and write it to a MIDI file."""
    from pianobot.cli import display
    from pianobot.music.midi_io import write_midi
    from pianobot.music.phrases import split_phrases
    from pianobot.pianist.fingering import ensure_fingering
    from pianobot.pianist.reduce import load_for_hand

    check_midi_output(output, song, "the fingered piece")
    check_writable(output)
    keyboard, hand_spec = reading.keyboard, reading.hand
    piece = load_for_hand(song, reading.options, keyboard, hand_spec)
    piece, plan = ensure_fingering(piece, keyboard, hand_spec, refinger=True)
    write_midi(piece, output, name=f"{song.stem} fingered by pianobot")
    out.print(display.notes_table(piece, split_phrases(piece, DEFAULT_MAX_NOTES), None if all_rows else display.ROWS))
    out.print(
        f"fingering for fingers {hand_spec.describe()} written to {said(output)}: wrist travel {plan.travel * 100:.1f} cm "
        f"in {plan.moves} moves over {len(piece)} notes"
    )
    for problem in plan.problems:
        out.print(f"[yellow]cannot be played at this tempo:[/yellow] {said(phrase(problem))}")
