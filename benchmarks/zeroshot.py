"""The general policy on pieces it was never trained on, beside the scripted pianist (its teacher).

    python -m benchmarks.zeroshot [--general DIR] [--melodies 50] [--seed 2026] [--per-task 10]
                                  [--sets examples melodies articulation tasks duets polyphonic]
                                  [--duets 50] [--duet-seed 35] [--polyphonic 20] [--wrist-guard]
                                  [--hold-guard | --no-hold-guard] [--json out.json] [--plot docs/zeroshot.png]

One-hand sets, each played in one continuous simulation per piece, from hand start 0, as
``pianobot play`` plays a piece no phrase policy was trained for (the general policy, through the
wrist guard, :mod:`pianobot.perform.guard`, with ``--wrist-guard``, and through the hold guard
where ``play`` plays it through one, or as ``--hold-guard``/``--no-hold-guard`` say):

- ``examples``: the one-hand example songs (their own fingering), split into phrases as
  ``pianobot play`` splits them, every phrase played by the general policy (no phrase policy is
  looked up: a model store with nothing in it but the general policy);
- ``melodies``: ``--melodies`` random melodies of 8 to 16 notes in every key
  (:func:`pianobot.music.melodies.random_melody`, 60-144 bpm, velocities 20-127), drawn with
  generators seeded ``[--seed, index, draw]`` (no training run draws from these: the melody task
  family draws from the environment's generator, the melody benchmark from ``[tonic, index, draw]``),
  fingered by the planner for the general policy's fingers (and the scripted pianist plays with
  them: three, or four for a policy with the thumb); a melody it says this hand cannot play at its
  tempo is drawn again;
- ``articulation``: as many random melodies drawn the same way with slurs (notes written to last
  until the next one sounds; :data:`SLURS`), seeded ``[38, index, draw]``: how long notes are held;
- ``tasks``: ``--per-task`` instances of each of the paper's task families (seeds 0, 1, ...).

Two-hand sets, both hands in one simulation as ``pianobot play`` plays them, by the packaged
policies one per hand unless ``--general`` names one for both (:mod:`benchmarks.hands`,
its own table: note F1 of the whole piece and each hand, per-step key-press F1, note F1 with
offsets, notes left out):

- ``duets``: ``--duets`` random two-hand pieces (:func:`pianobot.music.duets.duet_set`, seed
  ``--duet-seed``; no training run draws from them);
- ``polyphonic``: ``--polyphonic`` hands' parts alone (seed ``--duet-seed`` + 1): left hands
  with block chords or two voices, right hands in two voices (:func:`benchmarks.hands.polyphonic_set`).

For each piece: note F1, velocity MAE (matched notes, MIDI units), per-step key-press F1 (the
paper's frame-level measure), note F1 with offsets and the played/written duration ratio by note
length (articulation; its median over every matched note of a set, docs/metrics.md), for the general policy and for the scripted pianist on the same
piece (the ceiling); a Markdown table per set (means; the general policy's share of the scripted
pianist's note F1), for the melodies the share of notes the general policy played by phrase and by
onset within a phrase (where it loses notes), and, with ``--plot``, a figure of every piece's
note F1 for both. Another ``--seed`` gives a validation set, e.g. to choose among checkpoints
without looking at the test set.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

from benchmarks import hands
from benchmarks.hands import polyphonic_set
from pianobot.agent.general import find_general
from pianobot.agent.policy import policy_configs
from pianobot.music.duets import duet_set
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.melodies import describe, random_melody
from pianobot.music.metrics import LENGTH_CLASSES, duration_ratios
from pianobot.music.phrases import DEFAULT_MAX_NOTES, split_phrases
from pianobot.music.piece import Piece
from pianobot.music.tasks import TASKS, make_task
from pianobot.perform.compose import CompositionalController
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.perform.plan import assign, guarded_family
from pianobot.pianist.fingering import ensure_fingering

EXAMPLES = ("c-major-scale", "mary", "ode-to-joy", "twinkle", "one-note", "three-note", "six-note", "rhythmic", "chord")
"""The one-hand example songs in examples/midi (the recordings and the five-finger piece need a
hand part reduced or five fingers)."""
MELODY_DRAWS = 50
SETS = ("examples", "melodies", "articulation", "tasks")
HAND_SETS = ("duets", "polyphonic")
"""Two-hand sets, played as ``pianobot play`` plays both hands (:mod:`benchmarks.hands`)."""
ARTICULATION_SEED = 38
"""The articulation set's first seed entry (issue 38), apart from the melodies' ``--seed``."""
SLURS = 0.35
"""The articulation set's chance that a note begins a slur (:func:`pianobot.music.melodies.random_melody`)."""


def figures(rollout) -> dict:
    report = rollout.report()
    return {
        "f1": report.f1,
        "velocity_mae": report.velocity_mae,
        "f1_offsets": report.f1_with_offsets,
        "step_f1": report.step_f1,
        "ratios": duration_ratios(report.rows),
    }


def placed_hits(phrases, rollout) -> list[tuple[int, int, bool]]:
    """For every note of the piece: (its phrase's index, its onset's index within the phrase,
    whether it was played), to see where a performance loses notes."""
    played = {(r.reference.pitch, r.reference.onset) for r in rollout.report().rows if r.reference and r.played}
    out = []
    for phrase in phrases:
        onsets = sorted({note.onset for note in phrase.notes})
        out += [(phrase.index, onsets.index(n.onset), (n.pitch, n.onset) in played) for n in phrase.notes]
    return out


def play_both(piece: Piece, general: Path, empty: Path, guard: bool = False, hold: bool | None = None) -> dict:
    """The general policy's and the scripted pianist's figures on ``piece`` (``guard``, ``hold``: the
    general policy through the wrist guard, the hold guard; None: as ``pianobot play`` plays it)."""
    hold = guarded_family(general) if hold is None else hold
    env_config, _ = policy_configs(general)
    phrases = split_phrases(piece, DEFAULT_MAX_NOTES)
    policy = perform(
        piece, lambda env: CompositionalController(env, assign(phrases, empty, general), guard, hold), env_config
    )
    hand = replace(PLAY_CONFIG.world.hand, spec=env_config.world.hand.spec)  # (the policy's fingers)
    scripted = perform(piece, "scripted", replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand)))
    return {
        "notes": len(piece),
        "general": {**figures(policy), "hits": placed_hits(phrases, policy)},
        "scripted": figures(scripted),
    }


def where_table(rows: list[dict]) -> str:
    """The share of notes the general policy played, by phrase and by onset within a phrase."""
    hits = [hit for row in rows for hit in row["general"]["hits"]]
    columns = 1 + max((max(phrase, onset) for phrase, onset, _ in hits), default=0)
    lines = [
        "| place | " + " | ".join(f"{k + 1}" for k in range(columns)) + " |",
        "| --- |" + " ---: |" * columns,
    ]
    for label, position in (("phrase", 0), ("onset within its phrase", 1)):
        cells = []
        for k in range(columns):
            played = [ok for *place, ok in hits if place[position] == k]
            cells.append(f"{np.mean(played):.2f} ({len(played)})" if played else "")
        lines.append(f"| played, by {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def example_set(root: Path, hand: HandSpec = HandSpec()) -> list[tuple[str, Piece]]:
    """The example songs as ``pianobot play`` reads them: their own fingering, else the planner's for ``hand``."""
    pieces = [(name, load_piece(root / f"{name}.mid", LoadOptions())) for name in EXAMPLES]
    return [(name, ensure_fingering(piece, KeyboardSpec(), hand)[0]) for name, piece in pieces]


def melody_set(
    count: int, seed: int, slurs: float = 0.0, hand: HandSpec = HandSpec()
) -> tuple[list[tuple[str, Piece]], int]:
    """``count`` random melodies that ``hand`` can play (``slurs``: their chance of a slur at each
    note), fingered for it, and how many draws the planner turned down."""
    out, rejected = [], 0
    for index in range(count):
        for draw in range(MELODY_DRAWS):
            piece = random_melody(np.random.default_rng([seed, index, draw]), KeyboardSpec(), slurs=slurs)
            fingered, plan = ensure_fingering(piece, KeyboardSpec(), hand)
            if plan is None or not plan.problems:
                out.append((describe(fingered), fingered))
                break
            rejected += 1
        else:
            raise RuntimeError(f"no playable melody for index {index} in {MELODY_DRAWS} draws")
    return out, rejected


def task_set(per_task: int) -> list[tuple[str, Piece]]:
    return [
        (f"{task} #{seed}", make_task(task, np.random.default_rng(seed), KeyboardSpec()))
        for task in TASKS
        for seed in range(per_task)
    ]


def chosen_sets(
    names: list[str], examples: Path, melodies: int, seed: int, per_task: int, hand: HandSpec = HandSpec()
) -> tuple[dict[str, list[tuple[str, Piece]]], int]:
    """The pieces of the sets ``names`` (in :data:`SETS` order), fingered for ``hand``, and how many
    melody draws the planner turned down (0 without the melodies); a set left out is not even drawn."""
    sets, rejected = {}, 0
    for name in (n for n in SETS if n in names):
        if name == "examples":
            sets[name] = example_set(examples, hand)
        elif name == "melodies":
            sets[name], rejected = melody_set(melodies, seed, hand=hand)
        elif name == "articulation":
            sets[name], _ = melody_set(melodies, ARTICULATION_SEED, SLURS, hand)
        else:
            sets[name] = task_set(per_task)
    return sets, rejected


def summary(rows: list[dict]) -> dict:
    def mean(who: str, key: str) -> float:
        values = [r[who][key] for r in rows if r[who][key] is not None]
        return float(np.mean(values)) if values else float("nan")

    out = {
        who: {k: mean(who, k) for k in ("f1", "velocity_mae", "f1_offsets", "step_f1")}
        for who in ("general", "scripted")
    }
    for who in ("general", "scripted"):  # the median over every matched note of the set, by length class
        for name, _, _ in LENGTH_CLASSES:
            pooled = [x for r in rows for x in r[who]["ratios"][name]]
            out[who][f"held_{name}"] = float(np.median(pooled)) if pooled else float("nan")
    out["pieces"], out["notes"] = len(rows), sum(r["notes"] for r in rows)
    out["share"] = out["general"]["f1"] / out["scripted"]["f1"]
    out["at_least_0.9"] = sum(r["general"]["f1"] >= 0.9 for r in rows)
    return out


def table(results: dict[str, list[dict]]) -> str:
    lines = [
        "| set | pieces | notes | note F1 general | note F1 scripted | general / scripted | pieces at F1 >= 0.9 "
        "| velocity MAE general | velocity MAE scripted | per-step F1 general | per-step F1 scripted "
        "| F1 with offsets general | F1 with offsets scripted "
        "| held / written general (short, medium, long) | held / written scripted (short, medium, long) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |",
    ]

    def held(figures: dict) -> str:
        return ", ".join(f"{figures[f'held_{name}']:.2f}" for name, _, _ in LENGTH_CLASSES)

    for name, rows in results.items():
        s = summary(rows)
        g, c = s["general"], s["scripted"]
        lines.append(
            f"| {name} | {s['pieces']} | {s['notes']} | {g['f1']:.3f} | {c['f1']:.3f} | {100 * s['share']:.0f} % | "
            f"{s['at_least_0.9']}/{s['pieces']} | {g['velocity_mae']:.1f} | {c['velocity_mae']:.1f} | "
            f"{g['step_f1']:.3f} | {c['step_f1']:.3f} | {g['f1_offsets']:.3f} | {c['f1_offsets']:.3f} | "
            f"{held(g)} | {held(c)} |"
        )
    return "\n".join(lines)


def plot(results: dict[str, list[dict]], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 3.6), squeeze=False)
    for axis, (name, rows) in zip(axes[0], results.items()):
        x = np.arange(len(rows))
        axis.scatter(x, [r["scripted"]["f1"] for r in rows], s=14, marker="s", label="scripted pianist", alpha=0.7)
        axis.scatter(x, [r["general"]["f1"] for r in rows], s=14, label="general policy", alpha=0.8)
        axis.set_title(f"{name} ({len(rows)})")
        axis.set_ylim(-0.05, 1.05)
        axis.set_xlabel("piece")
        axis.axhline(0.9, color="grey", lw=0.6, ls="--")
    axes[0][0].set_ylabel("note F1")
    axes[0][0].legend(loc="lower left", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--general", type=Path, help="the general policy's folder (default: the newest in --models)")
    parser.add_argument("--models", type=Path, default=Path("models"), help="model store to find it in")
    parser.add_argument("--examples", type=Path, default=Path("examples/midi"), help="folder of the example songs")
    parser.add_argument("--melodies", type=int, default=50, help="random melodies (default 50)")
    parser.add_argument("--seed", type=int, default=2026, help="first entry of the melodies' generator seeds")
    parser.add_argument("--per-task", type=int, default=10, help="instances of each paper task family (default 10)")
    parser.add_argument(
        "--sets",
        nargs="+",
        choices=SETS + HAND_SETS,
        default=list(SETS + HAND_SETS),
        help="which sets to play (default all)",
    )
    parser.add_argument("--duets", type=int, default=50, help="random two-hand pieces (default 50)")
    parser.add_argument("--duet-seed", type=int, default=35, help="their seed (the polyphonic parts': one more)")
    parser.add_argument("--polyphonic", type=int, default=20, help="one hand's polyphonic parts (default 20)")
    parser.add_argument("--wrist-guard", action="store_true", help="play the general policy through the wrist guard")
    parser.add_argument(
        "--hold-guard",
        action=argparse.BooleanOptionalAction,
        help="the general policies through the hold guard, or (--no-hold-guard) alone; default: as `pianobot play` "
        "plays them (the parts policy through it, the melody policy alone)",
    )
    parser.add_argument("--json", help="write every piece's figures here")
    parser.add_argument("--plot", help="draw every piece's note F1 to this PNG")
    args = parser.parse_args()
    torch.set_num_threads(1)
    general = find_general(args.models, path=args.general)
    if general is None:
        raise SystemExit(
            f"no general policy in {args.models}: train one with `pianobot train --task melody` or give --general"
        )
    began = time.perf_counter()
    hand = policy_configs(general)[0].world.hand.spec  # (one-hand sets are fingered for the policy's fingers)
    sets, rejected = chosen_sets(args.sets, args.examples, args.melodies, args.seed, args.per_task, hand)
    results: dict[str, list[dict]] = {}
    with tempfile.TemporaryDirectory() as empty:
        for name, pieces in sets.items():
            results[name] = [
                {"piece": label, **play_both(piece, general, Path(empty), args.wrist_guard, args.hold_guard)}
                for label, piece in pieces
            ]
    drawn = {
        "duets": lambda: duet_set(args.duet_seed, args.duets),
        "polyphonic": lambda: polyphonic_set(args.duet_seed + 1, args.polyphonic),
    }
    for name in (n for n in HAND_SETS if n in args.sets):
        # as `pianobot play` plays a two-hand file: the packaged policies by hand unless --general names one
        results[name] = hands.play_set(drawn[name](), args.general, hold_guard=args.hold_guard)
    held = guarded_family(general) if args.hold_guard is None else args.hold_guard
    guards = [name for name, on in (("wrist guard", args.wrist_guard), ("hold guard", held)) if on]
    print(f"general policy: {general}" + (f" ({', '.join(guards)})" if guards else "") + "\n")
    if any(name in results for name in SETS):
        print(table({name: rows for name, rows in results.items() if name in SETS}))
    for name in (n for n in HAND_SETS if n in results):
        print("\n" + hands.table(name, results[name]))
    if "melodies" in results:
        print("\nRandom melodies: the share of notes the general policy played (count), by place\n")
        print(where_table(results["melodies"]))
        print(f"\nMelodies the planner said this hand cannot play at their tempo, drawn again: {rejected}.")
    print(f"{time.perf_counter() - began:.0f} s")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(
                {
                    "general": str(general),
                    "wrist_guard": args.wrist_guard,
                    "hold_guard": held,
                    "rejected": rejected,
                    **results,
                },
                f,
                indent=1,
            )
    if args.plot:
        plot({name: rows for name, rows in results.items() if name in SETS}, args.plot)


if __name__ == "__main__":
    main()
