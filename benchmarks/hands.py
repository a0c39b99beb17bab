"""Two-hand pieces played with both hands (pianobot/perform/together.py): the general policy zero-shot,
beside the scripted pianist, against the pieces as written.

    python -m benchmarks.hands [--duets 50] [--seed 35] [--polyphonic 20] [--general DIR]
                               [--general-left DIR] [--parts DIR] [--apart] [--hold-guard | --no-hold-guard]
                               [--examples [FOLDER]] [--lowest-note C2 --keys 48]
                               [--thumb | --no-thumb | --hand-model pianist]
                               [--json out.json]

(``python -m benchmarks.zeroshot --sets duets polyphonic`` plays the same sets beside the
one-hand ones.)

Sets:

- ``duets``: ``--duets`` random two-hand pieces (:func:`pianobot.music.duets.duet_set`, seed
  ``--seed``: a melody over a bass line, broken chords, block chords or two voices, or a right
  hand in two voices over a bass line; 60-120 bpm, every key); no training run draws from them;
- ``polyphonic``: one hand's part alone of ``--polyphonic`` further duets (seed ``--seed`` + 1),
  in turn the left hand's with block chords, the left hand's in two voices, the right hand's in
  two voices: chords, and a held note under a moving voice;
- with ``--examples``: the two-hand files of a folder (``examples/midi``), as ``pianobot play``
  reads and plays them, against each file; the general policies from hand starts 0, 1 and 2.

Each piece is played once from hand start 0, both hands in one simulation as ``pianobot play``
plays them (``--apart``: each hand in a simulation of its own), by the general policy (the
packaged one, as ``pianobot play`` plays them: the parts policy on both hands; the model store
is an empty folder;
``--general`` names the right hand's, and both hands' without ``--general-left``, which names the
left's; ``--parts`` the parts policy, in its place on the hands it plays; through the hold guard,
as ``play`` plays them, unless ``--no-hold-guard``) and by the scripted pianist; each part on
the keys its player takes (the general policy's 24, or a wider part's own octaves; the scripted
pianist's own), or with ``--lowest-note``/``--keys`` on those keys for both players. Both hands
take their thumbs where that gives them more of the notes than three fingers, as ``pianobot play``
chooses (:func:`pianobot.perform.together.thumbs_keep_more`; a polyphonic part: for the part alone;
each row's ``fingers``), everywhere with ``--thumb``, nowhere with ``--no-thumb``.
A polyphonic part is played as ``play`` plays that hand of a two-hand file: by the parts policy (the
packaged left hand's), the left hands and the right hands alike (``pianobot play`` of a one-hand
file gives the melody policy a right hand, polyphonic or not). Prints a
Markdown table per set: note F1 (whole piece, right hand, left hand), per-step key-press F1, note
F1 with offsets, notes left outside the keys (only with ``--keys``), and the general policy's share
of the scripted pianist's note F1.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import torch

from pianobot.agent.general import parts_policy
from pianobot.errors import PianobotWarning
from pianobot.music.duets import duet_set, random_duet
from pianobot.music.instrument import THUMB, HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions
from pianobot.music.piece import parse_pitch
from pianobot.perform.together import fingers_for_file, play_hands, two_hands
from pianobot.sim.hand import HAND_MODELS, default_fingers

PLAYERS = ("sac", "scripted")
POLYPHONIC = ("block", "voices", "right-voices")
"""The textures of the polyphonic parts, in turn (the right hand's part of ``right-voices``, else the left's)."""
NAMES = {"sac": "general", "scripted": "scripted"}
EXAMPLE_STARTS = (0, 1, 2)
"""Hand starts (``pianobot play --seed``) the general policies play each two-hand example from."""


def figures(
    piece,
    controller: str,
    models,
    general=None,
    together: bool = True,
    hold_guard: bool | None = None,
    seed: int = 0,
    keyboard: KeyboardSpec | None = None,
    hand: HandSpec | None = None,
) -> dict:
    options = {"general_policy": general} if controller == "sac" and general is not None else {}
    options["hold_guard"] = hold_guard
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)  # the left-out counts are in the figures
        performance = play_hands(
            piece, controller, models, seed=seed, together=together, keyboard=keyboard, hand=hand, **options
        )
    whole, given = performance.report(), performance.given_report()
    out = {
        "f1": whole.f1,
        "step_f1": whole.step_f1,
        "f1_offsets": whole.f1_with_offsets,
        "left_out": sum(h.left_out for h in performance.hands),
        "given": sum(len(h.part) for h in performance.hands),  # (what the reduction left the hands to play)
        # the given notes as given, against the file: the most a player of them scores
        "as_given": {"f1": given.f1, "step_f1": given.step_f1, "f1_offsets": given.f1_with_offsets},
        "fingers": list(performance.hands[0].performance.plan.config.world.hand.spec.fingers),
    }
    for hand in piece.hands:
        out[f"f1_{hand}"] = performance.report(hand).f1
    return out


def polyphonic_set(seed: int, count: int) -> list[tuple[str, object]]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        texture = POLYPHONIC[i % len(POLYPHONIC)]
        hand = "right" if texture == "right-voices" else "left"
        out.append((f"{hand} hand {seed}-{i} ({texture})", random_duet(rng, texture).part(hand)))
    return out


def table(name: str, rows: list[dict], players=PLAYERS) -> str:
    def mean(player: str, key: str) -> str:
        values = [r[player][key] for r in rows if key in r[player]]
        return f"{np.mean(values):.3f}" if values else "–"

    lines = [
        f"**{name}** ({len(rows)} pieces, {sum(r['notes'] for r in rows)} notes)",
        "",
        "| player | note F1 | right hand | left hand | per-step F1 | note F1 with offsets | notes left out | pieces at F1 ≥ 0.9 |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for player in players:
        at = sum(r[player]["f1"] >= 0.9 for r in rows)
        lines.append(
            f"| {NAMES[player]} | {mean(player, 'f1')} | {mean(player, 'f1_right')} | {mean(player, 'f1_left')} | "
            f"{mean(player, 'step_f1')} | {mean(player, 'f1_offsets')} | "
            f"{sum(r[player]['left_out'] for r in rows)} | {at}/{len(rows)} |"
        )
    if "sac" in players:
        general = np.mean([r["sac"]["f1"] for r in rows])
        scripted = np.mean([r["scripted"]["f1"] for r in rows])
        lines += ["", f"general / scripted: {general / scripted:.1%}"]
    return "\n".join(lines + [""])


def with_parts(piece, general, parts):
    """The general policies by hand with ``parts`` on the hands ``play`` gives the parts policy: every
    hand of a two-hand piece."""
    if parts is None:
        return general
    return dict.fromkeys(piece.hands, parts)


def play_set(
    pieces,
    general=None,
    together: bool = True,
    parts=None,
    hold_guard: bool | None = None,
    keyboard: KeyboardSpec | None = None,
    hand: HandSpec | None = None,
    players=PLAYERS,
) -> list[dict]:
    """Every piece of a set played by ``players`` (both): one row of figures per piece (``parts``: the
    parts policy, :func:`with_parts`; ``hold_guard``: the general policies through the hold guard,
    as ``pianobot play`` plays them; ``keyboard``: every part on these keys, as ``pianobot play
    --lowest-note/--keys`` plays it, else each player's own; ``hand``: each hand's fingers, as
    ``pianobot play --thumb`` gives them; default: as :func:`~pianobot.perform.together.play_hands`
    chooses them for each piece)."""
    rows = []
    with tempfile.TemporaryDirectory() as models:
        for label, piece in pieces:
            piece = piece if piece.hands else piece.with_hands("left")
            row = {"piece": label, "notes": len(piece)}
            policies = with_parts(piece, general, parts)
            row.update(
                {
                    player: figures(piece, player, models, policies, together, hold_guard, 0, keyboard, hand=hand)
                    for player in players
                }
            )
            rows.append(row)
            print(f"{label}: " + ", ".join(f"{NAMES[p]} {row[p]['f1']:.3f}" for p in players), flush=True)
    return rows


def example_set(folder: Path, hand: HandSpec | None = None) -> list[tuple[str, object, HandSpec]]:
    """The files in ``folder`` that ``pianobot play`` plays with both hands, each as it reads them,
    with the hands' fingers: ``hand``'s, default as ``pianobot play`` chooses them for the file
    (:func:`~pianobot.perform.together.fingers_for_file`)."""
    out = []
    for path in sorted(folder.glob("*.mid")):
        fingers = hand if hand is not None else fingers_for_file(path, LoadOptions())[0]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PianobotWarning)
            reading = two_hands(path, LoadOptions(), fingers)
        if reading is not None:
            out.append((path.stem, reading.piece, fingers))
    return out


def play_examples(
    pieces, general=None, hold_guard: bool | None = None, starts=EXAMPLE_STARTS, players=PLAYERS
) -> list[dict]:
    """Each two-hand example (:func:`example_set`'s: with its hands' fingers) as ``pianobot play``
    plays it: the general policies from each of ``starts`` (hand starts: ``--seed``), the scripted
    pianist from 0; each play's figures."""
    rows = []
    with tempfile.TemporaryDirectory() as models:
        for label, piece, hand in pieces:
            general_figures = [
                figures(piece, "sac", models, general, True, hold_guard, s, hand=hand)
                for s in starts
                if "sac" in players
            ]
            scripted = figures(piece, "scripted", models, hand=hand)
            rows.append({"piece": label, "notes": len(piece), "sac": general_figures, "scripted": scripted})
            f1s = ", ".join(f"{f['f1']:.3f}" for f in general_figures) or "-"
            print(f"{label}: general {f1s}; scripted {scripted['f1']:.3f}", flush=True)
    return rows


def example_table(rows: list[dict], starts=EXAMPLE_STARTS) -> str:
    def mean(row: dict, key: str) -> float:
        return float(np.mean([f[key] for f in row["sac"]])) if row["sac"] else float("nan")

    lines = [
        f"**two-hand examples** (against each file; the general policies from hand starts {', '.join(map(str, starts))})",
        "",
        "| example | notes | note F1, general policies | mean | per-step F1, general (mean) | note F1, scripted pianist | per-step F1, scripted |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        values = ", ".join(f"{f['f1']:.3f}" for f in r["sac"])
        lines.append(
            f"| `{r['piece']}` | {r['notes']} | {values} | {mean(r, 'f1'):.3f} | {mean(r, 'step_f1'):.3f} | "
            f"{r['scripted']['f1']:.3f} | {r['scripted']['step_f1']:.3f} |"
        )
    if rows:
        means = [mean(r, "f1") for r in rows]
        lines.append(
            f"| mean | | | {np.mean(means):.3f} | {np.mean([mean(r, 'step_f1') for r in rows]):.3f} | "
            f"{np.mean([r['scripted']['f1'] for r in rows]):.3f} | {np.mean([r['scripted']['step_f1'] for r in rows]):.3f} |"
        )
        if any(r["sac"] for r in rows):
            every = sum(bool(r["sac"]) and min(f["f1"] for f in r["sac"]) >= 0.9 for r in rows)
            lines += ["", f"examples at note F1 0.9 or more from every hand start: {every} of {len(rows)}"]
        lines += [""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duets", type=int, default=50)
    parser.add_argument("--polyphonic", type=int, default=20)
    parser.add_argument("--seed", type=int, default=35)
    parser.add_argument("--general", help="the general policy's folder (default: the packaged ones, one per hand)")
    parser.add_argument(
        "--general-left",
        help="the left hand's general policy (default: --general's when given, else the packaged left hand's)",
    )
    parser.add_argument(
        "--parts",
        help="the parts policy: both hands', as play gives them the packaged left hand's policy (overrides "
        "--general and --general-left)",
    )
    parser.add_argument("--apart", action="store_true", help="each hand in a simulation of its own")
    parser.add_argument(
        "--examples",
        type=Path,
        nargs="?",
        const=Path("examples/midi"),
        help="also play the two-hand files of this folder (default examples/midi) from hand starts 0-2, as "
        "`pianobot play` plays them, against each file",
    )
    parser.add_argument(
        "--hold-guard",
        action=argparse.BooleanOptionalAction,
        help="the general policies through the hold guard, or (--no-hold-guard) alone; default: as `pianobot play` "
        "plays them (the parts policy through it, the melody policy alone)",
    )
    parser.add_argument(
        "--lowest-note",
        type=parse_pitch,
        help="with --keys, play every part of the random sets on these keys (as `pianobot play --lowest-note "
        "--keys`), notes outside them left out; default: each player's own",
    )
    parser.add_argument("--keys", type=int, help="how many keys, from --lowest-note")
    fingers = parser.add_mutually_exclusive_group()
    fingers.add_argument("--thumb", action="store_true", help="each hand with its thumb too (as play --thumb)")
    fingers.add_argument("--no-thumb", action="store_true", help="three fingers on each hand (as play --no-thumb)")
    fingers.add_argument(
        "--hand-model",
        choices=tuple(HAND_MODELS),
        help="each hand this model with its fingers (as play --hand-model); the general policy plays where one is "
        "packaged for it (or --general or --general-left names one), else the scripted pianist alone",
    )
    parser.add_argument("--json", help="write every piece's figures here")
    args = parser.parse_args()
    hand = THUMB if args.thumb else HandSpec() if args.no_thumb else None  # (None: as play_hands chooses)
    players = PLAYERS
    if args.hand_model is not None and args.hand_model != HandSpec.model:
        hand = default_fingers(args.hand_model)
        packaged = parts_policy(None, None, hand) is not None
        players = PLAYERS if args.general or args.general_left or packaged else ("scripted",)
    if (args.lowest_note is None) != (args.keys is None):
        parser.error("--lowest-note and --keys go together")
    keyboard = KeyboardSpec(args.lowest_note, args.keys) if args.keys is not None else None
    torch.set_num_threads(1)
    sets = {
        "duets": duet_set(args.seed, args.duets),
        "polyphonic": polyphonic_set(args.seed + 1, args.polyphonic),
    }
    results = {}
    started = time.perf_counter()
    for name, pieces in sets.items():
        if not pieces:
            continue
        general = {"right": args.general, "left": args.general_left} if args.general_left else args.general
        results[name] = play_set(pieces, general, not args.apart, args.parts, args.hold_guard, keyboard, hand, players)
        print(table(name, results[name], players), flush=True)
    if args.examples is not None:
        general = {"right": args.general, "left": args.general_left} if args.general_left else args.general
        results["examples"] = play_examples(example_set(args.examples, hand), general, args.hold_guard, players=players)
        print(example_table(results["examples"]), flush=True)
    print(f"{time.perf_counter() - started:.0f} s")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
