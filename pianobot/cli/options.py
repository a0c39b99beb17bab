"""The options several commands share, and the helpers that turn them into library objects."""

from __future__ import annotations

import contextlib
import os
import warnings
from pathlib import Path

import typer

from pianobot.errors import PianobotError, PianobotWarning, quote
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.piece import Piece, parse_pitch, pitch_name


@contextlib.contextmanager
def option(name: str | None = None, value=None):
    """Phrase a library's ValueError about an option's value (or about options together: no
    name) as the command's error."""
    try:
        yield
    except ValueError as e:
        raise PianobotError(f"{name} {quote(str(value))}: {e}" if name else str(e)) from None


# -- shared options --------------------------------------------------------------------------
Track = typer.Option(None, "--track", help="Read only this track (index or name); default: merge all tracks.")
Tempo = typer.Option(None, "--tempo", help="Re-time the piece at this constant tempo in bpm (the paper uses 60).")
Transpose = typer.Option(LoadOptions.transpose, "--transpose", help="Shift every note by this many semitones.")
Fingering = typer.Option(
    None,
    "--fingering",
    help="PIG fingering file for the notes (default: <song>_fingering.txt beside the .mid, if any).",
)
LowestNote = typer.Option(
    pitch_name(KeyboardSpec.lowest), "--lowest-note", help="Lowest key of the keyboard (name like C4, or MIDI number)."
)
Keys = typer.Option(KeyboardSpec.count, "--keys", help="Number of keys on the keyboard.")
Thumb = typer.Option(False, "--thumb", help="Let the hand use its thumb (finger 1) too.")
PhraseNotes = typer.Option(DEFAULT_MAX_NOTES, "--phrase-notes", help="Most notes in one phrase (one policy each).")
GeneralPolicy = typer.Option(
    None,
    "--general-policy",
    help="The general policy's folder (any trained policy; default: the newest `pianobot train --task melody` "
    "policy in --models whose environment fits).",
)
PlayPhraseNotes = typer.Option(
    None,
    "--phrase-notes",
    help=f"Most notes in one phrase (default: the longest phrases, up to {DEFAULT_MAX_NOTES} notes, whose policies are all trained).",
)
Hand = typer.Option(
    None,
    "--hand",
    help="Play one hand's part of a two-hand piece: right or left (tracks named for it, else split by pitch).",
)
Split = typer.Option(
    pitch_name(LoadOptions.split),
    "--split",
    help="With --hand and no track named for it: lowest note of the right hand's part.",
)
Quantize = typer.Option(
    None, "--quantize", help="Move onsets and offsets to a grid, e.g. 1/16 (for recordings of human players)."
)
AllRows = typer.Option(False, "--all", help="List every note and phrase (by default the tables stop after 100 rows).")
Refinger = typer.Option(
    LoadOptions.refinger,
    "--refinger",
    help="Replace the file's fingering with the planner's (e.g. human fingering for five fingers).",
)


def make_options(
    track, tempo, transpose, fingering, hand=None, split=None, quantize=None, refinger=False
) -> LoadOptions:
    split = LoadOptions.split if split is None else parse_pitch(split)
    return LoadOptions(
        track=track,
        tempo=tempo,
        transpose=transpose,
        fingering=fingering,
        hand=hand,
        split=split,
        quantize=quantize,
        refinger=refinger,
    )


def check_midi_output(output: Path, song: Path, what: str) -> None:
    """-o must name a .mid file other than the input."""
    if output.suffix.lower() not in (".mid", ".midi"):
        raise PianobotError(f"-o {output}: {what} is a MIDI file, name it *.mid")
    if os.path.realpath(output) == os.path.realpath(song):  # (realpath: a symbolic-link loop is no crash)
        raise PianobotError(f"-o {output} would overwrite the input {song.name}: choose another file name")


def read_song(song: Path, options: LoadOptions, keyboard: KeyboardSpec, hand: HandSpec) -> Piece:
    """Load a piece for this hand and keyboard; finger it with the planner when it has no fingering."""
    from pianobot.music.instrument import check_playable
    from pianobot.pianist.fingering import ensure_fingering
    from pianobot.pianist.reduce import load_for_hand

    piece = load_for_hand(song, options, keyboard, hand)  # with --hand, reduced to what the hand can play
    piece, plan = ensure_fingering(piece, keyboard, hand, options.refinger)
    if plan is not None:
        why = "--refinger" if options.refinger else "it has notes without fingering"
        warnings.warn(
            PianobotWarning(
                f"{song.name}: fingering planned for fingers {', '.join(map(str, hand.fingers))} ({why}): "
                f"wrist travel {plan.travel * 100:.1f} cm in {plan.moves} moves; `pianobot finger` writes it to a file"
            )
        )
        for problem in plan.problems:
            warnings.warn(PianobotWarning(problem))
    check_playable(piece, keyboard, hand)
    return piece


def make_instrument(lowest_note: str, keys: int, thumb: bool) -> tuple[KeyboardSpec, HandSpec]:
    hand = HandSpec(fingers=(1,) + HandSpec.fingers if thumb else HandSpec.fingers)
    return KeyboardSpec(lowest=parse_pitch(lowest_note), count=keys), hand


def refuse_training_into(start: Path | None, jobs) -> None:
    """One line, before any work, when the policy to start from is a folder this run trains into
    (the same options, so the same hash): ``--force`` would delete it before it is read."""
    if start is not None and any(job.folder.resolve() == Path(start).resolve() for job in jobs):
        raise PianobotError(
            f"--general-policy {start} is the folder this run trains into: copy it elsewhere and start from the copy"
        )
