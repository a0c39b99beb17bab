"""Every example played as `pianobot play` plays it, with the committed models, from hand starts 0-3:
the figures of models/README.md and of the README's rows that quote them, written from one run.

    python -m benchmarks.examples            # play, write models/examples.json and the tables
    python -m benchmarks.examples --check    # play, and fail where a recorded figure no longer holds

The examples with phrase policies of their own (models/), the two-hand examples as `play`
plays them (the pianist's hands with their packaged general policy; Ode to Joy is `make demo`'s
second piece) and the same with the Allegro-like hand (:data:`ALLEGRO`, its packaged general
policies) are played through the command line itself (`pianobot play
examples/midi/<name>.mid --seed N`, in this process), so that what is measured is what a user
runs. The tables sit between ``<!-- examples:NAME -->`` and ``<!-- /examples:NAME -->`` markers;
everything between them is rewritten. ``tests/test_examples_play.py`` runs the check.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).parent.parent
EXAMPLES = ROOT / "examples" / "midi"
RECORD = ROOT / "models" / "examples.json"
SEEDS = (0, 1, 2, 3)
PHRASE_POLICIES = {  # example -> the options its phrase policies were trained with
    "one-note": [],
    "three-note": [],
    "rhythmic": [],
    "chord": [],  # (play finds the --phrase-notes 3 split its policies were trained in)
    "six-note": [],
    "twinkle": [],
}
TWO_HANDS = ("chorale-performed", "ode-to-joy-performed", "prelude-performed", "minuet-performed",
             "nocturne-performed", "twinkle-performed")  # fmt: skip
DEMO = "ode-to-joy-performed"
"""`make demo`'s second piece."""
ALLEGRO = tuple(f"{name} --hand-model allegro" for name in TWO_HANDS)
"""The two-hand examples played by the Allegro-like hand (its packaged general policies); each
named by the arguments `pianobot play` is given."""
FLOOR = {"phrase": 1.0, "two-hand": 0.9, "allegro": 0.9}
"""What the docs promise from every hand start: the phrase-policy examples play every note, the
two-hand examples (either hand model) at note F1 0.9 or more."""
SLACK = 0.03
"""A check also fails where a figure falls this far below the recorded one (floating point may
differ across machines by a physics step now and then; a real regression moves more)."""


def play(name: str, seed: int, scratch: Path) -> dict:
    """`pianobot play examples/midi/<name>.mid --seed <seed>` in this process: its report (``name``
    may go on with options: 'ode-to-joy-performed --hand-model allegro')."""
    from typer.testing import CliRunner

    from pianobot.cli.app import app

    stem, *options = name.split()
    file = "".join(c if c.isalnum() else "-" for c in name)  # (its options too: one file per entry)
    out, report = scratch / f"{file}-{seed}.mid", scratch / f"{file}-{seed}.json"
    args = ["play", str(EXAMPLES / f"{stem}.mid"), "-o", str(out), "--seed", str(seed), "--json", str(report), "-q"]
    result = CliRunner().invoke(app, [*args, *options, *PHRASE_POLICIES.get(name, [])])
    if result.exit_code:
        said = " ".join([f"{stem}.mid", *options])
        raise RuntimeError(f"pianobot play {said} --seed {seed} failed: {result.output.strip()}")
    figures = json.loads(report.read_text())
    warnings = [line for line in result.output.splitlines() if line.startswith("warning:")]
    return {
        "performer": figures["performer"],
        "f1": round(figures["f1"], 4),
        "velocity_mae": None if figures["velocity_mae"] is None else round(figures["velocity_mae"], 2),
        "onset_error_ms": None if figures["onset_error_mean"] is None else round(1000 * figures["onset_error_mean"]),
        "notes": figures["reference_notes"],
        "judged": [w.removeprefix("warning: ") for w in warnings if "played both ways" in w],
    }


def play_all(names: list[str], seeds=SEEDS, say=print) -> dict:
    """{name: {"kind", "seeds": {seed: figures}}} for every example in ``names``."""
    import torch

    torch.set_num_threads(1)
    out = {}
    with tempfile.TemporaryDirectory() as scratch:
        for name in names:
            kind = "phrase" if name in PHRASE_POLICIES else "allegro" if name in ALLEGRO else "two-hand"
            out[name] = {"kind": kind, "seeds": {str(s): play(name, s, Path(scratch)) for s in seeds}}
            f1s = " ".join(f"{v['f1']:.3f}" for v in out[name]["seeds"].values())
            say(f"{name}: note F1 {f1s}")
    return out


def problems(played: dict, recorded: dict) -> list[str]:
    """Where ``played`` breaks a promise: below the floor, or ``SLACK`` below the recorded figure."""
    found = []
    for name, entry in played.items():
        for seed, figures in entry["seeds"].items():
            floor = FLOOR[entry["kind"]]
            if figures["f1"] < floor:
                found.append(f"{name} from hand start {seed}: note F1 {figures['f1']:.3f}, below {floor}")
            before = recorded.get(name, {}).get("seeds", {}).get(seed)
            if before is not None and figures["f1"] < before["f1"] - SLACK:
                found.append(f"{name} from hand start {seed}: note F1 {figures['f1']:.3f}, recorded {before['f1']:.3f}")
    return found


def _span(values: list) -> str:
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    low, high = min(values), max(values)
    return f"{low:g}" if low == high else f"{low:g}–{high:g}"


def _f1s(entry: dict) -> str:
    f1s = [v["f1"] for v in entry["seeds"].values()]
    return f"{f1s[0]:.3f} ×{len(f1s)}" if len(set(f1s)) == 1 else " / ".join(f"{f:.3f}" for f in f1s)


def _each(entry: dict) -> str:
    """An entry's note F1 in words: '1.000 from each of hand starts 0–3', or each start's."""
    f1s = {seed: v["f1"] for seed, v in entry["seeds"].items()}
    if len(set(f1s.values())) == 1:
        return f"{next(iter(f1s.values())):.3f} from each of hand starts {min(f1s)}–{max(f1s)}"
    return ", ".join(f"{f:.3f} from hand start {seed}" for seed, f in f1s.items())


def _who(performer: str) -> str:
    """A performer in few words: 'own policies', 'task-parts-v2-... (hold guard)'."""
    who = performer.removeprefix("general policy ").replace(" (both hands in one simulation)", "")
    return who.replace(" through the hold guard", " (hold guard)")


def _shown(name: str) -> str:
    """An entry's name as the tables show it: '`ode-to-joy-performed.mid` `--hand-model allegro`'."""
    stem, *options = name.split()
    return f"`{stem}.mid`" + (f" `{' '.join(options)}`" if options else "")


def tables(record: dict) -> dict[str, str]:
    """The Markdown each marker pair holds, from ``record`` (the Allegro-like hand's rows in the two-hand table)."""
    rows = {"phrase": [], "two-hand": [], "allegro": []}
    for name, entry in record["examples"].items():
        seeds = list(entry["seeds"].values())
        performers = " / ".join(dict.fromkeys(_who(v["performer"]) for v in seeds))
        judged = sum(bool(v["judged"]) for v in seeds)
        said = f" (judged {judged}×: policies from another simulator)" if judged else ""
        rows[entry["kind"]].append(
            f"| {_shown(name)} ({seeds[0]['notes']} note{'s' * (seeds[0]['notes'] != 1)}) | {performers}{said} | {_f1s(entry)} | "
            f"{_span([round(v['velocity_mae'], 1) for v in seeds if v['velocity_mae'] is not None])} | "
            f"{_span([v['onset_error_ms'] for v in seeds])} |"
        )
    head = "| example | who plays | note F1, hand starts 0–3 | velocity MAE | mean onset error (ms) |\n| --- | --- | --- | --- | --- |\n"
    phrase = [e for e in record["examples"].values() if e["kind"] == "phrase"]
    two = {name: e for name, e in record["examples"].items() if e["kind"] == "two-hand"}
    allegro = [e for e in record["examples"].values() if e["kind"] == "allegro"]
    lowest = lambda entries: min(v["f1"] for e in entries for v in e["seeds"].values())  # noqa: E731
    mean = lambda entries: statistics.mean(v["f1"] for e in entries for v in e["seeds"].values())  # noqa: E731
    demo = "".join(
        f"; {_shown(name)} (`make demo`'s second piece): {_each(e)}" for name, e in two.items() if name == DEMO
    )
    return {
        "phrase": head + "\n".join(rows["phrase"]),
        "two-hand": head + "\n".join(rows["two-hand"] + rows["allegro"]),
        "readme": (
            f"the examples with phrase policies of their own, each from hand starts 0–3: lowest note F1 "
            f"{lowest(phrase):.3f}; the two-hand examples, the pianist's hands with their packaged general policy: "
            f"lowest {lowest(two.values()):.3f}, mean {mean(two.values()):.3f} (the Allegro-like hand's: lowest "
            f"{lowest(allegro):.3f}, mean {mean(allegro):.3f}){demo}"
        ),
    }


def write_tables(record: dict, files=(ROOT / "models" / "README.md", ROOT / "README.md")) -> None:
    made = tables(record)
    for path in files:
        text = path.read_text()
        for name, body in made.items():
            begin, end = f"<!-- examples:{name} -->", f"<!-- /examples:{name} -->"
            if begin in text:
                head, rest = text.split(begin, 1)
                _, tail = rest.split(end, 1)
                inline = not head.endswith("\n")
                text = head + begin + (body if inline else f"\n{body}\n") + end + tail
        path.write_text(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with models/examples.json; write nothing")
    parser.add_argument("--only", default=None, help="these examples only (names separated by commas)")
    parser.add_argument("--tables", action="store_true", help="write the tables from the record; play nothing")
    args = parser.parse_args(argv)
    if args.tables:
        write_tables(json.loads(RECORD.read_text()))
        return 0
    known = [*PHRASE_POLICIES, *TWO_HANDS, *ALLEGRO]
    names = [" ".join(name.split()) for name in args.only.split(",")] if args.only else known
    unknown = [name for name in names if name not in known]
    if unknown:
        parser.error(f"--only {', '.join(unknown)}: not an example of the record; choose among {', '.join(known)}")
    played = play_all(names)
    recorded = json.loads(RECORD.read_text())["examples"] if RECORD.exists() else {}
    found = problems(played, recorded if args.check else {})
    for line in found:
        print(line, file=sys.stderr)
    if args.check:
        return 1 if found else 0
    kept = {name: entry for name, entry in {**recorded, **played}.items() if name in known}  # (none it no longer plays)
    record = {"command": "python -m benchmarks.examples", "seeds": list(SEEDS), "examples": kept}
    RECORD.write_text(json.dumps(record, indent=2) + "\n")
    write_tables(record)
    print(f"wrote {RECORD.relative_to(ROOT)} and the tables; median note F1 "
          f"{statistics.median(v['f1'] for e in played.values() for v in e['seeds'].values()):.3f}")  # fmt: skip
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
