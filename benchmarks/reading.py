"""Reading long files: the timed side of two unit tests that bound the work instead
(tests/test_midi_io.py's tempo map, tests/test_pig.py's sidecar matching).

    python benchmarks/reading.py [--repeats 5]

- a tempo map of 8,000 tempo changes: the times of 16,000 ticks (each found by bisection;
  walking the changes instead took several seconds);
- a .mid file of those 8,000 tempo changes and 2,000 notes, read whole (``read_midi``);
- a PIG sidecar's fingering applied to a piece of 20,000 notes (``apply_fingering``: each note
  against the PIG notes of its pitch near its onset; every note against every note took minutes).

- both hands of a long real piece read as ``pianobot play`` reads a two-hand file, planned and
  reduced for the pianist's hands (``two_hands``, then ``prepare_parts``): the whole Maple Leaf Rag
  from music21's corpus (2,308 notes, 129 s; needs ``pip install -e ".[corpus]"``, else left out).
  With ``--peer DIR`` (a checkout of another pianobot commit, e.g. a ``git worktree``), the same figure
  of that checkout too, run after ours in a process of its own: the ratio of the medians is the speed-up.

Each figure is the median of ``--repeats`` runs, in a fresh temporary folder.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Callable

import mido

from pianobot.music.midi_io import _TempoMap, read_midi
from pianobot.music.piece import Note, Piece
from pianobot.music.pig import apply_fingering, write_pig

TEMPO_CHANGES = 8_000
LOOKUPS = 16_000
NOTES_IN_MIDI = 2_000
NOTES_IN_PIG = 20_000


def tempo_midi(notes: int = 0) -> mido.MidiFile:
    """A tempo change every 10 ticks (as the unit test has them), and ``notes`` notes of 40 ticks."""
    midi = mido.MidiFile(ticks_per_beat=480)
    midi.tracks.append(
        mido.MidiTrack(mido.MetaMessage("set_tempo", tempo=400_000 + i % 7, time=10) for i in range(TEMPO_CHANGES))
    )
    track = mido.MidiTrack()
    for i in range(notes):
        track.append(mido.Message("note_on", note=60 + i % 12, velocity=80, time=0))
        track.append(mido.Message("note_off", note=60 + i % 12, velocity=0, time=40))
    midi.tracks.append(track)
    return midi


def median_seconds(work: Callable[[Path], Callable[[], object]], repeats: int) -> float:
    """``work(folder)`` prepares one run and returns what to time."""
    seconds = []
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as folder:
            run = work(Path(folder))
            start = time.perf_counter()
            run()
            seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)


def tempo_lookups(folder: Path) -> Callable[[], object]:
    tempo_map = _TempoMap(tempo_midi(), folder / "t.mid")
    step = TEMPO_CHANGES * 10 // LOOKUPS
    return lambda: [tempo_map.seconds(tick) for tick in range(0, TEMPO_CHANGES * 10, step)]


def midi_read(folder: Path) -> Callable[[], object]:
    path = folder / "tempos.mid"
    tempo_midi(NOTES_IN_MIDI).save(path)
    return lambda: read_midi(path)


def pig_matching(folder: Path) -> Callable[[], object]:
    piece = Piece(tuple(Note(i * 0.1, 60 + i % 12, i * 0.1 + 0.1, 80, 2 + i % 3) for i in range(NOTES_IN_PIG)))
    write_pig(piece, folder / "many.txt")
    unfingered = piece.without_fingering()
    return lambda: apply_fingering(unfingered, folder / "many.txt")


LONG_PIECE = "joplin/maple_leaf_rag"
"""The long two-hand piece of music21's corpus that the last figure reads whole."""


def two_hand_reading(folder: Path) -> Callable[[], object]:
    import music21  # (the corpus extra)

    from pianobot.errors import PianobotWarning
    from pianobot.music.load import LoadOptions
    from pianobot.perform.together import prepare_parts, two_hands
    from pianobot.sim.hand import default_fingers

    path = folder / "long.mid"
    music21.corpus.parse(LONG_PIECE).write("midi", fp=str(path))
    fingers = default_fingers("pianist")

    def read() -> object:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PianobotWarning)
            return prepare_parts(two_hands(path, LoadOptions(), fingers).piece, None, fingers)

    return read


def _has_corpus() -> bool:
    try:
        import music21  # noqa: F401
    except ImportError:
        return False
    return True


def peer_seconds(peer: Path, repeats: int) -> float:
    """The long piece's median reading time with ``peer``'s pianobot: this script again, in a process of
    its own whose ``import pianobot`` finds the peer's (a failure: one line, exit code 2)."""
    env = {**os.environ, "PYTHONPATH": str(peer.resolve())}
    command = [sys.executable, str(Path(__file__).resolve()), "--long-only", "--repeats", str(repeats)]
    done = subprocess.run(command, env=env, cwd=peer, capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise SystemExit(f"the peer checkout {peer} could not read the long piece: {last}")
    return float(done.stdout)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--peer", type=Path, help="a checkout of another pianobot commit: its long piece's reading too")
    parser.add_argument("--long-only", action="store_true", help=argparse.SUPPRESS)  # (how --peer runs the peer)
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    if args.peer is not None and not (args.peer / "pianobot" / "__init__.py").is_file():
        parser.error(f"--peer {args.peer}: not a pianobot checkout (no pianobot/__init__.py there)")
    if args.peer is not None and not _has_corpus():
        parser.error("--peer times the long piece's reading, which needs music21: pip install -e '.[corpus]'")
    if args.long_only:
        print(median_seconds(two_hand_reading, args.repeats))
        return
    long = f"both hands of the whole Maple Leaf Rag ({LONG_PIECE}) read and reduced for the pianist's hands"
    figures = (
        (f"{LOOKUPS:,} tick times, {TEMPO_CHANGES:,} tempo changes", tempo_lookups),
        (f"read_midi: {TEMPO_CHANGES:,} tempo changes, {NOTES_IN_MIDI:,} notes", midi_read),
        (f"apply_fingering: a PIG sidecar of {NOTES_IN_PIG:,} notes", pig_matching),
    ) + (((long, two_hand_reading),) if _has_corpus() else ())
    print(f"| figure | median of {args.repeats} |" + (" peer | peer / ours |" if args.peer else ""))
    print("| --- | ---: |" + (" ---: | ---: |" if args.peer else ""))
    for name, work in figures:
        ours = median_seconds(work, args.repeats)
        peer = ""
        if args.peer and work is two_hand_reading:
            seconds = peer_seconds(args.peer, args.repeats)
            peer = f" {seconds:.1f} s | {seconds / ours:.1f}x |"
        elif args.peer:
            peer = " | |"
        print(f"| {name} | {ours:.3f} s |{peer}", flush=True)
    if not _has_corpus():
        print(f"(the reading of {LONG_PIECE} needs music21: pip install -e '.[corpus]')")


if __name__ == "__main__":
    main()
