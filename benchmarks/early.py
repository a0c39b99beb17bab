"""Why the scripted pianist lets held notes go before their written end, on real two-hand music.

    python -m benchmarks.early [--set validation|test] [--hand-model pianist] [--only NAME ...] [--json out.json]

Plays :mod:`benchmarks.corpus`' excerpts with the scripted pianist (both hands in one simulation,
as ``pianobot play`` plays them) and counts every note the strike planner lets go while the score
window still holds it (:meth:`~pianobot.pianist.strikes.StrikePlanner._let_go`), by the rule that
let it go, with the control steps of it that were left:

- **own next note**: its finger must lift, move over and strike its own next note;
- **same key**: another finger strikes the same key next, and it must rise first;
- **wrist move**: a strike needs the wrist where no sideways turn of the holding finger keeps its
  key (``hold_reach``), soon enough at the speed the wrist slides while holding.

Beside them, the scripted pianist's per-step F1 and note F1 with offsets, and the same figures of
the notes as the reduction gave them (``as given``: the most a player of them scores). A
diagnostic: it wraps the strike planner's method to watch it, and changes nothing it does.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

from benchmarks.corpus import SETS, write_excerpt
from pianobot.errors import PianobotWarning
from pianobot.music.load import LoadOptions
from pianobot.perform.together import play_hands, two_hands
from pianobot.pianist.strikes import StrikePlanner, finger_runs
from pianobot.sim.hand import HAND_MODELS, default_fingers

RULES = ("own next note", "same key", "wrist move")


def watch(counts: Counter, steps: Counter):
    """Wrap :meth:`StrikePlanner.plan` so that each note let go while still written is counted in
    ``counts`` by its rule, and the steps of it left in ``steps``; returns the original, to restore."""
    original = StrikePlanner.plan

    def plan(self, score, previous_row, tips, wrist=None, released=frozenset()):
        watched = self._let_go

        def let_go(plans, tips_, wrist_):
            holds = {f: p for f, p in plans.items() if p.phase == "hold"}
            own = {f for f, p in holds.items() if p.next_note is not None and p.next_note.start - p.next_lead <= 0}
            watched(plans, tips_, wrist_)
            for finger, held in holds.items():
                if finger in plans and plans[finger].phase == "hold":
                    continue
                others = any(p.key == held.key and f != finger and p.phase != "hold" for f, p in plans.items())
                rule = "own next note" if finger in own else "same key" if others else "wrist move"
                slot = self.fingers.index(finger)
                runs = [r for r in finger_runs(score, slot) if r.start == 0 and r.key == held.key]
                counts[rule] += 1
                steps[rule] += runs[0].end if runs else 0

        self._let_go = let_go
        try:
            return original(self, score, previous_row, tips, wrist, released)
        finally:
            del self._let_go

    StrikePlanner.plan = plan
    return original


def early(excerpts, folder: Path, hand) -> list[dict]:
    """A row per excerpt: the releases and steps by rule, and the held figures played and as given."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, path, parts, first in excerpts:
        file = folder / f"{name}.mid"
        write_excerpt(path, parts, first, file)
        counts, steps = Counter(), Counter()
        original = watch(counts, steps)
        try:
            with warnings.catch_warnings(), tempfile.TemporaryDirectory() as models:
                warnings.simplefilter("ignore", PianobotWarning)
                reading = two_hands(file, LoadOptions(), hand)
                performance = play_hands(reading.piece, "scripted", models, hand=hand)
        finally:
            StrikePlanner.plan = original
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
    parser.add_argument("--set", choices=tuple(SETS), default="validation", help="the excerpts (default: validation)")
    parser.add_argument("--hand-model", choices=tuple(HAND_MODELS), default="pianist", help="the hand that plays")
    parser.add_argument("--only", nargs="+", default=(), help="only these excerpts (by name)")
    parser.add_argument("--out", type=Path, help="folder the excerpts are written to (default out/early-SET)")
    parser.add_argument("--json", type=Path, help="write every figure to this file")
    args = parser.parse_args()
    try:
        import music21  # noqa: F401 (the corpus's scores)
    except ImportError:
        parser.error('music21 is not installed: pip install -e ".[corpus]"')
    excerpts = [e for e in SETS[args.set] if not args.only or e[0] in args.only]
    rows = early(excerpts, args.out or Path(f"out/early-{args.set}"), default_fingers(args.hand_model))
    print()
    print(table(rows))
    if args.json:
        args.json.write_text(
            json.dumps({"set": args.set, "hand_model": args.hand_model, "rows": rows}, indent=2) + "\n"
        )


if __name__ == "__main__":
    main()
