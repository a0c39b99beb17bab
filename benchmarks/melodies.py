"""The scripted pianist on random single-voice melodies in all 12 keys.

    python benchmarks/melodies.py [--per-key 4] [--json out.json] [--failures] [--hand-model pianist]

Draws ``--per-key`` melodies per key (:func:`pianobot.music.melodies.melody_set`, fixed seeds;
major and minor in turn), fingers each with the planner (a melody the planner says this hand
cannot play at its tempo is drawn again, and counted), plays each with the scripted pianist
from hand start ``index`` and prints a Markdown table per key: mean and lowest note F1,
velocity MAE (MIDI units, matched notes), mean absolute onset error (ms), extra notes (played
notes the score does not ask for), mean note F1 with offsets and per-step key-press F1, and the
median played/written duration of notes written < 0.35 s, 0.35-0.7 s and longer (articulation,
docs/metrics.md); then the totals, what came after the notes let go early (:func:`early_causes`:
the same key again, a move of the hand, neither, or nothing), and every melody short of the targets
(note F1 >= 0.95, velocity MAE <= 5, no extra notes). ``--hand-model`` plays them with that hand
and its fingers (default the Allegro-like hand's three).
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace

import numpy as np

from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.melodies import TONICS, describe, melody_set
from pianobot.music.metrics import LENGTH_CLASSES, NoteRow, duration_ratios
from pianobot.music.piece import Piece
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.pianist.fingering import ensure_fingering, plan_fingering
from pianobot.sim.hand import HAND_MODELS, default_fingers, hand_config
from pianobot.sim.keyboard import KeyboardConfig

F1_TARGET, VELOCITY_TARGET, MEAN_F1_TARGET = 0.95, 5.0, 0.98


def playable(piece: Piece, hand: HandSpec = HandSpec()) -> Piece | None:
    """The piece fingered by the planner, or None when the planner reports notes too fast for the hand."""
    fingered, plan = ensure_fingering(piece, KeyboardSpec(), hand)
    return None if plan is not None and plan.problems else fingered


OFFSET_TOLERANCE, OFFSET_RATIO = 0.05, 0.2
"""note F1 with offsets' tolerance (mir_eval's): an offset counts within the larger of 50 ms and
20 % of the written duration."""
EARLY_CAUSES = ("repeated key", "hand move", "other", "last note")


CAUSE_NAMES = {
    "repeated key": "the same key again",
    "hand move": "a hand move",
    "other": "neither",
    "last note": "nothing (the last note)",
}


def early_causes(piece: Piece, rows: tuple[NoteRow, ...], hand: HandSpec) -> dict[str, int]:
    """How many matched notes of ``piece`` were let go early (before their written offset by more
    than note F1 with offsets allows), by what comes at the next onset: the same key struck again
    (it must rise first), the hand moving (the fingering planner's wrist moves between this note's
    onset and the next: a held key lets go before the wrist slides), neither, or nothing (the
    piece's last notes)."""
    plan = plan_fingering(piece, KeyboardConfig(), hand_config(hand))
    onsets = sorted({n.onset for n in plan.piece.notes})
    wrist = dict(zip(onsets, plan.wrist))
    counts = dict.fromkeys(EARLY_CAUSES, 0)
    for row in rows:
        note, played = row.reference, row.played
        if note is None or played is None:
            continue
        if note.offset - played.offset <= max(OFFSET_TOLERANCE, OFFSET_RATIO * note.duration):
            continue
        later = [n.onset for n in piece.notes if n.onset > note.onset]
        if not later:
            counts["last note"] += 1
        elif any(n.onset == min(later) and n.pitch == note.pitch for n in piece.notes):
            counts["repeated key"] += 1
        elif abs(wrist[min(later)] - wrist[note.onset]) > 1e-9:
            counts["hand move"] += 1
        else:
            counts["other"] += 1
    return counts


def play_set(per_key: int, hand: HandSpec = HandSpec()) -> tuple[list[dict], int]:
    """Every melody's figures, played by ``hand``, and how many draws the planner turned down."""
    config = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand_config(hand)))
    rejected = 0

    def accept(piece: Piece) -> Piece | None:
        nonlocal rejected
        kept = playable(piece, hand)
        rejected += kept is None
        return kept

    results = []
    for melody in melody_set(per_key, accept):
        report = perform(melody.piece, "scripted", config, seed=melody.index).report()
        onset_errors = [abs(r.onset_error) for r in report.rows if r.onset_error is not None]
        results.append(
            {
                "key": melody.key.name,
                "tonic": melody.key.tonic,
                "seed": list(melody.seed),
                "melody": describe(melody.piece),
                "f1": report.f1,
                "f1_offsets": report.f1_with_offsets,
                "step_f1": report.step_f1,
                "ratios": duration_ratios(report.rows),
                "velocity_mae": report.velocity_mae if report.velocity_mae is not None else float("nan"),
                "onset_ms": 1000 * float(np.mean(onset_errors)) if onset_errors else float("nan"),
                "extra": sum(r.reference is None for r in report.rows),
                "missed": sum(r.played is None for r in report.rows),
                "notes": len(melody.piece),
                "matched": report.matched_notes,
                "early": early_causes(melody.piece, report.rows, hand),
            }
        )
    return results, rejected


def passes(r: dict) -> bool:
    return r["f1"] >= F1_TARGET and r["velocity_mae"] <= VELOCITY_TARGET and r["extra"] == 0


def held_cells(results: list[dict]) -> str:
    """The median played/written duration per note-length class, over every matched note of ``results``."""
    pooled = [[x for r in results for x in r["ratios"][name]] for name, _, _ in LENGTH_CLASSES]
    return ", ".join(f"{np.median(p):.2f}" if p else "n/a" for p in pooled)


def table(results: list[dict], rejected: int) -> str:
    lines = [
        "| key | melodies | notes | mean F1 | min F1 | velocity MAE (mean, max) | onset error (ms) | extra notes | pass "
        "| F1 with offsets | per-step F1 | held / written (short, medium, long) |",
        "| --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | --- |",
    ]

    def row(name: str, rs: list[dict]) -> str:
        f1 = [r["f1"] for r in rs]
        vel = [r["velocity_mae"] for r in rs]
        return (
            f"| {name} | {len(rs)} | {sum(r['notes'] for r in rs)} | {np.mean(f1):.3f} | {min(f1):.3f} | "
            f"{np.mean(vel):.1f}, {max(vel):.1f} | {np.mean([r['onset_ms'] for r in rs]):.0f} | "
            f"{sum(r['extra'] for r in rs)} | {sum(passes(r) for r in rs)}/{len(rs)} | "
            f"{np.mean([r['f1_offsets'] for r in rs]):.3f} | {np.mean([r['step_f1'] for r in rs]):.3f} | "
            f"{held_cells(rs)} |"
        )

    for tonic, name in enumerate(TONICS):
        lines.append(row(name, [r for r in results if r["tonic"] == tonic]))
    lines.append(row("**all**", results))
    lines.append("")
    lines.append(f"Melodies the planner said this hand cannot play at their tempo, drawn again: {rejected}.")
    matched = sum(r["matched"] for r in results)
    early = {cause: sum(r["early"][cause] for r in results) for cause in EARLY_CAUSES}
    lines.append(
        f"Notes let go early (before their written end by more than note F1 with offsets allows): "
        f"{sum(early.values())} of {matched} matched ({sum(early.values()) / max(matched, 1):.1%}); before "
        + ", ".join(f"{CAUSE_NAMES[cause]} {n}" for cause, n in early.items())
        + "."
    )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-key", type=int, default=4, help="melodies per key (default 4: 48 in all)")
    parser.add_argument("--json", help="write every melody's figures here")
    parser.add_argument("--failures", action="store_true", help="list every melody short of the targets")
    parser.add_argument("--hand-model", choices=tuple(HAND_MODELS), default=HandSpec.model, help="the hand that plays")
    args = parser.parse_args()
    began = time.perf_counter()
    results, rejected = play_set(args.per_key, default_fingers(args.hand_model))
    print(table(results, rejected))
    f1 = [r["f1"] for r in results]
    ok = all(passes(r) for r in results) and np.mean(f1) >= MEAN_F1_TARGET
    print(
        f"\nTargets (every melody F1 >= {F1_TARGET}, velocity MAE <= {VELOCITY_TARGET:g}, no extra notes; "
        f"mean F1 >= {MEAN_F1_TARGET}): {'met' if ok else 'NOT met'}; {time.perf_counter() - began:.0f} s"
    )
    failures = [r for r in results if not passes(r)]
    if args.failures or failures:
        for r in failures:
            print(
                f"  {r['key']} seed {tuple(r['seed'])}: {r['melody']}: F1 {r['f1']:.3f}, velocity MAE "
                f"{r['velocity_mae']:.1f}, onset {r['onset_ms']:.0f} ms, {r['missed']} missed, {r['extra']} extra"
            )
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"rejected": rejected, "melodies": results}, f, indent=1)


if __name__ == "__main__":
    main()
