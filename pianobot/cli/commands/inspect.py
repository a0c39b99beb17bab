"""The `pianobot inspect` command."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Optional

import typer

from pianobot.cli.flags import phrase
from pianobot.cli.options import (
    DEFAULT_STORE,
    AllRows,
    PlayPhraseNotes,
    Reading,
    check_files,
    check_models,
    read_file,
    reads,
)
from pianobot.cli.terminal import err, out, said, write_json
from pianobot.errors import PianobotError
from pianobot.files import check_writable
from pianobot.music.piece import pitch_name

MODELS_OPTION = typer.Option(
    DEFAULT_STORE, "--models", help="Model store whose trained phrase split to show (as play uses it)."
)
JSON_PATH_OPTION = typer.Option(
    None, "--json", help="Also write what inspect found to this JSON file ('-': standard output)."
)


@reads()
def inspect(
    song: Path = typer.Argument(
        ..., help="A .mid file, a MusicXML score (.musicxml, .xml, .mxl) or a PIG fingering .txt file."
    ),
    phrase_notes: Optional[int] = PlayPhraseNotes,
    models: Path = MODELS_OPTION,
    all_rows: bool = AllRows,
    json_path: Optional[Path] = JSON_PATH_OPTION,
    reading: Reading = None,
):
    """Explain what a file holds (tracks, hands, pedal, range, polyphony, fingering) and whether the hand can play it."""
    from pianobot.cli import display
    from pianobot.music.instrument import check_playable
    from pianobot.perform.compose import missing_phrases, phrase_players, trained_split
    from pianobot.pianist.fingering import ensure_fingering
    from pianobot.pianist.reading import open_song

    options, keyboard, hand_spec = reading.options, reading.keyboard, reading.hand
    to_stdout = json_path is not None and str(json_path) == "-"
    check_files({"the input": song, "the fingering file": options.fingering}, {"--json": json_path})
    check_models(models)
    if json_path is not None and not to_stdout:
        check_writable(json_path)
    console = err if to_stdout else out  # standard output carries the JSON
    source = open_song(song)  # (the file read once: all below derives from it)
    tracks, named, tempi = _show_tracks(console, song, source, options)
    try:
        read = read_file(source, reading, finger=False, models=models)
    except PianobotError:
        if named:
            raise  # the two-hand reading's refusal (notes beyond the piano)
        read = None  # one hand's reading, below, says what it found, then what is wrong
    both = None if read is None else read.hands
    if both is not None:
        _both_hands(console, both, tracks, json_path, tempi, read.fingers)
        return
    if len([t for t in tracks if t.notes]) > 1 and options.track is None and options.hand is None:
        console.print("[yellow]several tracks are merged; play one part with --track N or --hand right|left[/yellow]")
    if read is None:
        read = read_file(source, reading, finger=False, both=False, models=models)
    keyboard, hand_spec, piece = read.keyboard, read.fingers, read.part
    line, data = _summary(piece, tempi)
    console.print(line)
    if options.hand is not None:
        import warnings

        from pianobot.music.load import load_piece

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (said as the part was read)
            written = len(load_piece(source, options))
        if written > len(piece):
            console.print(
                f"[yellow]the {options.hand} hand's part has {written} notes: the hand is given {len(piece)} "
                "of them, the others left out or reduced (the warnings say which)[/yellow]"
            )
            data["part_notes"] = written
    # the keyboard and the chords, before the split (a transposition it suggests counts --transpose in)
    check_playable(piece.without_fingering(), keyboard, hand_spec, options.transpose)
    piece, plan = ensure_fingering(piece, keyboard, hand_spec, options.refinger)
    if plan is not None:
        console.print(
            f"fingering planned for fingers {hand_spec.describe()}: wrist travel {plan.travel * 100:.1f} cm in {plan.moves} move{'s' * (plan.moves != 1)}"
        )
        for problem in plan.said():
            console.print(f"[yellow]{said(phrase(problem))}[/yellow]")
    phrases = trained_split(models, piece, phrase_notes)
    rows = None if all_rows else display.ROWS
    console.print(display.notes_table(piece, phrases, rows))
    missing = {p.index for p in missing_phrases(models, phrases)}
    players = phrase_players(models, phrases)
    console.print(display.phrases_table(phrases, players, rows))
    check_playable(piece, keyboard, hand_spec)
    console.print(f"[green]playable[/green] on {keyboard.describe()} with fingers {hand_spec.describe()}")
    if json_path is not None:
        write_json(
            json_path,
            {
                "tracks": [{"index": t.index, "name": t.name, "notes": t.notes, "pedal": t.pedal} for t in tracks],
                **data,
                "playable": True,
                "keyboard": keyboard.describe(),
                "hand_model": hand_spec.model,
                "fingers": list(hand_spec.fingers),
                "phrases": [
                    {
                        "index": p.index,
                        "hash": p.hash,
                        "notes": [n.name for n in p.notes],
                        "start": p.start,
                        "end": p.end,
                        "trained": p.index not in missing,
                        "played_by": players[p.index],
                    }
                    for p in phrases
                ],
            },
        )


def _show_tracks(console, song: Path, source, options) -> tuple[list, bool, list | None]:
    """A MIDI file's tracks, which hands they name and its pedal, printed: (tracks, whether any
    track names a hand, the tempos (None with --tempo))."""
    from pianobot.cli import display
    from pianobot.music import midi_io
    from pianobot.music.load import HANDS, hand_tracks

    tracks, named, tempi = [], False, None
    if song.suffix.lower() != ".txt":
        tracks = midi_io.describe_tracks(source)
        tempi = None if options.tempo is not None else midi_io.tempi(source)  # (--tempo re-times it at one tempo)
        hands = {i: h for h in HANDS for i in hand_tracks(tracks, h)}
        named = bool(hands)
        console.print(display.tracks_table([replace(t, name=said(t.name)) for t in tracks], hands))
        with_notes = [t for t in tracks if t.notes]
        pedal = sum(t.pedal for t in tracks)
        console.print(
            f"{len(with_notes)} track(s) with notes"
            + (f"; {_hand_parts(tracks)}" if hands else "")
            + (
                f"; sustain pedal pressed {pedal} times (play presses it as written; --no-pedal leaves it up)"
                if pedal
                else "; no sustain pedal"
            )
        )
    return tracks, named, tempi


def _summary(piece, tempi: list[float] | None = None) -> tuple[str, dict]:
    """A piece in one line (its notes, length, tempo, range, polyphony, velocities, fingering), and as
    JSON; ``tempi``: the file's tempos, where it changes tempo and no --tempo re-times it."""
    polyphony, _ = piece.max_polyphony()
    given = sum(n.finger is not None for n in piece.notes)
    low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
    velocities = sorted({n.velocity for n in piece.notes})
    tempo = f"{piece.bpm:.0f} bpm"
    if tempi and len(tempi) > 1:
        tempo += f", then {len(tempi) - 1} other tempo{'s' * (len(tempi) > 2)} ({min(tempi):.0f}-{max(tempi):.0f} bpm)"
    line = (
        f"{len(piece)} note{'s' * (len(piece) != 1)}, {piece.duration:.2f} s at {tempo}; range {pitch_name(low)}-{pitch_name(high)} "
        f"({high - low} semitones); at most {polyphony} note{'s' * (polyphony != 1)} at once; velocities {velocities[0]}-{velocities[-1]}; "
        f"{given}/{len(piece)} notes fingered in the file"
    )
    data = {
        "notes": len(piece),
        "duration": piece.duration,
        "bpm": piece.bpm,
        "tempi": list(tempi) if tempi else [piece.bpm],
        "range": [pitch_name(low), pitch_name(high)],
        "polyphony": polyphony,
        "fingered_in_file": given,
    }
    return line, data


def _both_hands(console, reading, tracks, json_path, tempi, fingers) -> None:
    """What `inspect` says of a file `play` plays with both hands: each hand in play's words, and
    the hand (``fingers``: the model and fingers the reading chose)."""
    from pianobot.perform.together import TOGETHER

    line, data = _summary(reading.piece, tempi)
    console.print(line)
    for hand in reading.piece.hands:
        console.print(said(reading.describe(hand)), soft_wrap=True)
    console.print(
        f"[green]two hands[/green]: `pianobot play` plays both, {TOGETHER}, with fingers {said(fingers.describe())}; "
        "--hand right|left plays one hand's part",
        soft_wrap=True,
    )
    if json_path is not None:
        write_json(
            json_path,
            {
                "tracks": [{"index": t.index, "name": t.name, "notes": t.notes, "pedal": t.pedal} for t in tracks],
                **data,
                "hands": {hand: reading.to_dict(hand) for hand in reading.piece.hands},
                "played_as": f"both hands, {TOGETHER}",
                "hand_model": fingers.model,
                "fingers": list(fingers.fingers),
            },
        )


def _hand_parts(tracks) -> str:
    """Which tracks each hand's name is on, in the words `--hand` warns with when none is."""
    from pianobot.music.load import HANDS, hand_tracks

    parts = []
    for hand in HANDS:
        named = hand_tracks(tracks, hand)
        if named:
            parts.append(f"track{'s' * (len(named) > 1)} {', '.join(map(str, named))} named for the {hand} hand")
        else:
            parts.append(f"no track is named for the {hand} hand")
    return ", ".join(parts)
