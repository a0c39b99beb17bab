"""The HTML report of a performance (play --html, score --html): every figure with what it means
(:data:`~pianobot.perform.figures.FIGURES`, kept here by name too), the piano roll, every note."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pianobot.music.metrics import Report
from pianobot.perform.figures import FIGURES, Figure, _opt, figures_for  # noqa: F401 (FIGURES, Figure: by their old address too)

FINGER_COLOURS = {1: "#8c564b", 2: "#1f77b4", 3: "#2ca02c", 4: "#ff7f0e", 5: "#9467bd", None: "#7f7f7f"}
"""A played note's colour: the finger that struck it (grey: none recorded)."""
PLAYER_COLOURS = {
    "own policy": "#dceaf7",
    "general policy": "#e3f1d8",
    "scripted pianist": "#f7ead6",
    "random actions": "#eeeeee",
}
"""The background of a stretch of the piano roll: who played it."""
MISSED = "#d62728"


@dataclass(frozen=True)
class Section:
    """A stretch of time and who played it."""

    phrases: tuple[int, ...]
    start: float
    end: float
    player: str
    policy: str | None = None


def sections(plan) -> list[Section]:
    """Who played when, from a :class:`~pianobot.perform.plan.PerformancePlan`."""
    return [
        Section(
            tuple(p.index for p in s.phrases),
            min(p.start for p in s.phrases),
            max(p.end for p in s.phrases),
            s.player.value,
            s.policy.name if s.policy is not None else None,
        )
        for s in plan.stretches
    ]


def _status(row) -> str:
    return "missed" if row.played is None else "extra" if row.reference is None else "matched"


def _svg(fig) -> str:
    """A matplotlib figure as an inline <svg> element (glyphs as paths: no font needed)."""
    import io

    import matplotlib.pyplot as plt

    buffer = io.StringIO()
    fig.savefig(buffer, format="svg", bbox_inches="tight")
    plt.close(fig)
    text = buffer.getvalue()
    return text[text.index("<svg") :]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _box(note, height: float, gid: str, **style):
    """A note's box in the roll, ``height`` semitones tall, with the SVG id ``gid``."""
    from matplotlib.patches import Rectangle

    box = Rectangle((note.onset, note.pitch - height / 2), note.duration, height, **style)
    box.set_gid(gid)
    return box


def roll_svg(report: Report, stretches: list[Section]) -> str:
    """The piano roll: the score's notes as outlines, the played notes filled in the colour of
    the finger that struck them (stronger when louder), missed notes in red outline, extra notes
    red-edged; behind them, who played each stretch. Each note's group has an id: ``score-N``,
    ``played-N`` (N: the row of the per-note table)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    plt = _pyplot()
    notes = [n for row in report.rows for n in (row.reference, row.played) if n is not None]
    low, high = min((n.pitch for n in notes), default=60), max((n.pitch for n in notes), default=60)
    end = max((n.offset for n in notes), default=1.0)
    fig, ax = plt.subplots(figsize=(11, 1.6 + 0.22 * (high - low + 3)))
    for s in stretches:
        ax.axvspan(s.start, s.end, color=PLAYER_COLOURS.get(s.player, "#eeeeee"), zorder=0, lw=0)
        ax.axvline(s.start, color="#888888", lw=0.8, ls="--", zorder=1)
        label = f"phrase{'s' * (len(s.phrases) > 1)} {', '.join(map(str, s.phrases))}"
        ax.text(s.start, high + 1.3, f" {label}", fontsize=7, color="#555555", va="top")
    for i, row in enumerate(report.rows):
        status = _status(row)
        missed = status == "missed"
        if row.reference is not None:
            box = _box(row.reference, 0.9, f"score-{i}", fill=False, lw=2 if missed else 0.8, zorder=3)
            ax.add_patch(box)
            box.set_edgecolor(MISSED if missed else "#333333")
        if row.played is not None:
            n = row.played
            colour = FINGER_COLOURS.get(n.finger, FINGER_COLOURS[None])
            box = _box(n, 0.6, f"played-{i}", facecolor=colour, alpha=0.35 + 0.65 * n.velocity / 127, lw=1.5, zorder=2)
            box.set_edgecolor(MISSED if status == "extra" else "none")
            box.set_hatch("//" if n.hand == "left" else None)
            ax.add_patch(box)
    ax.set_xlim(0, end * 1.01)
    ax.set_ylim(low - 1.5, high + 1.5)
    from pianobot.music.piece import pitch_name

    ticks = range(low - 1, high + 2)
    ax.set_yticks(list(ticks), [pitch_name(p) if p % 12 in (0, 4, 7) or p in (low, high) else "" for p in ticks])
    ax.set_xlabel("time (s)")
    ax.grid(axis="x", alpha=0.3)
    fingers = sorted({n.finger for n in notes if n.finger is not None})
    handles = [Patch(color=FINGER_COLOURS[f], label=f"finger {f}") for f in fingers]
    handles += [
        Line2D([], [], color="#333333", lw=1, label="score"),
        Line2D([], [], color=MISSED, lw=2, label="missed / extra"),
    ]
    handles += [Patch(color=PLAYER_COLOURS[p], label=p) for p in dict.fromkeys(s.player for s in stretches)]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    return _svg(fig)


def errors_svg(report: Report) -> str:
    """Each matched note's velocity error (played - score, MIDI) and onset error (ms) at its
    time, in the colour of its finger."""
    plt = _pyplot()
    matched = [row for row in report.rows if _status(row) == "matched"]
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(11, 4))
    for ax, values, label in (
        (axes[0], [row.velocity_error for row in matched], "velocity error\n(played - score)"),
        (axes[1], [row.onset_error * 1000 for row in matched], "onset error (ms)\n(+ late, - early)"),
    ):
        times = [row.reference.onset for row in matched]
        colours = [FINGER_COLOURS.get(row.played.finger, FINGER_COLOURS[None]) for row in matched]
        ax.axhline(0, color="#333333", lw=0.8)
        ax.vlines(times, 0, values, colors=colours, lw=2)
        ax.scatter(times, values, c=colours, s=14, zorder=3)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(alpha=0.3)
    axes[1].set_xlabel("time (s)")
    return _svg(fig)


_STYLE = """
body { font: 15px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 72em; padding: 0 1em; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { font-size: 1.15em; margin-top: 1.8em; }
p.what { color: #555; margin-top: 0; }
table { border-collapse: collapse; } td, th { padding: 0.15em 0.7em; border-bottom: 1px solid #ddd; text-align: left; }
td.value { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.meaning { color: #555; } tr.missed td, tr.extra td { color: #b00; }
video { max-width: 100%; background: #000; } svg { max-width: 100%; height: auto; }
.scroll { max-height: 30em; overflow-y: auto; display: inline-block; }
"""


def _figures_table(report: Report, first: bool) -> str:
    from html import escape

    rows = "".join(
        f"<tr><td>{escape(f.label)}</td><td class='value'>{escape(f.value(report))}</td>"
        f"<td class='meaning'>{escape(f.meaning)}</td></tr>"
        for f in figures_for(report, not first)
    )
    return f"<table class='figures'>{rows}</table>"


def _cell(value, fmt: str) -> str:
    return _opt(value, fmt, absent="-")


NOTE_COLUMNS = (
    "pitch",
    "score onset s",
    "played onset s",
    "onset error ms",
    "score velocity",
    "played velocity",
    "velocity error",
    "finger (score / played)",
    "status",
)
"""The per-note table's columns (:func:`note_cells`), in the terminal and the HTML page."""


def note_cells(row) -> tuple[str, ...]:
    """One row of the per-note table as text, in :data:`NOTE_COLUMNS` order ('-': nothing there)."""
    ref, out = row.reference, row.played
    onset_error = None if row.onset_error is None else row.onset_error * 1000
    return (
        (ref or out).name,
        _cell(ref and ref.onset, ".3f"),
        _cell(out and out.onset, ".3f"),
        _cell(onset_error, "+.0f"),
        _cell(ref and ref.velocity, "d"),
        _cell(out and out.velocity, "d"),
        _cell(row.velocity_error, "+d"),
        f"{_cell(ref and ref.finger, 'd')} / {_cell(out and out.finger, 'd')}",
        _status(row),
    )


def _notes_table(report: Report, stretches: list[Section], phrase_of: dict[int, int]) -> str:
    from html import escape

    player = {p: s.player for s in stretches for p in s.phrases}
    head = "".join(f"<th>{h}</th>" for h in ("#", *NOTE_COLUMNS, "phrase", "played by"))
    rows = []
    for i, row in enumerate(report.rows):
        phrase = phrase_of.get(i)
        cells = (str(i), *note_cells(row), "" if phrase is None else str(phrase), player.get(phrase, ""))
        rows.append(f"<tr class='{_status(row)}'>" + "".join(f"<td>{escape(c)}</td>" for c in cells) + "</tr>")
    return f"<div class='scroll'><table class='notes'><tr>{head}</tr>{''.join(rows)}</table></div>"


def _phrases_table(stretches: list[Section]) -> str:
    from html import escape

    rows = "".join(
        f"<tr><td>{', '.join(map(str, s.phrases))}</td><td>{s.start:.2f}-{s.end:.2f} s</td>"
        f"<td><span style='background:{PLAYER_COLOURS.get(s.player, '#eee')}'>&nbsp;&nbsp;&nbsp;</span> "
        f"{escape(s.player)}</td><td>{escape(s.policy or '')}</td></tr>"
        for s in stretches
    )
    return (
        f"<table class='phrases'><tr><th>phrases</th><th>time</th><th>played by</th><th>policy</th></tr>{rows}</table>"
    )


def _hands_section(performance, reading) -> str:
    """Each hand of a two-hand performance (:class:`~pianobot.perform.together.HandsPerformance`):
    who played it, where, what it was given, its figures, what was left out or reduced."""
    from html import escape

    from pianobot.perform.together import AGAINST

    head = "".join(
        f"<th>{h}</th>"
        for h in ("hand", "written", "played by", "played as", "notes given", "note F1", "key-press F1 per step")
    )
    rows = []
    for h in performance.hands:
        report = performance.report(h.hand)
        written = reading.describe(h.hand) if reading is not None else f"{len(performance.piece.part(h.hand))} notes"
        cells = (
            f"{h.hand} hand",
            written,
            h.performer,
            h.describe(),
            f"{len(h.part)} of {len(performance.piece.part(h.hand))}",
            f"{report.f1:.3f}",
            f"{report.step_f1:.3f}",
        )
        rows.append("<tr>" + "".join(f"<td>{escape(c)}</td>" for c in cells) + "</tr>")
    changes = [line for h in performance.hands for line in h.changes]
    listed = "".join(f"<li>{escape(line)}</li>" for line in changes) or "<li>nothing: every note was given</li>"
    return (
        "<section id='hands'><h2>Each hand</h2>"
        f"<p class='what'>Both hands played, {escape(performance.simulated)}: each hand's part given to its "
        "player as a right hand's (the left hand's mirrored about D); "
        f"{escape(AGAINST)}. In the piano roll the left hand's notes are hatched.</p>"
        f"<table class='hands'><tr>{head}</tr>{''.join(rows)}</table>"
        f"<h3>Left out or reduced</h3><ul class='changes'>{listed}</ul></section>"
    )


def _scores_section(scores) -> str:
    """Each hand of a two-hand reference, scored (:class:`~pianobot.music.per_hand.HandsReport`)."""
    from html import escape

    head = "".join(f"<th>{h}</th>" for h in ("part", "notes played", "note F1", "key-press F1 per step", "fingering"))
    rows = []
    for name, report in (("whole piece", scores.whole), *((f"{h} hand", r) for h, r in scores.hands.items())):
        extra = report.played_notes - report.matched_notes
        cells = (
            name,
            f"{report.matched_notes} of {report.reference_notes}, {extra} extra",
            f"{report.f1:.3f}",
            f"{report.step_f1:.3f}",
            _opt(report.fingering_accuracy, ".3f"),
        )
        rows.append("<tr>" + "".join(f"<td>{escape(c)}</td>" for c in cells) + "</tr>")
    return (
        "<section id='hands'><h2>Each hand</h2><p class='what'>The reference's notes of each hand against "
        "the played notes matched to them (an extra note counts for its own hand, else the nearest "
        f"reference note's).</p><table class='hands'><tr>{head}</tr>{''.join(rows)}</table></section>"
    )


def _media(path: Path | None, kind: str, mime: str) -> str:
    import base64

    if path is None:
        return ""
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f"<{kind} controls preload='auto' src='data:{mime};base64,{data}'></{kind}>"


def html_report(
    report: Report,
    title: str,
    *,
    plan=None,
    seed: int | None = None,
    video: Path | None = None,
    audio: Path | None = None,
    hands=None,
    reading=None,
    scores=None,
) -> str:
    """One self-contained HTML page (no file or network needed beside it): the figures with what
    they mean, the video (with its sound) and the audio when given, the piano roll of the score
    against what was played, each note's velocity and timing errors, who played each phrase
    (``plan``: a :class:`~pianobot.perform.plan.PerformancePlan`) and every note; for a two-hand
    performance (``hands``: a :class:`~pianobot.perform.together.HandsPerformance`, ``reading``
    what the file named) or a two-hand reference scored (``scores``: a
    :class:`~pianobot.music.per_hand.HandsReport`), each hand."""
    from html import escape

    stretches = sections(plan) if plan is not None else []
    phrase_of = {}
    if plan is not None:
        index = {id(n): p.index for p in plan.phrases for n in p.notes}
        by_note = {(n.onset, n.pitch): index[id(n)] for p in plan.phrases for n in p.notes}
        phrase_of = {
            i: by_note[(row.reference.onset, row.reference.pitch)]
            for i, row in enumerate(report.rows)
            if row.reference is not None and (row.reference.onset, row.reference.pitch) in by_note
        }
    performer = plan.performer if plan is not None else hands.performer if hands is not None else None
    # (one hand's fingers and hand model, as the report's JSON has them; each hand's are in its table)
    fingers = f", with fingers {plan.config.world.hand.spec.describe()}" if plan is not None else ""
    who = (
        f"Played by: {escape(performer)}{escape(fingers)}" + (f", from hand start {seed}" if seed is not None else "")
        if performer
        else ""
    )
    parts = [
        f"<!doctype html><html lang='en'><head><meta charset='utf-8'><title>{escape(title)}</title>",
        f"<style>{_STYLE}</style></head><body>",
        f"<h1>{escape(title)}</h1><p class='what'>{who}{'. ' if who else ''}pianobot's report: "
        "every figure, the piano roll and every note; docs/metrics.md says how each figure is computed.</p>",
        "<section id='figures'><h2>How well it played</h2>",
        _figures_table(report, first=True),
        f"<details><summary>every figure</summary>{_figures_table(report, first=False)}</details></section>",
    ]
    if hands is not None:
        parts.append(_hands_section(hands, reading))
    elif scores is not None and scores.hands:
        parts.append(_scores_section(scores))
    if video is not None or audio is not None:
        parts += [
            "<section id='media'><h2>Watch and listen</h2>",
            "<p class='what'>The simulation as it played, with the sound of the notes the keys sounded.</p>",
            _media(video, "video", "video/mp4"),
            _media(audio, "audio", "audio/wav"),
            "</section>",
        ]
    parts += [
        "<section id='roll'><h2>The score against what was played</h2>",
        "<p class='what'>Outlines: the score's notes (red: missed). Filled: the notes played, coloured by the "
        "finger that struck them, darker when louder (red edge: not in the score). Behind them: who played "
        "each stretch.</p>",
        roll_svg(report, stretches),
        "</section>",
        "<section id='errors'><h2>Loudness and timing, note by note</h2>",
        "<p class='what'>For each note played on time: how much louder (+) or softer (-) than the score, in "
        "MIDI velocity, and how many milliseconds late (+) or early (-) it started.</p>",
        errors_svg(report),
        "</section>",
    ]
    if stretches:
        parts += [
            "<section id='phrases'><h2>Who played each phrase</h2>",
            "<p class='what'>A phrase's own trained policy, the general policy (one policy for any melody), "
            "or the scripted pianist, in the order they played.</p>",
            _phrases_table(stretches),
            "</section>",
        ]
    parts += [
        "<section id='notes'><h2>Every note</h2>",
        "<p class='what'>Each score note beside the played note matched to it (onsets within the onset "
        "tolerance, same pitch); a missed note has no played note, an extra one no score note.</p>",
        _notes_table(report, stretches, phrase_of),
        "</section></body></html>",
    ]
    return "\n".join(parts) + "\n"


def write_html(path: Path, report: Report, title: str, **given) -> Path:
    """:func:`html_report` written to ``path`` (atomically)."""
    from pianobot.files import atomic_write

    atomic_write(path, html_report(report, title, **given))
    return path
