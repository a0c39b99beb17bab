"""Why the scripted pianist lets held notes go before their written end, on real two-hand music.

    python -m benchmarks.early [--set test|validation] [--hand-model pianist|allegro] [--only NAME ...] [--json out.json]

Plays :mod:`benchmarks.corpus`' excerpts (default the test set, as it) with the scripted pianist,
both hands in one simulation and each hand's fingers as there (``pianobot play``'s), and counts every
note the strike planner lets go while the score still holds it, by the rule it names
(:meth:`~pianobot.pianist.strikes.StrikePlanner.released_for`), with the control steps of the note
still written from then to its end:

- **own next note**: its finger must lift, move over and strike its own next note;
- **same key**: another finger strikes the same key next, and it must rise first;
- **wrist move**: a strike needs the wrist where no sideways turn of the holding finger keeps its
  key (``hold_reach``), soon enough at the speed the wrist slides while holding.

Beside them, the scripted pianist's per-step F1 and note F1 with offsets, and the same figures of
the notes as the reduction gave them (``as given``: the most a player of them scores). A
diagnostic: it watches the strike planner (:func:`watch`) and changes nothing it does."""

from __future__ import annotations

import argparse
import json
import tempfile
import warnings
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from benchmarks.corpus import SETS, write_excerpt
from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions
from pianobot.music.tensor import FINGER, NOTE
from pianobot.perform.together import fingers_for_file, play_hands, two_hands
from pianobot.pianist.strikes import StrikePlanner
from pianobot.sim.hand import HAND_MODELS, default_fingers

RULES = ("own next note", "same key", "wrist move")


@contextmanager
def watch(counts: Counter, steps: Counter):
    """While in the block, every note a strike planner lets go while the score still holds it is counted
    in ``counts`` by its rule (:meth:`StrikePlanner.released_for`), and ``steps`` counts the control
    steps of it still written from then on, step by step to its end (so past the score window too).
    The planner's plans are not changed; its methods are restored on leaving the block."""
    plan, released_for = StrikePlanner.plan, StrikePlanner.released_for
    open_notes: dict[int, dict[tuple[int, int], str]] = {}  # planner -> (slot, key) let go -> rule

    def watched_plan(self, score, *args, **kwargs):
        notes = open_notes.setdefault(id(self), {})
        row = score[0]
        for (slot, key), rule in list(notes.items()):  # a note let go earlier: one more step of it written?
            if row[key, NOTE] > 0.5 and row[key, FINGER + slot] > 0.5:
                steps[rule] += 1
            else:
                del notes[slot, key]
        return plan(self, score, *args, **kwargs)

    def watched_release(self, finger, held, rule):
        counts[rule] += 1
        steps[rule] += 1  # (this step)
        open_notes[id(self)][self.fingers.index(finger), held.key] = rule

    StrikePlanner.plan, StrikePlanner.released_for = watched_plan, watched_release
    try:
        yield
    finally:
        StrikePlanner.plan, StrikePlanner.released_for = plan, released_for


def early(excerpts, folder: Path, hand: HandSpec | None) -> list[dict]:
    """A row per excerpt: the releases and steps by rule, and the held figures played and as given
    (``hand``: each hand's fingers; None: chosen per file as ``pianobot play`` and
    :mod:`benchmarks.corpus` choose them)."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, path, parts, first in excerpts:
        file = folder / f"{name}.mid"
        write_excerpt(path, parts, first, file)
        counts, steps = Counter(), Counter()
        fingers = hand if hand is not None else fingers_for_file(file, LoadOptions())[0]  # (as benchmarks.corpus)
        with watch(counts, steps), warnings.catch_warnings(), tempfile.TemporaryDirectory() as models:
            warnings.simplefilter("ignore", PianobotWarning)
            reading = two_hands(file, LoadOptions(), fingers)
            performance = play_hands(reading.piece, "scripted", models, hand=fingers)
        played, given = performance.report(), performance.given_report()
        rows.append(
            {
                "piece": name,
                "releases": {rule: counts[rule] for rule in RULES},
                "steps": {rule: steps[rule] for rule in RULES},
                "played": {"f1": played.f1, "step_f1": played.step_f1, "f1_offsets": played.f1_with_offsets},
                "as_given": {"f1": given.f1, "step_f1": given.step_f1, "f1_offsets": given.f1_with_offsets},
            }
        )
        print(f"{name}: " + ", ".join(f"{rule} {counts[rule]} ({steps[rule]} steps)" for rule in RULES), flush=True)
    return rows


def table(rows: list[dict]) -> str:
    lines = [
        "| piece | " + " | ".join(f"{rule}: notes (steps)" for rule in RULES) + " | per-step F1, offsets | as given |",
        "| --- | " + " | ".join("---:" for _ in RULES) + " | --- | --- |",
    ]

    def held(figures: list[dict]) -> str:
        return f"{np.mean([f['step_f1'] for f in figures]):.3f}, {np.mean([f['f1_offsets'] for f in figures]):.3f}"

    for r in rows:
        cells = " | ".join(f"{r['releases'][rule]} ({r['steps'][rule]})" for rule in RULES)
        lines.append(f"| {r['piece']} | {cells} | {held([r['played']])} | {held([r['as_given']])} |")
    total = " | ".join(
        f"{sum(r['releases'][rule] for r in rows)} ({sum(r['steps'][rule] for r in rows)})" for rule in RULES
    )
    lines.append(
        f"| all ({len(rows)}) | {total} | {held([r['played'] for r in rows])} | {held([r['as_given'] for r in rows])} |"
    )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", choices=tuple(SETS), default="test", help="the excerpts (default: test)")
    parser.add_argument("--hand-model", choices=tuple(HAND_MODELS), default="pianist", help="the hand that plays")
    parser.add_argument("--only", nargs="+", default=(), help="only these excerpts (by name)")
    parser.add_argument("--out", type=Path, help="folder the excerpts are written to (default out/early-SET)")
    parser.add_argument("--json", type=Path, help="write every figure to this file")
    args = parser.parse_args()
    names = [e[0] for e in SETS[args.set]]
    unknown = [name for name in args.only if name not in names]
    if unknown:
        parser.error(
            f"--only {' '.join(unknown)}: no such excerpt in the {args.set} set; its excerpts: {', '.join(names)}"
        )
    try:
        import music21  # noqa: F401 (the corpus's scores)
    except ImportError:
        parser.error('music21 is not installed: pip install -e ".[corpus]"')
    excerpts = [e for e in SETS[args.set] if not args.only or e[0] in args.only]
    hand = default_fingers(args.hand_model) if args.hand_model != HandSpec.model else None  # (None: as play chooses)
    rows = early(excerpts, args.out or Path(f"out/early-{args.set}"), hand)
    print()
    print(table(rows))
    if args.json:
        args.json.write_text(
            json.dumps({"set": args.set, "hand_model": args.hand_model, "rows": rows}, indent=2) + "\n"
        )


if __name__ == "__main__":
    main()
