"""What a user waits for: `pianobot play` end to end, start-up included, beside the simulation alone.

    python -m benchmarks.command [--runs 5] [--peer DIR]

Three commands, each run ``--runs`` times as a fresh process (`python -m pianobot play ... -q`):
one hand, the longest one-hand example (`mary.mid`, 19.2 s) with the scripted pianist; two
hands, a two-hand chorale (`chorale-performed.mid`, 41.6 s) with the default controller (the
packaged general policies through the hold guard), played by the pianist's hands (the default for
both hands) and by the Allegro-like hand (`--hand-model allegro`). Beside each, in the same run, the same
performance in this process after start-up (the plan performed and scored: what the command
adds is the difference). The commands run as a user's would: Python writes and reuses its
bytecode cache (``PYTHONDONTWRITEBYTECODE`` is dropped from their environment), and one untimed
run of each checkout fills it first, as any earlier use of the command does. With ``--peer DIR`` (a checkout of another pianobot commit, e.g. a
``git worktree``), the same commands of that checkout, run in turn with ours: the ratio of the
medians is the speed-up. Real-time factor: seconds of music per second of wall clock; medians.
Prints a Markdown table for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parent.parent
EXAMPLES = ROOT / "examples" / "midi"
COMMANDS = {
    "one hand, scripted pianist (`mary.mid`)": ("mary.mid", ["--controller", "scripted"]),
    "two hands, default controller: the pianist's hands (`chorale-performed.mid`)": ("chorale-performed.mid", []),
    "two hands, the Allegro-like hand (`chorale-performed.mid --hand-model allegro`)": (
        "chorale-performed.mid",
        ["--hand-model", "allegro"],
    ),
}


def command_seconds(song: str, options: list[str], scratch: Path, checkout: Path = ROOT) -> float:
    """Wall-clock seconds of `pianobot play <song>` in a fresh process, of the package in ``checkout``."""
    args = [sys.executable, "-m", "pianobot", "play", str(EXAMPLES / song), "-o", str(scratch / "o.mid"), "-q"]
    env = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
    started = time.perf_counter()
    subprocess.run([*args, *options], check=True, capture_output=True, cwd=checkout, env=env)
    return time.perf_counter() - started


def library_seconds(song: str, options: list[str]) -> float:
    """Wall-clock seconds of the same performance in this process, read, performed and scored (no start-up)."""
    import warnings

    import pianobot
    from pianobot.perform.together import read_hands
    from pianobot.sim.hand import default_fingers

    controller = "scripted" if "scripted" in options else "sac"
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if song == "mary.mid":
            piece, hand = pianobot.load_piece(EXAMPLES / song), {}
        else:  # (both hands: the pianist's, unless the options name the Allegro-like hand, as `play` reads them)
            spec = default_fingers("allegro" if "allegro" in options else "pianist")
            piece, hand = read_hands(EXAMPLES / song, spec=spec).piece, {"hand": spec}
        pianobot.play(piece, controller=controller, models=ROOT / "models", **hand).report()
    return time.perf_counter() - started


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--peer", type=Path, default=None, help="a checkout of another commit to time beside")
    args = parser.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    import pianobot

    head = "| command | music (s) | `pianobot play`, end to end: s, real-time factor | in process after start-up: s, factor"
    peer = " | the peer, end to end | speed-up" if args.peer else ""
    print(f"{head}{peer} |")
    print("| --- | ---: | ---: | ---: |" + (" ---: | ---: |" if args.peer else ""))
    with tempfile.TemporaryDirectory() as scratch:
        for name, (song, options) in COMMANDS.items():
            duration = pianobot.load_piece(EXAMPLES / song).duration
            library_seconds(song, options)  # (warm: imports and the policies' first load)
            for checkout in [ROOT, args.peer] if args.peer else [ROOT]:
                command_seconds(song, options, Path(scratch), checkout)  # (warm: the bytecode cache)
            ends, insides, peers = [], [], []
            for _ in range(args.runs):
                ends.append(command_seconds(song, options, Path(scratch)))
                insides.append(library_seconds(song, options))
                if args.peer:
                    peers.append(command_seconds(song, options, Path(scratch), args.peer))
            end, inside = statistics.median(ends), statistics.median(insides)
            beside = ""
            if args.peer:
                them = statistics.median(peers)
                beside = f" | {them:.2f} s, {duration / them:.1f}× | {them / end:.2f}×"
            print(
                f"| {name} | {duration:.1f} | {end:.2f} s, {duration / end:.1f}× | {inside:.2f} s, {duration / inside:.1f}×{beside} |",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
