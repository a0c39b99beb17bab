"""Rich tables for the terminal: what `inspect` and `score` print."""

from __future__ import annotations

from rich.console import Console
from rich.table import Table

from pianobot.music.metrics import Report
from pianobot.music.midi_io import TrackInfo
from pianobot.music.phrases import Phrase
from pianobot.music.piece import FINGER_NAMES, Piece, pitch_name


def _finger(finger: int | None) -> str:
    return "-" if finger is None else f"{finger} {FINGER_NAMES[finger]}"


def _opt(value, fmt: str) -> str:
    return "n/a" if value is None else format(value, fmt)


def tracks_table(tracks: list[TrackInfo], hands: dict[int, str] | None = None) -> Table:
    """The file's tracks; ``hands`` names the hand a track's name says it holds."""
    table = Table(title="tracks")
    for column in ("track", "name", "notes", "range", "channels", "pedal", "hand"):
        table.add_column(column)
    for t in tracks:
        span = f"{pitch_name(t.low)}-{pitch_name(t.high)}" if t.notes else "-"
        table.add_row(
            str(t.index),
            t.name or "-",
            str(t.notes),
            span,
            ",".join(map(str, t.channels)) or "-",
            str(t.pedal) if t.pedal else "-",
            (hands or {}).get(t.index, "-"),
        )
    return table


ROWS = 100
"""Rows a table shows by default: a long piece's tables would take longer to draw than to compute."""


def _shown(table: Table, total: int, rows: int | None, what: str, more: str = "--all shows every one") -> int:
    """How many of ``total`` rows to show; says in the caption when some are left out, and ``more``."""
    if rows is None or total <= rows:
        return total
    table.caption = f"the first {rows} of {total} {what}; {more}"
    return rows


def notes_table(piece: Piece, phrases: list[Phrase], rows: int | None = ROWS) -> Table:
    """The notes with their fingers and phrases, or for a two-hand piece their hands (the first
    ``rows``; None: all)."""
    phrase_of = {id(n): p.index for p in phrases for n in p.notes}
    both = len(piece.hands) == 2  # (a hand column for a two-hand piece)
    table = Table(title=f"{len(piece)} notes")
    columns = ("#", "onset s", "pitch", "duration s", "velocity", "finger") + (("hand",) if both else ("phrase",))
    for column in columns:
        table.add_column(column, justify="right" if column not in ("finger", "hand") else "left")
    shown = _shown(table, len(piece), rows, "notes")
    for i, n in enumerate(piece.notes[:shown]):
        table.add_row(
            str(i),
            f"{n.onset:.3f}",
            n.name,
            f"{n.duration:.3f}",
            str(n.velocity),
            _finger(n.finger),
            n.hand if both else str(phrase_of.get(id(n), "-")),
        )
    return table


def phrases_table(phrases: list[Phrase], players: dict[int, str] | None = None, rows: int | None = ROWS) -> Table:
    """The phrases (the first ``rows``; None: all); with ``players`` (who plays each phrase, by
    index: :func:`~pianobot.perform.compose.phrase_players`), a column saying so."""
    table = Table(title=f"{len(phrases)} phrase{'s' * (len(phrases) != 1)}")
    columns = ("phrase", "hash", "notes", "start s", "end s", "pitches") + (
        ("played by",) if players is not None else ()
    )
    for column in columns:
        table.add_column(column)
    for p in phrases[: _shown(table, len(phrases), rows, "phrases")]:
        row = [
            str(p.index),
            p.hash,
            str(len(p.notes)),
            f"{p.start:.3f}",
            f"{p.end:.3f}",
            " ".join(n.name for n in p.notes),
        ]
        if players is not None:
            who = players[p.index]
            row.append(who if who == "own policy" else f"[yellow]{who}[/yellow]")
        table.add_row(*row)
    return table


def report_tables(report: Report, every: bool = False, notes: int | None = None) -> list[Table]:
    """The figures, each with what it means: the first few (``every``: all of them); then the
    per-note table, its first ``notes`` rows (None: every row; 0: no table)."""
    from pianobot.perform.figures import figures_for
    from pianobot.perform.report import NOTE_COLUMNS, note_cells

    summary = Table(title="performance against reference")
    for column in ("figure", "value", "what it means"):
        summary.add_column(column, justify="right" if column == "value" else "left")
    for figure in figures_for(report, every):
        summary.add_row(figure.label, figure.value(report), f"[dim]{figure.meaning}[/dim]")
    if not every:
        summary.caption = "--all shows every figure; docs/metrics.md says how each is computed"
    if notes == 0:
        return [summary]
    table = Table(title="per note")
    for column in NOTE_COLUMNS:
        table.add_column(column)
    shown = _shown(table, len(report.rows), notes, "notes", "--notes N shows N")
    for row in report.rows[:shown]:
        cells = note_cells(row)
        table.add_row(*cells, style="red" if cells[-1] != "matched" else None)
    return [summary, table]


def _figures(report: Report) -> list[str]:
    """A part's first figures, for the tables of hands: notes played, note F1, key-press F1 per step."""
    extra = report.played_notes - report.matched_notes
    return [
        f"{report.matched_notes} of {report.reference_notes}, {extra} extra",
        f"{report.f1:.3f}",
        f"{report.step_f1:.3f}",
    ]


def hands_table(performance) -> Table:
    """A two-hand performance (:class:`~pianobot.perform.together.HandsPerformance`): the whole piece
    and each hand, who played it and where, and its first figures."""
    table = Table(title=performance.simulated)
    columns = ("part", "played by", "played as", "notes given", "notes played", "note F1", "key-press F1 per step")
    for column in columns:
        table.add_column(column, justify="right" if column in ("note F1", "key-press F1 per step") else "left")

    whole = performance.report()
    given = sum(len(h.part) for h in performance.hands)
    table.add_row("whole piece", performance.performer, "", f"{given} of {len(performance.piece)}", *_figures(whole))
    for h in performance.hands:
        written = len(performance.piece.part(h.hand))
        row = [f"{h.hand} hand", h.performer, h.describe(), f"{len(h.part)} of {written}"]
        table.add_row(*row, *_figures(performance.report(h.hand)))
    table.caption = (
        "notes given: what each simulated hand was given of the notes written (the rest left out or reduced)"
    )
    return table


def hands_scores_table(scores) -> Table:
    """A two-hand performance scored (:class:`~pianobot.music.per_hand.HandsReport`): the whole
    piece and each hand of the reference."""
    table = Table(title="the whole piece and each hand")
    for column in ("part", "notes played", "note F1", "key-press F1 per step", "fingering"):
        table.add_column(column, justify="left" if column in ("part", "notes played") else "right")
    for name, report in (("whole piece", scores.whole), *((f"{h} hand", r) for h, r in scores.hands.items())):
        table.add_row(name, *_figures(report), _opt(report.fingering_accuracy, ".3f"))
    return table


def print_all(console: Console, tables: list[Table]) -> None:
    for table in tables:
        console.print(table)


def training_table(rows) -> Table:
    """(job, manifest) pairs -> the summary `pianobot train` prints at the end."""
    table = Table(title="trained policies")
    columns = (
        "phrase",
        "used by",
        "from",
        "steps",
        "kept from step",
        "eval note F1",
        "velocity MAE",
        "minutes",
        "folder",
    )
    for column in columns:
        table.add_column(column, overflow="fold")  # piped output is 80 columns wide: wrap, never cut a path
    for job, manifest in rows:
        evaluation = manifest.get("evaluation", {})  # the kept (best evaluated) policy's figures
        table.add_row(
            job.key,
            ", ".join(map(str, job.phrases)),
            "general" if manifest.get("start") else "scratch",  # (fine-tuned from the general policy, or not)
            str(manifest.get("steps", "-")),
            str(evaluation.get("step", "-")),
            _opt(evaluation.get("f1"), ".3f"),
            _opt(evaluation.get("velocity_mae"), ".1f"),
            _opt(manifest.get("seconds", 0) / 60 if manifest.get("seconds") is not None else None, ".1f"),
            str(job.folder) if manifest.get("kept") != "start" else _kept_start(job),
        )
    return table


def _kept_start(job) -> str:
    """The folder column of a run that stored nothing: its start played best."""
    if not isinstance(job.target, Piece):  # a task family (or one given parts), trained on from --general-policy
        return "none: its start policy played best"
    return "none: the general policy plays it"
