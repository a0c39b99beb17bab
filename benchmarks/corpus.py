"""Real two-hand keyboard music nobody here wrote: excerpts of music21's corpus of public-domain
scores, written to MIDI files and played as ``pianobot play`` plays them, against each file.

    pip install -e ".[corpus]"      # music21, which carries its corpus
    python -m benchmarks.corpus [--set test|validation|more|reductions] [--out out/corpus] [--json out.json] [--only NAME ...]
                                [--hold-guard | --no-hold-guard]

Each excerpt is a piece's first measures (from :data:`EXCERPTS`' first measure), as many as keep
it within :data:`MAX_NOTES` notes and :data:`MAX_SECONDS` seconds at the score's own tempo
(music21's default of 120 bpm where the score gives none), repeats not taken; its staves (the
chorales' voices) are the MIDI file's tracks, named as music21 names them: "Piano" and the like,
for no hand, so the fingering planner gives their notes hands, as ``pianobot play`` does; a
chorale's "Bass" is read as a left hand's track (its other voices go to the hands by the planner).
Nothing was chosen or tuned on these pieces: they were played once, as found. ``--set
validation`` plays twelve other excerpts (:data:`VALIDATION`: three more of Clara Schumann's
polonaises, her trio's piano part, two songs' accompaniments, six chorales), which no figure of
the test set comes from: a setting is chosen on them, and the test set then says how it plays.
``--set more`` plays a second, larger test set added later (:data:`MORE`: 30 more chorales and
five pieces of other kinds), which chose nothing either, and ``--set reductions`` a third
(:data:`REDUCTIONS`: vocal scores and a string quartet, every part, reduced for two hands).

    python -m benchmarks.corpus --write-training out/chorales [--count 160]

writes excerpts of other chorales (:func:`write_training`: the first ``--count`` of music21's Bach
chorales by corpus path, none of the test or validation pieces) for ``pianobot train --task parts
--pieces out/chorales``, the recipe of the packaged thumb's policy (models/README.md).

Both players play each file as ``pianobot play`` reads it (:func:`pianobot.perform.together.two_hands`):
the general policies (the packaged ones: the parts policy on both hands, through the hold guard)
from hand start 0, and the scripted pianist; figures against the file as written, so notes the
reduction left out (faster than the hand moves, chords wider than it reaches, more notes than it
has fingers) count as missed. ``notes`` is the file as ``pianobot play`` reads it (a chord of
more notes than two hands have fingers thinned), ``notes given`` how many of them the hands were
given to play after that reduction: the most a player can strike; ``as given``, the per-step F1 and
note F1 with offsets of those notes as given (the reduction ends a note early where the hand cannot
hold it), against the file: the most a player of them scores, beside the scripted pianist's. ``--apart`` plays each hand in a
simulation of its own (``pianobot.perform.together.play_hands(..., together=False)``): what the
hands lose by getting in each other's way. By default the Allegro-like hand plays (``pianobot play
--hand-model allegro``; ``play`` alone gives two-hand files the pianist's hands), its fingers chosen
per file as ``play`` chooses them (:func:`pianobot.perform.together.fingers_for_file`: the thumbs
too where they keep notes three fingers leave out; the row's ``fingers``); ``--thumb`` gives each hand its thumb
everywhere (``pianobot play --thumb``), ``--no-thumb`` three fingers everywhere, ``--hand-model
pianist`` the pianist's five fingers (its packaged parts policy beside the scripted pianist); the general
policy plays where one for that hand is packaged (else the scripted pianist alone plays);
``--general DIR`` names the general policy to play both hands.
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

from benchmarks.hands import figures
from pianobot.agent.general import parts_policy
from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.instrument import THUMB, HandSpec
from pianobot.music.load import LoadOptions
from pianobot.perform.together import fingers_for_file, two_hands
from pianobot.sim.hand import HAND_MODELS, default_fingers

EXCERPTS = (
    # (name, music21 corpus path, the parts that are the piano's staves (None: all), first measure)
    ("bach-prelude-c", "bach/bwv846", None, 1),
    ("mozart-k545", "mozart/k545/movement1_exposition", None, 1),
    ("joplin-maple-leaf", "joplin/maple_leaf_rag", None, 0),
    ("chopin-mazurka-6-2", "chopin/mazurka06-2.krn", None, 1),
    ("cpebach-h186", "cpebach/h186", None, 1),
    ("schoenberg-op19-2", "schoenberg/opus19/movement2", None, 1),
    ("schoenberg-op19-6", "schoenberg/opus19/movement6", None, 1),
    ("clara-schumann-polonaise", "schumann_clara/polonaise_op1n1", None, 1),
    ("beach-prayer", "beach/prayer_of_a_tired_child", (4, 5), 1),
    ("aloha-oe", "liliuokalani/aloha_oe", (5, 6), 0),
    ("chorale-bwv66-6", "bach/bwv66.6", None, 0),
    ("chorale-bwv269", "bach/bwv269", None, 0),
)
"""Two-staff keyboard pieces of every kind the corpus holds (a prelude, a sonata, a rag, a
mazurka, a polonaise, atonal miniatures, a song's accompaniment) and two four-voice chorales:
the test set."""
VALIDATION = (
    ("clara-schumann-polonaise-2", "schumann_clara/polonaise_op1n2", None, 1),
    ("clara-schumann-polonaise-3", "schumann_clara/polonaise_op1n3", None, 1),
    ("clara-schumann-polonaise-4", "schumann_clara/polonaise_op1n4", None, 1),
    ("clara-schumann-trio-3", "schumann_clara/opus17/movement3", (2, 3), 1),
    ("schubert-lindenbaum", "schubert/Lindenbaum", (1, 2), 1),
    ("handel-lascia", "handel/rinaldo/Lascia_chio_pianga", (1, 2), 1),
    ("chorale-bwv8-6", "bach/bwv8.6", None, 0),
    ("chorale-bwv80-8", "bach/bwv80.8", None, 0),
    ("chorale-bwv81-7", "bach/bwv81.7", None, 0),
    ("chorale-bwv83-5", "bach/bwv83.5", None, 0),
    ("chorale-bwv84-5", "bach/bwv84.5", None, 0),
    ("chorale-bwv85-6", "bach/bwv85.6", None, 0),
)
"""Other excerpts, for choosing settings: none of the test set's pieces (the trio's and the songs'
piano staves only)."""
MORE_CHORALES = (265, 266, 267, 268, "27.6", 270, 271, 272, 273, 274, 275, 276, 277, 278, 279, "28.6", 280)
MORE_CHORALES += (281, 282, 283, 284, 285, 286, 287, 288, 289, "29.8", 290, 291, 292)
"""The chorales of :data:`MORE`: music21's next 30 by corpus path (bwvN) after those :func:`write_training` writes."""
MORE = tuple((f"bwv{n}", f"bach/bwv{n}", None, 0) for n in MORE_CHORALES) + (
    ("schumann-dichterliebe-2", "schumann_robert/dichterliebe_no2", (1, 2), 1),
    ("verdi-la-donna-e-mobile", "verdi/laDonnaEMobile", (0, 1), 1),
    ("weber-concertino", "weber/concertino_clarinet", (1, 2), 1),
    ("johnson-lift-every-voice", "johnson_j_r/lift_every_voice", None, 1),
    ("corelli-op3-1-grave", "corelli/opus3no1/1grave", None, 1),
)
"""A second test set, larger and added later (2026-12-07), that chose nothing: the 30 Bach chorales
that come next by corpus path after the 160 :func:`write_training` writes (bwv265 to bwv292), and
five pieces of other kinds: a song's piano staves (Schumann), an aria's piano reduction (Verdi), a
concertino's piano reduction (Weber), a four-part hymn (Johnson) and a trio sonata's three parts
(Corelli), which the hands play reduced."""
REDUCTIONS = (
    ("monteverdi-3-1", "monteverdi/madrigal.3.1", None, 1),
    ("monteverdi-3-5", "monteverdi/madrigal.3.5", None, 1),
    ("monteverdi-4-1", "monteverdi/madrigal.4.1", None, 1),
    ("monteverdi-4-5", "monteverdi/madrigal.4.5", None, 1),
    ("monteverdi-5-1", "monteverdi/madrigal.5.1", None, 1),
    ("palestrina-agnus-00", "palestrina/Agnus_00", None, 1),
    ("palestrina-credo-76", "palestrina/Credo_76", None, 1),
    ("palestrina-kyrie-10", "palestrina/Kyrie_10", None, 1),
    ("luca-gloria", "luca/gloria", None, 1),
    ("trecento-fava", "trecento/Fava_Dicant_nunc_iudei", None, 1),
    ("schumann-op41-1-1", "schumann_robert/opus41no1/movement1", None, 1),
    ("schumann-op41-1-2", "schumann_robert/opus41no1/movement2", None, 1),
)
"""A third test set, added 2026-12-08, that chose nothing: vocal scores and a string quartet, every
part, which two hands play reduced (as a pianist plays from a vocal score or a quartet's score):
five-voice madrigals (Monteverdi), four- to six-voice mass movements (Palestrina), two medieval
pieces (a Gloria by Luca, a motet by Fava) and the first two movements of Robert Schumann's string
quartet op. 41 no. 1 (the second a presto scherzo, quavers at 207 bpm). None of their composers is
among the training pieces' (:func:`write_training`: Bach chorales and the quartets of
:data:`QUARTETS`). Left out: the corpus's Webern (music21 cannot time it: it has no tempo) and
Ciconia (its excerpt is one voice, a one-hand file)."""
SETS = {"test": EXCERPTS, "validation": VALIDATION, "more": MORE, "reductions": REDUCTIONS}
TRAINING_COUNT = 160
"""Chorales :func:`write_training` writes by default: those the packaged thumb's policy was trained on."""
MAX_NOTES = 150
MAX_SECONDS = 40.0


def _measures(score, parts, first: int, last: int):
    """The excerpt: measures ``first``..``last`` of ``parts``, repeat signs taken away."""
    from music21 import bar, stream

    excerpt = stream.Score()
    for part in score.parts if parts is None else [score.parts[i] for i in parts]:
        sub = part.measures(first, last)
        for measure in sub.recurse().getElementsByClass("Measure"):
            for side in ("leftBarline", "rightBarline"):
                if isinstance(getattr(measure, side), bar.Repeat):
                    setattr(measure, side, None)
            for mark in list(measure.getElementsByClass("RepeatExpression")):
                measure.remove(mark)
        for bracket in list(sub.recurse().getElementsByClass("RepeatBracket")):
            sub.remove(bracket, recurse=True)
        excerpt.insert(0, sub)
    return excerpt


def write_excerpt(path: str, parts, first: int, out: Path) -> dict:
    """Write the longest excerpt from measure ``first`` within the limits to ``out``; what it holds."""
    from music21 import corpus
    from music21.midi import translate

    score = corpus.parse(path)
    measures = [m.number for m in score.parts[0].getElementsByClass("Measure")]
    kept = None
    for last in range(first, max(measures) + 1):
        excerpt = _measures(score, parts, first, last)
        notes = sum(len(n.pitches) for n in excerpt.stripTies().flatten().notes)
        if notes > MAX_NOTES or excerpt.flatten().seconds > MAX_SECONDS:
            break
        kept = (last, excerpt)
    if kept is None:
        raise ValueError(f"{path}: measure {first} alone is over the limits")
    last, excerpt = kept
    midi = translate.streamToMidiFile(excerpt)
    midi.open(str(out), "wb")
    midi.write()
    midi.close()
    return {"source": path, "measures": f"{first}-{last}"}


QUARTETS = ("mozart", "haydn", "beethoven")
"""The composers whose string quartets :func:`write_training` may add (``quartets``): four parts that
two hands play reduced, as in a quartet's piano reduction."""


def write_training(out: Path, count: int = TRAINING_COUNT, quartets: bool = False) -> list[Path]:
    """Write excerpts of the first ``count`` Bach chorales of music21's corpus (its MusicXML files, by path, each
    from its first measure within the limits, as the test chorales are) to ``out``, none of the
    test sets' or validation set's pieces, nor the Well-Tempered Clavier's prelude: training pieces for
    ``pianobot train --task parts --pieces``; ``quartets``: then an excerpt of every movement of the
    string quartets of :data:`QUARTETS` (MusicXML), all four parts, from measure 1. A piece music21
    cannot excerpt is passed over (said)."""
    from music21 import corpus

    used = {path for _, path, *_ in EXCERPTS + VALIDATION + MORE + REDUCTIONS} | {"bach/bwv846"}
    scores = [str(p).split("corpus/")[-1] for p in corpus.getComposer("bach")]
    found = {p.rsplit(".", 1)[0] for p in scores if p.endswith(".mxl")}
    chorales = [p for p in sorted(found) if p not in used]
    quartet_paths = []
    for composer in QUARTETS if quartets else ():
        paths = sorted(str(p).split("corpus/")[-1] for p in corpus.getComposer(composer))
        quartet_paths += [p.rsplit(".", 1)[0] for p in paths if p.endswith(".mxl") and p.rsplit(".", 1)[0] not in used]
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in chorales:
        if len(written) == count:
            break
        written += _excerpt_to(path, 0, out / (path.split("/")[-1].replace(".", "-") + ".mid"))
    for path in quartet_paths:
        written += _excerpt_to(path, 1, out / (path.replace("/", "-").replace(".", "-") + ".mid"))
    return written


def _excerpt_to(path: str, first: int, file: Path) -> list[Path]:
    """[``file``] with the excerpt of ``path`` from measure ``first`` written to it; [] (said) where music21 cannot."""
    try:
        write_excerpt(path, None, first, file)
    except Exception as error:  # (music21's own errors: a score it cannot excerpt)
        print(f"{path}: passed over ({str(error)[:80]})")
        return []
    return [file]


def play_corpus(
    folder: Path,
    only: tuple[str, ...] = (),
    together: bool = True,
    hand: HandSpec | None = None,
    general: Path | None = None,
    excerpts: tuple = EXCERPTS,
    hold_guard: bool | None = None,
) -> list[dict]:
    """Write the excerpts to ``folder`` and play each with both players (``together``: both hands
    in one simulation, as ``pianobot play`` plays them; ``hand``: each hand's fingers, default
    chosen per file as ``pianobot play`` chooses them; ``general``:
    the general policy on both hands, default the packaged one for ``hand``, and where none is
    packaged for it the scripted pianist alone plays; ``hold_guard``: the general policy through the
    hold guard, or alone, default as ``pianobot play`` plays it); a row each."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, path, parts, first in excerpts:
        if only and name not in only:
            continue
        file = folder / f"{name}.mid"
        row = {"piece": name, **write_excerpt(path, parts, first, file)}
        fingers = hand if hand is not None else fingers_for_file(file, LoadOptions())[0]
        plays = general is not None or parts_policy(None, None, fingers) is not None
        row["fingers"] = list(fingers.fingers)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PianobotWarning)
                reading = two_hands(file, LoadOptions(), fingers)
        except PianobotError as error:  # (refused: the row says why)
            rows.append({**row, "refused": str(error)})
            print(f"{name}: refused: {error}", flush=True)
            continue
        if reading is None:
            rows.append({**row, "refused": "read as one hand's file"})
            print(f"{name}: read as one hand's file", flush=True)
            continue
        with tempfile.TemporaryDirectory() as models:  # (an empty store: the packaged policies play)
            piece = reading.piece
            policy = (
                figures(piece, "sac", models, general, together=together, hold_guard=hold_guard, hand=fingers)
                if plays
                else None
            )
            row.update(
                notes=len(piece),
                sac=policy,
                scripted=figures(piece, "scripted", models, together=together, hand=fingers),
            )
        rows.append(row)
        said = f"{row['sac']['f1']:.3f}" if row["sac"] else "n/a"
        print(f"{name}: general {said}, scripted {row['scripted']['f1']:.3f}", flush=True)
    return rows


def table(rows: list[dict]) -> str:
    """The rows as Markdown; "notes given" as the general policy was given them (the scripted
    pianist's where the general policy did not play: ``--thumb``)."""
    lines = [
        "| piece | corpus path (measures) | fingers | notes | notes given | note F1, general policy | right | left | "
        "per-step F1, general policy | note F1, scripted pianist | general / scripted | "
        "per-step F1, offsets: scripted pianist | as given |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |",
    ]
    played = [r for r in rows if "refused" not in r]
    for r in rows:
        where = f"`{r['source']}` ({r['measures']})"
        if "refused" in r:
            lines.append(f"| {r['piece']} | {where} | | | | refused: {r['refused']} | | | | | | | |")
            continue
        g, s = r["sac"], r["scripted"]
        general = (
            f"{g['f1']:.3f} | {g['f1_right']:.3f} | {g['f1_left']:.3f} | {g['step_f1']:.3f}" if g else "n/a | | | n/a"
        )
        share = _share(g["f1"], s["f1"]) if g else "n/a"
        fingers = "-".join(str(f) for f in r["fingers"][:: len(r["fingers"]) - 1]) if r.get("fingers") else ""
        lines.append(
            f"| {r['piece']} | {where} | {fingers} | {r['notes']} | {(g or s)['given']} | {general} | {s['f1']:.3f} | {share} "
            f"| {_held(s)} | {_held(s['as_given'])} |"
        )
    if played:
        given = sum((r["sac"] or r["scripted"])["given"] for r in played) / sum(r["notes"] for r in played)
        scripted = np.mean([r["scripted"]["f1"] for r in played])
        with_general = [r for r in played if r["sac"]]
        general = np.mean([r["sac"]["f1"] for r in with_general]) if with_general else None
        steps = np.mean([r["sac"]["step_f1"] for r in with_general]) if with_general else None
        lines.append(
            f"| mean ({len(played)} played) | | | | {given:.0%} given | "
            + (f"{general:.3f} | | | {steps:.3f}" if general is not None else "n/a | | | n/a")
            + f" | {scripted:.3f} | {_share(general, scripted) if general is not None else 'n/a'} "
            + f"| {_held(_means([r['scripted'] for r in played]))} "
            + f"| {_held(_means([r['scripted']['as_given'] for r in played]))} |"
        )
    return "\n".join(lines)


def _means(figures: list[dict]) -> dict:
    return {key: float(np.mean([f[key] for f in figures])) for key in ("step_f1", "f1_offsets")}


def _held(figures: dict) -> str:
    """Per-step F1 and note F1 with offsets: how long the notes were held (as given: how long the
    reduction left them, the most a player of them scores)."""
    return f"{figures['step_f1']:.3f}, {figures['f1_offsets']:.3f}"


def _share(general: float, scripted: float) -> str:
    return f"{general / scripted:.0%}" if scripted > 0 else "n/a"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--set",
        choices=tuple(SETS),
        default="test",
        help="the test excerpts, the validation ones, the larger second test set, or the third (vocal scores "
        "and a quartet, every part)",
    )
    parser.add_argument(
        "--out", type=Path, help="folder the excerpts are written to (default out/corpus, or out/corpus-SET)"
    )
    parser.add_argument("--only", nargs="+", default=(), help="only these excerpts (by name)")
    parser.add_argument("--json", type=Path, help="write every figure to this file")
    parser.add_argument("--apart", action="store_true", help="each hand in a simulation of its own")
    fingers = parser.add_mutually_exclusive_group()
    fingers.add_argument("--thumb", action="store_true", help="each hand with its thumb too, in every file")
    fingers.add_argument("--no-thumb", action="store_true", help="three fingers in every file")
    fingers.add_argument(
        "--hand-model",
        choices=tuple(HAND_MODELS),
        help="each hand this model with its fingers (as play --hand-model); the general policy plays where one "
        "is packaged for it, else the scripted pianist alone",
    )
    parser.add_argument(
        "--general",
        type=Path,
        help="the general policy's folder, on both hands (default: the packaged one for the hand; "
        "where none is packaged for it, the scripted pianist alone plays)",
    )
    parser.add_argument(
        "--hold-guard",
        action=argparse.BooleanOptionalAction,
        help="the general policy through the hold guard, or (--no-hold-guard) alone; default: as `pianobot play` "
        "plays it (a parts policy through the guard, a melody policy alone)",
    )
    parser.add_argument(
        "--write-training",
        type=Path,
        metavar="DIR",
        help="only write excerpts of other chorales to DIR, to train on (pianobot train --task parts --pieces DIR)",
    )
    parser.add_argument(
        "--quartets",
        action="store_true",
        help="with --write-training: also excerpts of the string quartets of " + ", ".join(QUARTETS),
    )
    parser.add_argument(
        "--count",
        type=int,
        default=TRAINING_COUNT,
        help="with --write-training: how many chorales (default %(default)s)",
    )
    args = parser.parse_args()
    torch.set_num_threads(1)  # (the simulation is the cost; torch's threads would only contend)
    try:
        import music21
    except ImportError:
        parser.error('music21 is not installed: pip install -e ".[corpus]"')
    if args.count < 1:
        parser.error(f"--count {args.count}: give 1 or more chorales")
    if args.write_training is not None:
        written = write_training(args.write_training, args.count, args.quartets)
        print(f"{len(written)} excerpts written to {args.write_training}")
        return
    started = time.perf_counter()
    hand = (
        THUMB if args.thumb else HandSpec() if args.no_thumb else None
    )  # (None: as play --hand-model allegro chooses)
    if args.hand_model is not None and args.hand_model != HandSpec.model:
        hand = default_fingers(args.hand_model)
    out = args.out or Path("out/corpus" if args.set == "test" else f"out/corpus-{args.set}")
    rows = play_corpus(out, tuple(args.only), not args.apart, hand, args.general, SETS[args.set], args.hold_guard)
    seconds = time.perf_counter() - started
    print()
    print(table(rows))
    chosen = (
        "with thumbs; "
        if args.thumb
        else "three fingers; "
        if args.no_thumb
        else "the Allegro-like hand's fingers as play chooses; "
    )
    if args.hand_model is not None:
        chosen = f"the {args.hand_model} hand; "
    how = ("each hand apart; " if args.apart else "") + chosen
    how += {True: "the general policy through the hold guard; ", False: "the general policy alone; "}.get(
        args.hold_guard, ""
    )
    print(f"\nmusic21 {music21.__version__}; {how}{seconds:.0f} s")
    if args.json:
        record = {
            "music21": music21.__version__,
            "set": args.set,
            "apart": args.apart,
            "thumb": True if args.thumb else False if args.no_thumb else "as play chooses",
            "hand_model": hand.model if hand is not None else HandSpec.model,
            "general": None if args.general is None else str(args.general),
            "hold_guard": "as play plays it" if args.hold_guard is None else args.hold_guard,
            "seconds": round(seconds),
            "rows": rows,
        }
        args.json.write_text(json.dumps(record, indent=2) + "\n")


if __name__ == "__main__":
    main()
