"""The `pianobot` command line: thin wrappers that read arguments, call the library and print.

Every :class:`PianobotError` becomes one red line on stderr and exit code 2; warnings about
repaired input are printed in yellow and do not stop the command. Option defaults come from the
configuration dataclasses. The simulator, torch and the metrics are imported inside the commands
that need them, so that `pianobot --version` and `pianobot score` start quickly.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.markup import escape

from pianobot import __version__
from pianobot.agent.config import ACTORS, SACConfig
from pianobot.env.piano import EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.errors import PianobotError, PianobotWarning, one_line, quote
from pianobot.files import atomic_write, check_writable, why
from pianobot.learn.config import LEARNERS, MAX_ENVS, DaggerConfig, TrainConfig
from pianobot.learn.explore import EXPLORATIONS
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions
from pianobot.music.metrics import DEFAULT_ONSET_TOLERANCE
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.piece import Piece, parse_pitch, pitch_name
from pianobot.music.tasks import FAMILIES, MELODY, TASKS
from pianobot.perform.controllers import CONTROLLERS
from pianobot.sim.world import WorldConfig

app = typer.Typer(
    help="Teach a simulated robot hand with touch sensors to play the piano from MIDI files.",
    no_args_is_help=True,
    add_completion=True,
    pretty_exceptions_enable=False,
)
out = Console()
err = Console(stderr=True)

EXIT_BAD_INPUT = 2


def said(text) -> str:
    """Text for the terminal as it is: on one line, and any '[...]' in it not taken for rich markup."""
    return escape(one_line(str(text)))


def friendly(command):
    """Turn PianobotError into one red line + exit 2, and show warnings in yellow.

    An OSError that escaped the library (the file system failed us where no one expected it)
    gets the same one line, never a traceback.
    """

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PianobotWarning)
            try:
                return command(*args, **kwargs)
            except PianobotError as e:
                err.print(f"[red]error:[/red] {said(e)}", markup=True, highlight=False, emoji=False, soft_wrap=True)
                raise typer.Exit(EXIT_BAD_INPUT) from None
            except OSError as e:
                where = f"{e.filename}: " if e.filename else ""
                err.print(f"[red]error:[/red] {said(where + why(e))}", highlight=False, emoji=False, soft_wrap=True)
                raise typer.Exit(EXIT_BAD_INPUT) from None
            except KeyboardInterrupt:
                err.print("[yellow]interrupted[/yellow]")
                raise typer.Exit(130) from None
            finally:
                for w in caught:
                    if issubclass(w.category, PianobotWarning):
                        err.print(
                            f"[yellow]warning:[/yellow] {said(w.message)}", highlight=False, emoji=False, soft_wrap=True
                        )

    return wrapper


@contextlib.contextmanager
def option(name: str | None = None, value=None):
    """Phrase a library's ValueError about an option's value (or about options together: no
    name) as the command's error."""
    try:
        yield
    except ValueError as e:
        raise PianobotError(f"{name} {quote(str(value))}: {e}" if name else str(e)) from None


def write_json(path: Path, data: dict) -> None:
    """``data`` as JSON to ``path``, or to standard output when ``path`` is '-'."""
    text = json.dumps(data, indent=2) + "\n"
    if str(path) == "-":
        typer.echo(text, nl=False)
    else:
        atomic_write(path, text)


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


# -- commands --------------------------------------------------------------------------------
@app.command()
@friendly
def inspect(
    song: Path = typer.Argument(..., help="A .mid file (or a PIG fingering .txt file)."),
    track: Optional[str] = Track,
    tempo: Optional[float] = Tempo,
    transpose: int = Transpose,
    fingering: Optional[Path] = Fingering,
    hand_part: Optional[str] = Hand,
    split: str = Split,
    quantize: Optional[str] = Quantize,
    refinger: bool = Refinger,
    lowest_note: str = LowestNote,
    keys: int = Keys,
    thumb: bool = Thumb,
    phrase_notes: Optional[int] = PlayPhraseNotes,
    models: Path = typer.Option(
        Path("models"), "--models", help="Model store whose trained phrase split to show (as play uses it)."
    ),
    all_rows: bool = AllRows,
    json_path: Optional[Path] = typer.Option(
        None, "--json", help="Also write what inspect found to this JSON file ('-': standard output)."
    ),
):
    """Explain what a file holds (tracks, hands, pedal, range, polyphony, fingering) and whether the hand can play it."""
    from pianobot.cli import display
    from pianobot.music import midi_io
    from pianobot.music.instrument import check_playable
    from pianobot.music.load import HANDS, hand_tracks
    from pianobot.perform.compose import missing_phrases, trained_split
    from pianobot.pianist.fingering import ensure_fingering
    from pianobot.pianist.reduce import load_for_hand

    keyboard, hand_spec = make_instrument(lowest_note, keys, thumb)
    options = make_options(track, tempo, transpose, fingering, hand_part, split, quantize, refinger)
    to_stdout = json_path is not None and str(json_path) == "-"
    if json_path is not None and not to_stdout:
        check_writable(json_path)
    console = err if to_stdout else out  # standard output carries the JSON
    tracks = []
    if song.suffix.lower() != ".txt":
        tracks = midi_io.describe_tracks(song)
        hands = {i: h for h in HANDS for i in hand_tracks(tracks, h)}
        console.print(display.tracks_table([replace(t, name=said(t.name)) for t in tracks], hands))
        with_notes = [t for t in tracks if t.notes]
        pedal = sum(t.pedal for t in tracks)
        console.print(
            f"{len(with_notes)} track(s) with notes"
            + (f"; named for hands: {', '.join(f'{i} {h}' for i, h in sorted(hands.items()))}" if hands else "")
            + (
                f"; sustain pedal pressed {pedal} times (ignored: a note sounds while its key is down)"
                if pedal
                else "; no sustain pedal"
            )
        )
        if len(with_notes) > 1 and track is None and hand_part is None:
            console.print(
                "[yellow]several tracks are merged; play one part with --track N or --hand right|left[/yellow]"
            )
    piece = load_for_hand(song, options, keyboard, hand_spec)
    polyphony, _ = piece.max_polyphony()
    given = sum(n.finger is not None for n in piece.notes)
    low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
    velocities = sorted({n.velocity for n in piece.notes})
    console.print(
        f"{len(piece)} notes, {piece.duration:.2f} s at {piece.bpm:.0f} bpm; range {pitch_name(low)}-{pitch_name(high)} "
        f"({high - low} semitones); at most {polyphony} notes at once; velocities {velocities[0]}-{velocities[-1]}; "
        f"{given}/{len(piece)} notes fingered in the file"
    )
    piece, plan = ensure_fingering(piece, keyboard, hand_spec, refinger)
    if plan is not None:
        console.print(
            f"fingering planned for fingers {hand_spec.describe()}: wrist travel {plan.travel * 100:.1f} cm in {plan.moves} moves"
        )
        for problem in plan.problems:
            console.print(f"[yellow]{problem}[/yellow]")
    check_playable(piece.without_fingering(), keyboard, hand_spec)  # the keyboard and the chords, before the split
    phrases = trained_split(models, piece, phrase_notes)
    rows = None if all_rows else display.ROWS
    console.print(display.notes_table(piece, phrases, rows))
    missing = {p.index for p in missing_phrases(models, phrases)}
    console.print(display.phrases_table(phrases, {p.index for p in phrases} - missing, rows))
    check_playable(piece, keyboard, hand_spec)
    console.print(f"[green]playable[/green] on {keyboard.describe()} with fingers {hand_spec.describe()}")
    if json_path is not None:
        write_json(
            json_path,
            {
                "tracks": [{"index": t.index, "name": t.name, "notes": t.notes, "pedal": t.pedal} for t in tracks],
                "notes": len(piece),
                "duration": piece.duration,
                "bpm": piece.bpm,
                "range": [pitch_name(low), pitch_name(high)],
                "polyphony": polyphony,
                "fingered_in_file": given,
                "playable": True,
                "keyboard": keyboard.describe(),
                "fingers": list(hand_spec.fingers),
                "phrases": [
                    {
                        "index": p.index,
                        "hash": p.hash,
                        "notes": [n.name for n in p.notes],
                        "start": p.start,
                        "end": p.end,
                        "trained": p.index not in missing,
                    }
                    for p in phrases
                ],
            },
        )


@app.command()
@friendly
def finger(
    song: Path = typer.Argument(..., help="A .mid file, with or without fingering."),
    output: Path = typer.Option(..., "--output", "-o", help="Write the fingered piece to this .mid file."),
    track: Optional[str] = Track,
    tempo: Optional[float] = Tempo,
    transpose: int = Transpose,
    hand_part: Optional[str] = Hand,
    split: str = Split,
    quantize: Optional[str] = Quantize,
    lowest_note: str = LowestNote,
    keys: int = Keys,
    thumb: bool = Thumb,
    all_rows: bool = AllRows,
):
    """Plan a fingering for the robot hand (least wrist travel within its reach) and write it to a MIDI file."""
    from pianobot.cli import display
    from pianobot.music.midi_io import write_midi
    from pianobot.music.phrases import split_phrases
    from pianobot.pianist.fingering import ensure_fingering
    from pianobot.pianist.reduce import load_for_hand

    check_midi_output(output, song, "the fingered piece")
    check_writable(output)
    keyboard, hand_spec = make_instrument(lowest_note, keys, thumb)
    options = make_options(track, tempo, transpose, None, hand_part, split, quantize)
    piece = load_for_hand(song, options, keyboard, hand_spec)
    piece, plan = ensure_fingering(piece, keyboard, hand_spec, refinger=True)
    write_midi(piece, output, name=f"{song.stem} fingered by pianobot")
    out.print(display.notes_table(piece, split_phrases(piece, DEFAULT_MAX_NOTES), None if all_rows else display.ROWS))
    out.print(
        f"fingering for fingers {hand_spec.describe()} written to {said(output)}: wrist travel {plan.travel * 100:.1f} cm "
        f"in {plan.moves} moves over {len(piece)} notes"
    )
    for problem in plan.problems:
        out.print(f"[yellow]cannot be played at this tempo:[/yellow] {problem}")


@app.command()
@friendly
def score(
    played: Path = typer.Argument(..., help="The performance, a .mid file (e.g. written by `pianobot play`)."),
    reference: Path = typer.Argument(..., help="The reference score, a .mid file."),
    onset_tolerance: float = typer.Option(
        DEFAULT_ONSET_TOLERANCE, "--onset-tolerance", help="Seconds within which a played onset matches the reference."
    ),
    json_path: Optional[Path] = typer.Option(
        None, "--json", help="Also write every figure and the per-note table to this JSON file."
    ),
    plot: Optional[Path] = typer.Option(
        None, "--plot", help="Draw both piano rolls with the errors marked to this PNG file."
    ),
    notes: bool = typer.Option(True, "--notes/--no-notes", help="Print the per-note table."),
    track: Optional[str] = Track,
    tempo: Optional[float] = Tempo,
    transpose: int = Transpose,
    fingering: Optional[Path] = Fingering,
    hand_part: Optional[str] = Hand,
    split: str = Split,
    quantize: Optional[str] = Quantize,
    thumb: bool = Thumb,
):
    """Compare a performance with its reference: note F1, velocity and timing errors, fingering.

    The reading options apply to the reference, as `play` applied them to the piece it played:
    `pianobot score out.mid original.mid --hand right --transpose -3` compares like with like."""
    from pianobot.cli import display
    from pianobot.music import midi_io
    from pianobot.music.metrics import compare, plot_report
    from pianobot.pianist.reduce import load_for_hand

    if not 0 < onset_tolerance <= 1:
        raise PianobotError(f"--onset-tolerance {onset_tolerance}: give seconds between 0 and 1, e.g. 0.05")
    if plot is not None and plot.suffix.lower() != ".png":
        raise PianobotError(f"--plot {plot}: the plot is a PNG image, name the file *.png")
    to_stdout = json_path is not None and str(json_path) == "-"
    for target in (None if to_stdout else json_path, plot):
        if target is not None:
            check_writable(target)
    console = err if to_stdout else out  # standard output carries the JSON
    keyboard, hand = make_instrument(pitch_name(KeyboardSpec.lowest), KeyboardSpec.count, thumb)
    options = make_options(track, tempo, transpose, fingering, hand_part, split, quantize)
    reference_piece = load_for_hand(reference, options, keyboard, hand)  # with --hand, reduced as play reduces it
    played_piece = midi_io.read_midi(played)
    report = compare(reference_piece, played_piece, onset_tolerance=onset_tolerance)
    tables = display.report_tables(report)
    display.print_all(console, tables if notes else tables[:1])
    if json_path is not None:
        write_json(json_path, report.to_dict())
        if not to_stdout:
            console.print(f"figures written to {said(json_path)}")
    if plot is not None:
        plot_report(reference_piece, played_piece, report, plot)
        console.print(f"piano rolls drawn to {said(plot)}")


@app.command()
@friendly
def play(
    song: Path = typer.Argument(..., help="The piece to play, a .mid file with fingering."),
    output: Path = typer.Option(
        ..., "--output", "-o", help="Write what the simulated piano sounded to this .mid file."
    ),
    controller: str = typer.Option(
        CONTROLLERS[0],
        "--controller",
        help="Who plays: 'sac' (the trained phrase policies), 'scripted' (the hand-written pianist) or 'random'.",
    ),
    models: Path = typer.Option(Path("models"), "--models", help="Folder of the model store (for --controller sac)."),
    fallback: Optional[str] = typer.Option(
        None,
        "--fallback",
        help="'scripted': play phrases that have no trained policy with the scripted pianist (when no general policy "
        "plays them: a phrase's own policy first, then the general policy, then the fallback).",
    ),
    use_general: bool = typer.Option(
        True,
        "--general/--no-general",
        help="Play phrases without a policy of their own with the general policy (the newest `pianobot train --task "
        "melody` policy in --models, or --general-policy), when there is one.",
    ),
    general_policy: Optional[Path] = GeneralPolicy,
    wrist_guard: bool = typer.Option(
        False,
        "--wrist-guard/--no-wrist-guard",
        help="While a fingertip is low over the keys, the general policy's wrist slides no faster than the scripted "
        "pianist's does while holding a key (PianistTuning.hold_slide, 8 mm a step), so that a late release drags a "
        "finger across the keys less often (no effect on a policy trained with a discrete wrist).",
    ),
    phrase_notes: Optional[int] = PlayPhraseNotes,
    seed: int = typer.Option(
        0, "--seed", help="Seed of the simulation (the hand's start position) and of the random controller."
    ),
    video: Optional[Path] = typer.Option(None, "--video", help="Also record the performance to this .mp4 file."),
    wav: Optional[Path] = typer.Option(None, "--wav", help="Also synthesise what was played to this .wav file."),
    soundfont: Optional[Path] = typer.Option(
        None,
        "--soundfont",
        help="A General MIDI .sf2 soundfont for --wav and --video's sound (FluidSynth; default: an installed one, "
        "else sine waves).",
    ),
    gui: bool = typer.Option(False, "--gui", help="Show the simulation in a PyBullet window (needs a display)."),
    track: Optional[str] = Track,
    tempo: Optional[float] = Tempo,
    transpose: int = Transpose,
    fingering: Optional[Path] = Fingering,
    hand_part: Optional[str] = Hand,
    split: str = Split,
    quantize: Optional[str] = Quantize,
    refinger: bool = Refinger,
    lowest_note: str = LowestNote,
    keys: int = Keys,
    thumb: bool = Thumb,
):
    """Perform a piece in the simulator; write the played notes (velocities, fingers) and a velocity-error report."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from pianobot.agent.general import describe, find_general
    from pianobot.agent.policy import policy_configs
    from pianobot.cli import display
    from pianobot.music.midi_io import write_midi
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.audio import check_soundfont, write_wav
    from pianobot.perform.compose import (
        GENERAL_SOURCE,
        CompositionalController,
        general_for,
        missing_phrases,
        shared_env_config,
        trained_split,
    )
    from pianobot.perform.guard import WristGuard
    from pianobot.perform.perform import PLAY_CONFIG, perform, write_video
    from pianobot.sim.hand import HandConfig
    from pianobot.sim.keyboard import KeyboardConfig

    check_midi_output(output, song, "the performance")
    report_path = output.with_suffix(".report.json")
    for target in (output, report_path, video, wav):
        if target is not None:
            check_writable(target)
    if video is not None and video.suffix.lower() != ".mp4":
        raise PianobotError(f"--video {video}: the video is an MP4 file, name it *.mp4")
    if wav is not None and wav.suffix.lower() != ".wav":
        raise PianobotError(f"--wav {wav}: the audio is a WAV file, name it *.wav")
    if soundfont is not None:
        check_soundfont(soundfont)
    if gui and not os.environ.get("DISPLAY"):
        raise PianobotError("--gui needs a display (DISPLAY is not set): drop --gui, or use --video to watch it later")
    if controller not in CONTROLLERS:
        raise PianobotError(f"--controller {quote(controller)}: choose one of {', '.join(CONTROLLERS)}")
    if fallback not in (None, "scripted"):
        raise PianobotError(f"--fallback {quote(fallback)}: the only fallback is 'scripted'")
    if general_policy is not None and not use_general:
        raise PianobotError(f"--general-policy {general_policy} and --no-general ask for opposite things: give one")
    if general_policy is not None:
        find_general(models, path=general_policy)  # a folder that holds no policy: said before any work
    keyboard, hand = make_instrument(lowest_note, keys, thumb)
    piece = read_song(
        song, make_options(track, tempo, transpose, fingering, hand_part, split, quantize, refinger), keyboard, hand
    )
    world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=HandConfig(spec=hand), gui=gui)
    config = replace(PLAY_CONFIG, world=world)
    sources: dict = {}
    guards: list = []  # the wrist guard the general policy played through (one, shared by its sections)
    general = None  # the general policy's folder, when it plays a phrase
    who = controller
    if controller == "sac":
        import torch

        torch.set_num_threads(1)  # batch-1 inference: more threads only spin against other work on the cores
        phrases = trained_split(models, piece, phrase_notes)
        missing = missing_phrases(models, phrases)
        if phrase_notes is None and phrases != split_phrases(piece, DEFAULT_MAX_NOTES):
            most = max(len(p.notes) for p in phrases)
            out.print(
                f"[dim]{len(phrases)} phrases of at most {most} note{'s' * (most > 1)}: the split the policies in {said(models)} were trained for[/dim]"
            )
        trained = shared_env_config(models, phrases)  # the environment of the phrases' own policies
        if missing and use_general:  # a phrase's own policy, else the general policy, else the fallback
            general = general_for(models, trained, general_policy)
        if missing and general is None and not fallback:
            first = missing[0]
            raise PianobotError(
                f"phrase {first.index} ({' '.join(n.name for n in first.notes)}) of {song.name} has no trained policy in {models}: "
                f"train it with `pianobot train {song}` (same reading options), train a general policy with "
                f"`pianobot train --task melody`, add --fallback scripted, or play with --controller scripted"
            )
        if trained is None and general is not None:
            trained = policy_configs(general)[0]
        if trained is not None:
            config = replace(trained, world=replace(trained.world, gui=gui))
            if trained.world.keyboard.spec != keyboard or trained.world.hand.spec != hand:
                raise PianobotError(
                    f"the policies in {models} were trained for another keyboard or hand: use the same --lowest-note/--keys/--thumb"
                )
        if missing and general is None and config.world.control == "torque":
            raise PianobotError("--fallback scripted needs policies trained with --control velocity or position")

        def who(env):
            composed = CompositionalController(env, phrases, models, fallback is not None, general, wrist_guard)
            sources.update({p.index: s.source for s in composed.sections for p in s.phrases})
            guards.extend(s.controller for s in composed.sections if isinstance(s.controller, WristGuard))
            return composed

    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TimeRemainingColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,  # (a bar in a log is noise, and its last line break an empty line)
    ) as bar:
        task = bar.add_task(f"playing {said(song.name)}", total=None)
        result = perform(
            piece,
            who,
            config,
            seed=seed,
            video=video is not None,
            on_step=lambda done, total: bar.update(task, completed=done, total=total),
        )
    report = result.report()
    write_midi(result.played, output, name=f"pianobot {controller}: {song.stem}")
    extra = {"phrases": {str(k): v for k, v in sources.items()}} if sources else {}
    by_general = [k for k, v in sources.items() if v.startswith(GENERAL_SOURCE)]
    if by_general:
        extra["general_policy"] = describe(general)
        extra["wrist_guard"] = {"on": bool(guards), "slowed_steps": guards[0].capped if guards else 0}
    atomic_write(
        report_path, json.dumps({"controller": controller, "seed": seed, **extra, **report.to_dict()}, indent=2) + "\n"
    )
    if by_general:
        out.print(
            f"[yellow]phrases {', '.join(map(str, by_general))} had no policy of their own and were played by the "
            f"general policy {said(general)}[/yellow]",
            soft_wrap=True,  # (one line, the path whole)
        )
    fallbacks = [k for k, v in sources.items() if "fallback" in v]
    if fallbacks:
        out.print(
            f"[yellow]phrases {', '.join(map(str, fallbacks))} had no trained policy and were played by the scripted pianist[/yellow]"
        )
    display.print_all(out, display.report_tables(report))
    out.print(f"performance written to {said(output)}, report to {said(report_path)}")
    if video is not None:
        import tempfile

        with tempfile.TemporaryDirectory() as scratch:  # the sound, starting with the first frame
            method = write_wav(result.played, Path(scratch) / "sound.wav", font=soundfont, delay=result.start)
            write_video(result.frames, video, fps=config.world.control_hz, audio=Path(scratch) / "sound.wav")
        out.print(f"video written to {said(video)}, with sound ({method})")
    if wav is not None:
        method = write_wav(result.played, wav, font=soundfont)
        out.print(f"audio written to {said(wav)} ({method})")


@app.command()
@friendly
def train(
    song: Optional[Path] = typer.Argument(None, help="A .mid file with fingering; leave out with --task."),
    task: Optional[str] = typer.Option(
        None,
        "--task",
        help=f"Train on a task family instead, a fresh random instance each episode: the paper's {', '.join(TASKS)}, "
        f"or {MELODY} (random one-hand phrases of up to {DEFAULT_MAX_NOTES} notes in every key, fingered by the "
        "planner; docs/training.md).",
    ),
    steps: int = typer.Option(
        TrainConfig.steps,
        "--steps",
        help="Environment steps per phrase (of all --envs together), exploration included.",
    ),
    seed: int = typer.Option(
        TrainConfig.seed, "--seed", help="Seed of the simulation, the exploration and the networks."
    ),
    learner: str = typer.Option(
        TrainConfig.learner,
        "--learner",
        help="How policies learn: sac (Soft Actor-Critic from the rewards, the paper's) or dagger (imitating the "
        f"scripted pianist in rounds of {DaggerConfig.round_steps} steps, every step labelled with its action; "
        "needs --control velocity or position; docs/training.md).",
    ),
    round_steps: int = typer.Option(
        DaggerConfig.round_steps,
        "--round-steps",
        help="With --learner dagger: environment steps gathered in a round, after which the policy learns from every "
        "step gathered so far and is evaluated (a round ends at the first episode end after them).",
    ),
    until_f1: Optional[float] = typer.Option(
        TrainConfig.until_f1,
        "--until-f1",
        help="Stop a phrase early once an evaluation reaches this note F1 (e.g. 0.95); default: train every step, "
        f"or, starting from the general policy, stop at {TrainConfig.finetune_until_f1}.",
    ),
    from_general: bool = typer.Option(
        TrainConfig.from_general,
        "--from-general/--no-from-general",
        help="Start every phrase from the general policy (the newest `pianobot train --task melody` policy in --models "
        "whose options are this run's, or --general-policy): load its actor, encoder, critic and temperature (Adam "
        "starts afresh), evaluate it before any training step, and stop the phrase at the first evaluation that "
        f"reaches note F1 {TrainConfig.finetune_until_f1} (--until-f1 sets another), keeping the best evaluated "
        "policy: a phrase the general policy already plays costs one evaluation, and none ends worse than the "
        "general policy plays it. Without a general policy, or with --no-from-general, phrases train from scratch. "
        "With --task: on only when --general-policy is given.",
    ),
    general_policy: Optional[Path] = typer.Option(
        None,
        "--general-policy",
        help="The policy to start from (any trained policy; default: the newest `pianobot train --task melody` "
        "policy in --models whose options fit). With --task there is no default: a task family trains from scratch, "
        "or, given this, that policy's training goes on, on the family.",
    ),
    workers: int = typer.Option(1, "--workers", help="Train this many phrases at once, in separate processes."),
    threads: int = typer.Option(
        1, "--threads", help="Torch threads per training process (workers x threads should not exceed the cores)."
    ),
    envs: int = typer.Option(
        TrainConfig.envs,
        "--envs",
        help="Environments each policy's training steps at once: 1 in the training process, more each in a worker "
        "process of its own.",
    ),
    device: str = typer.Option(
        TrainConfig.device,
        "--device",
        help="Where the learner's networks and updates run: auto (cuda when torch sees a GPU, else cpu), cpu or cuda.",
    ),
    control: str = typer.Option(
        WorldConfig.control,
        "--control",
        help="Finger control: velocity (joint speeds), position (joint angle targets) or torque.",
    ),
    reward: str = typer.Option(RewardConfig.kind, "--reward", help="Reward: linear, squared or wasserstein."),
    explore: str = typer.Option(
        TrainConfig.explore, "--explore", help=f"Exploration before learning: {', '.join(EXPLORATIONS)}."
    ),
    exploration_steps: int = typer.Option(
        SACConfig.exploration_steps, "--exploration-steps", help="Steps of exploration before learning starts."
    ),
    actor: Optional[str] = typer.Option(
        None,
        "--actor",
        help=f"The actor's networks: {' or '.join(ACTORS)} (one MLP shared by the fingers; docs/training.md). "
        f"Default: the start policy's when training from one, else {SACConfig.actor}.",
    ),
    tactile: bool = typer.Option(
        EnvConfig.tactile, "--tactile/--no-tactile", help="Observe the fingertips' tactile images."
    ),
    joints: str = typer.Option(
        ",".join(EnvConfig.actuated),
        "--joints",
        help="Finger joints the policy moves, from abd,mcp,pip,dip; the others hold still.",
    ),
    fingering_gate: bool = typer.Option(
        RewardConfig.fingering_gate,
        "--fingering-gate/--no-fingering-gate",
        help="Reward a key only when the score's finger pressed it (the paper's fingering indicator).",
    ),
    force: bool = typer.Option(False, "--force", help="Retrain phrases that already have a stored policy."),
    models: Path = typer.Option(Path("models"), "--models", help="Folder of the model store."),
    cluster: str = typer.Option(
        "local",
        "--cluster",
        help="Where phrases train: 'local' (--workers processes here) or 'ray' (Ray tasks on the cluster RAY_ADDRESS "
        "names, or a local Ray runtime; needs pianobot[ray]).",
    ),
    json_path: Optional[Path] = typer.Option(
        None, "--json", help="Also write each policy's figures and files to this JSON file ('-': standard output)."
    ),
    track: Optional[str] = Track,
    tempo: Optional[float] = Tempo,
    transpose: int = Transpose,
    fingering: Optional[Path] = Fingering,
    hand_part: Optional[str] = Hand,
    split: str = Split,
    quantize: Optional[str] = Quantize,
    refinger: bool = Refinger,
    lowest_note: str = LowestNote,
    keys: int = Keys,
    thumb: bool = Thumb,
    phrase_notes: int = PhraseNotes,
):
    """Train one Soft Actor-Critic policy per phrase of a piece (or one for a task family) and store them."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from pianobot.agent import store
    from pianobot.agent.general import find_general
    from pianobot.agent.sac import resolve_device
    from pianobot.cli import display
    from pianobot.learn.jobs import general_start, phrase_jobs, plan_jobs, run_jobs, run_jobs_on_ray, task_job
    from pianobot.learn.log import LOG_FILE, PLOT_FILE
    from pianobot.learn.train import TASK_EVAL_EPISODES
    from pianobot.music.phrases import split_phrases
    from pianobot.sim.hand import HandConfig
    from pianobot.sim.keyboard import KeyboardConfig

    if (song is None) == (task is None):
        raise PianobotError("give a .mid file to train on, or --task NAME (not both)")
    if task is not None and task not in FAMILIES:
        raise PianobotError(f"--task {quote(task)}: choose one of {', '.join(FAMILIES)}")
    if workers < 1 or threads < 1:
        raise PianobotError(f"--workers {workers} --threads {threads}: give 1 or more of each")
    if not 1 <= envs <= MAX_ENVS:
        raise PianobotError(f"--envs {envs}: give 1 to {MAX_ENVS} environments")
    if learner not in LEARNERS:
        raise PianobotError(f"--learner {quote(learner)}: choose one of {', '.join(LEARNERS)}")
    if cluster not in ("local", "ray"):
        raise PianobotError(f"--cluster {quote(cluster)}: choose local or ray")
    resolve_device(device)  # a GPU asked for and missing: say so before any work
    cores = os.cpu_count() or 1
    # the environment workers step while the learner waits for them, and the learner updates while they wait
    busy = workers * max(threads, envs)
    if cluster == "local" and busy > cores:
        asked = f"--workers {workers} x --{'threads' if threads >= envs else 'envs'} {max(threads, envs)}"
        warnings.warn(
            PianobotWarning(
                f"{asked} asks for {busy} busy threads on {cores} cores: torch's thread pools then spin against each "
                f"other (measured up to 20x slower); keep workers x threads (and workers x envs) <= {cores}"
            )
        )
    if task is not None and workers > 1:
        warnings.warn(
            PianobotWarning(
                f"--task trains one policy: --workers {workers} has nothing to share out (--envs steps several environments)"
            )
        )
    if json_path is not None and str(json_path) != "-":
        check_writable(json_path)
    console = err if json_path is not None and str(json_path) == "-" else out  # standard output carries the JSON
    if models.exists() and not models.is_dir():
        raise PianobotError(f"--models {models} is a file: give a folder")
    keyboard, hand = make_instrument(lowest_note, keys, thumb)
    with option("--control", control):
        world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=HandConfig(spec=hand), control=control)
    with option("--reward", reward):
        rewards = RewardConfig(kind=reward, fingering_gate=fingering_gate)
    with option("--joints", joints):
        env = EnvConfig(
            world=world,
            reward=rewards,
            tactile=tactile,
            actuated=tuple(j.strip() for j in joints.split(",") if j.strip()),
        )
    with option("--round-steps", round_steps):
        DaggerConfig(round_steps=round_steps)
    if actor is not None and actor not in ACTORS:
        raise PianobotError(f"--actor {quote(actor)}: choose one of {', '.join(ACTORS)}")
    with option("--exploration-steps", exploration_steps):
        sac = SACConfig(exploration_steps=exploration_steps, actor=actor or SACConfig.actor)
    with option():
        config = TrainConfig(
            steps=steps,
            seed=seed,
            learner=learner,
            dagger=DaggerConfig(round_steps=round_steps),
            explore=explore,
            until_f1=until_f1,
            # a task family trains from scratch, or continues the policy --general-policy names
            from_general=from_general and (task is None or general_policy is not None),
            sac=sac,
            env=env,
            eval_episodes=TASK_EVAL_EPISODES if task is not None else TrainConfig.eval_episodes,
            envs=envs,
            device=device,
        )
    if general_policy is not None and not from_general:
        raise PianobotError(
            f"--general-policy {general_policy} and --no-from-general ask for opposite things: give one of them"
        )
    if general_policy is not None:
        find_general(models, path=general_policy)  # a folder that holds no policy: said before any work
    # where the run begins, before its folders are named: a run from a policy takes its networks
    config, start = general_start(config, models, general_policy, networks_given=actor is not None)
    if task is not None:
        job = task_job(task, config, models)
        refuse_training_into(general_policy, [job])
        todo, done = plan_jobs([job], force)
        label = f"task {task}"
        if start is not None and todo and store.checkpoint_state(job.folder) is None:  # (else it resumes, and says so)
            console.print(f"continuing the policy {said(start)} on {said(label)}: evaluated first", soft_wrap=True)
    else:
        piece = read_song(
            song, make_options(track, tempo, transpose, fingering, hand_part, split, quantize, refinger), keyboard, hand
        )
        phrases = split_phrases(piece, phrase_notes)
        jobs = phrase_jobs(phrases, config, models, piece=song.name)
        refuse_training_into(general_policy, jobs)
        label = f"{song.name}: {len(phrases)} phrases"
        if force or not all(store.is_trained(job.folder) for job in jobs):  # (before --force removes a policy)
            if start is not None:
                console.print(
                    f"starting every phrase from the general policy {said(start)}: evaluated first, a phrase stops at "
                    f"note F1 {config.stop_f1} (--no-from-general trains from scratch)",
                    soft_wrap=True,
                )
            elif from_general:
                console.print(
                    f"[dim]no general policy in {said(models)} (`pianobot train --task melody` trains one): "
                    "training from scratch[/dim]"
                )
        todo, done = plan_jobs(jobs, force)
    models.mkdir(parents=True, exist_ok=True)
    for job in done:
        console.print(
            f"phrase {job.key} ({', '.join(map(str, job.phrases))}) already trained in {said(job.folder)}: skipped (--force retrains)"
        )
    console.print(f"training {len(todo)} polic{'y' if len(todo) == 1 else 'ies'} for {said(label)}, {steps} steps each")
    returns: dict[str, float] = {}
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} steps"),
        TextColumn("{task.fields[status]}"),
        TimeRemainingColumn(),
        console=console,
    ) as bar:
        rows = {
            job.key: bar.add_task(f"phrase {job.key[:8]}" if task is None else job.key, total=steps, status="")
            for job in todo
        }

        def on_progress(key: str, progress) -> None:
            if progress.resumed:
                bar.console.print(
                    f"{bar.tasks[rows[key]].description}: resuming from its checkpoint at step {progress.step}"
                )
            if progress.finished:  # stopped early (--until-f1) or at its last step: the bar ends full
                bar.update(rows[key], total=progress.step, completed=progress.step)
                return
            status = bar.tasks[rows[key]].fields.get("status", "")
            if progress.episode_return is not None:
                returns[key] = progress.episode_return
            if progress.eval_f1 is not None:
                status = f"eval F1 {progress.eval_f1:.2f}"
            elif key in returns:
                status = f"return {returns[key]:.1f}" + (f" | {status.split(' | ')[-1]}" if "eval" in status else "")
            bar.update(rows[key], completed=progress.step, status=status)

        if cluster == "ray":
            results = run_jobs_on_ray(todo, config, on_progress, threads=threads, start=start)
        else:
            results = run_jobs(todo, config, workers, on_progress, threads=threads, start=start)
    trained = [(job, results.get(job.key) or store.read_manifest(job.folder)) for job in done + todo]
    console.print(display.training_table(trained))
    console.print(f"learning curves: {LOG_FILE} and {PLOT_FILE} in each policy's folder")
    if json_path is not None:
        summary = [
            {
                "key": job.key,
                "phrases": job.phrases,
                "folder": str(job.folder),
                "trained_now": job in todo,
                **{k: manifest.get(k) for k in ("steps", "updates", "seconds", "start", "evaluation")},
                "log": str(job.folder / LOG_FILE),
                "plot": str(job.folder / PLOT_FILE),
            }
            for job, manifest in trained
        ]
        write_json(json_path, {"policies": summary})


@app.command()
@friendly
def export(
    model: Path = typer.Argument(
        ..., help="A trained policy's folder in the model store, e.g. models/<phrase hash>-<config hash>."
    ),
    output: Path = typer.Option(..., "--output", "-o", help="Write the policy to this .onnx file."),
):
    """Export a trained policy to ONNX (for a robot or any ONNX runtime); docs/models.md gives its inputs."""
    from pianobot.agent.export import export_onnx

    if output.suffix.lower() != ".onnx":
        raise PianobotError(f"-o {output}: the export is an ONNX file, name it *.onnx")
    if not model.is_dir():
        raise PianobotError(
            f"{model} is not a folder: give a trained policy's folder in the model store (see `pianobot inspect`)"
        )
    export_onnx(model, output)
    out.print(f"policy {model.name} written to {output}")


def _version(value: bool):
    if value:
        out.print(f"pianobot {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Show the version and exit."
    ),
):
    """pianobot: teach a simulated robot hand to play the piano from MIDI files."""


if __name__ == "__main__":
    app()
