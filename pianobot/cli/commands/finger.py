"""The `pianobot finger` command."""

from __future__ import annotations

from pathlib import Path

import typer

from pianobot.cli.flags import phrase
from pianobot.cli.options import (
    AllRows,
    Reading,
    check_files,
    check_midi_output,
    read_file,
    reads,
)
from pianobot.cli.terminal import out, said
from pianobot.files import check_writable
from pianobot.music.phrases import DEFAULT_MAX_NOTES


@reads(without=("fingering", "refinger"))
def finger(
    song: Path = typer.Argument(..., help="A .mid file or a MusicXML score, with or without fingering."),
    output: Path = typer.Option(
        ...,
        "--output",
        "-o",
        help="Write the fingered piece to this .mid file, or a MusicXML score (.musicxml, .xml, .mxl) with fingering marks.",
    ),
    all_rows: bool = AllRows,
    reading: Reading = None,
):
    """Plan a fingering for the robot hand (least wrist travel within its reach) and write it to a MIDI file
    or a MusicXML score (by -o's suffix); for a two-hand file (as `play` reads it), each hand's, one track
    (or staff) per hand."""
    from pianobot.cli import display
    from pianobot.music.instrument import check_playable
    from pianobot.music.midi_io import write_midi
    from pianobot.music.musicxml import is_musicxml, music21
    from pianobot.music.phrases import split_phrases
    from pianobot.pianist.assign import finger_hands
    from pianobot.pianist.fingering import ensure_fingering

    check_midi_output(output, song, "the fingered piece", score=True)
    write = write_midi
    if is_musicxml(output):
        from pianobot.music.musicxml_out import write_musicxml as write

        music21()  # (refused now, before the work, where music21 is missing)
    check_files({"the input": song, "the fingering file": reading.options.fingering}, {"-o": output})
    check_writable(output)
    read = read_file(song, reading, finger=False)
    keyboard, hand_spec, hands = read.keyboard, read.fingers, read.hands
    if hands is not None:  # a two-hand file: each hand fingered, one track each
        fingered = finger_hands(hands.piece, hand_spec, refinger=True)
        write(fingered.piece, output, name=f"{song.stem} fingered by pianobot")
        out.print(display.notes_table(fingered.piece, [], None if all_rows else display.ROWS))
        for hand, plan in fingered.plans.items():
            count = len(fingered.piece.part(hand))
            travel = (
                f"wrist travel {plan.travel * 100:.1f} cm in {plan.moves} move{'s' * (plan.moves != 1)}"
                if plan
                else "as the file had it"
            )
            out.print(f"{hand} hand, fingers {hand_spec.describe()}: {travel} over {count} notes", soft_wrap=True)
            for problem in plan.said() if plan else ():
                out.print(
                    f"[yellow]{'cannot be played at this tempo: ' * (problem in plan.problems)}[/yellow]{said(phrase(problem))}"
                )
        kept = len(fingered.piece)
        less = (
            f"; {kept} of {len(hands.piece)} notes, the others reduced away: the warnings say why"
            if kept < len(hands.piece)
            else ""
        )
        each = "one staff per hand" if is_musicxml(output) else "one track per hand"
        out.print(f"fingering for both hands written to {said(output)} ({each}{less})", soft_wrap=True)
        return
    piece = read.part
    check_playable(piece.without_fingering(), keyboard, hand_spec, reading.options.transpose)  # (the whole shift)
    had = sum(n.finger is not None for n in piece.notes)
    piece, plan = ensure_fingering(piece, keyboard, hand_spec, refinger=True)
    write(piece, output, name=f"{song.stem} fingered by pianobot")
    out.print(display.notes_table(piece, split_phrases(piece, DEFAULT_MAX_NOTES), None if all_rows else display.ROWS))
    out.print(
        f"fingering for fingers {hand_spec.describe()} written to {said(output)}: wrist travel {plan.travel * 100:.1f} cm "
        f"in {plan.moves} move{'s' * (plan.moves != 1)} over {len(piece)} notes"
    )
    for problem in plan.said():
        out.print(
            f"[yellow]{'cannot be played at this tempo: ' * (problem in plan.problems)}[/yellow]{said(phrase(problem))}"
        )
    if had:
        out.print(
            f"[yellow]the file's own fingering ({had} of {len(piece)} notes) was replaced by the planner's[/yellow] "
            "(play the file itself to play as it is fingered)",
            soft_wrap=True,
        )
