"""How well a performance matches its reference: pure functions of two pieces.

Note-level figures come from mir_eval's transcription metrics (notes match one-to-one when the
pitch agrees and the onsets are within the tolerance); velocity and onset errors are measured
over those matched pairs in plain MIDI units and seconds. The per-step key-press F1 is
RoboPianist's: at each control step compare the set of keys that should be down with the set
that is down (an empty step scores 1), then average over steps. Articulation is the played/written
duration ratio of matched notes, its median per note-length class (:data:`LENGTH_CLASSES`).
See docs/metrics.md.
"""

from __future__ import annotations

import io
import math
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from pianobot.files import atomic_write
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Note, Piece
from pianobot.music.tensor import ScoreSpec, note_steps

DEFAULT_ONSET_TOLERANCE = 0.05
"""Seconds; mir_eval's and the MIREX standard."""
LENGTH_CLASSES = (("short", 0.0, 0.35), ("medium", 0.35, 0.7), ("long", 0.7, float("inf")))
"""Note-length classes for the duration ratio: (name, shortest, longest) written duration in
seconds, shortest included (eighth notes at 90 bpm are short, quarters medium, halves long)."""


@dataclass(frozen=True)
class NoteRow:
    """One line of the per-note table: a reference note and what was played for it."""

    reference: Note | None
    """None for a played note that the reference does not have (an extra note)."""
    played: Note | None
    """None for a reference note that was not played (a missed note)."""

    @property
    def velocity_error(self) -> int | None:
        if self.reference is None or self.played is None:
            return None
        return self.played.velocity - self.reference.velocity

    @property
    def onset_error(self) -> float | None:
        if self.reference is None or self.played is None:
            return None
        return round(self.played.onset - self.reference.onset, 6)


@dataclass(frozen=True)
class Report:
    """Every figure `pianobot score` shows."""

    reference_notes: int
    played_notes: int
    matched_notes: int
    precision: float
    recall: float
    f1: float
    f1_with_offsets: float
    velocity_f1: float
    velocity_mae: float | None
    velocity_max_error: int | None
    onset_error_mean: float | None
    onset_error_max: float | None
    step_precision: float
    step_recall: float
    step_f1: float
    duration_ratio_short: float | None
    """Median played/written duration of the matched notes written shorter than 0.35 s (None: there are none)."""
    duration_ratio_medium: float | None
    """The same for notes of 0.35-0.7 s."""
    duration_ratio_long: float | None
    """The same for notes of 0.7 s or longer."""
    fingering_accuracy: float | None
    onset_tolerance: float
    rows: tuple[NoteRow, ...]
    sounding_f1_with_offsets: float | None = None
    """Note F1 with offsets on sounding durations: each file's own sustain pedal applied to its notes
    (:meth:`~pianobot.music.pedal.Pedal.sounding`); None where neither uses the pedal."""
    pedal_f1: float | None = None
    """Presses and releases of the pedal matched one to one within the onset tolerance (:func:`pedal_f1`);
    None where neither uses the pedal."""
    pedal_error_mean: float | None = None
    """Mean timing error (s) of the matched presses and releases; None where none matched."""

    def summary(self) -> dict:
        """The summary figures (everything but the per-note rows)."""
        out = asdict(self)
        del out["rows"]
        return out

    def to_dict(self) -> dict:
        """Summary plus per-note rows, as plain JSON-ready data."""
        out = self.summary()
        out["notes"] = [
            {
                "pitch": (row.reference or row.played).name,
                "target_onset": row.reference.onset if row.reference else None,
                "played_onset": row.played.onset if row.played else None,
                "onset_error": row.onset_error,
                "target_velocity": row.reference.velocity if row.reference else None,
                "played_velocity": row.played.velocity if row.played else None,
                "velocity_error": row.velocity_error,
                "target_finger": row.reference.finger if row.reference else None,
                "played_finger": row.played.finger if row.played else None,
                "status": "missed" if row.played is None else "extra" if row.reference is None else "matched",
            }
            for row in self.rows
        ]
        return out


def _mir_eval():
    """mir_eval's ``util``, ``transcription`` and ``transcription_velocity`` modules, the ones the
    figures use. mir_eval's package imports every module it has, scipy.stats among them (about
    2 s); where it has not been imported yet, these three are imported under a stand-in for the
    package, which is then taken away, so that a later ``import mir_eval`` imports the package
    whole and finds these modules already there."""
    import sys

    if "mir_eval.transcription_velocity" not in sys.modules and "mir_eval" not in sys.modules:
        import importlib.util
        import types

        spec = importlib.util.find_spec("mir_eval")
        if spec is None:
            raise ModuleNotFoundError("No module named 'mir_eval'", name="mir_eval")
        stand_in = types.ModuleType("mir_eval")
        stand_in.__path__ = list(spec.submodule_search_locations)
        sys.modules["mir_eval"] = stand_in
        try:
            import mir_eval.transcription_velocity  # noqa: F401  (and util, transcription)
        finally:
            if sys.modules.get("mir_eval") is stand_in:
                del sys.modules["mir_eval"]
    return (
        sys.modules["mir_eval.util"],
        sys.modules["mir_eval.transcription"],
        sys.modules["mir_eval.transcription_velocity"],
    )


def _arrays(piece: Piece) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    intervals = np.array([[n.onset, n.offset] for n in piece.notes], dtype=float).reshape(-1, 2)
    util, _, _ = _mir_eval()

    pitches = util.midi_to_hz(np.array([n.pitch for n in piece.notes], dtype=float))
    velocities = np.array([n.velocity for n in piece.notes], dtype=float)
    return intervals, pitches, velocities


def key_press_f1(
    reference: Piece, played: Piece, control_hz: float = ScoreSpec.control_hz
) -> tuple[float, float, float]:
    """RoboPianist's per-step key-press precision, recall and F1, averaged over control steps."""
    spec = ScoreSpec(control_hz=control_hz)
    spans = {"ref": note_steps(reference, spec), "out": note_steps(played, spec)}
    steps = max((e for s in spans.values() for _, _, e in s), default=0)
    if steps == 0:
        return 1.0, 1.0, 1.0
    rolls = {}
    for name, notes in spans.items():
        roll = np.zeros((steps, 128), dtype=bool)
        for note, start, end in notes:
            roll[start:end, note.pitch] = True
        rolls[name] = roll
    tp = (rolls["ref"] & rolls["out"]).sum(axis=1)
    fp = (~rolls["ref"] & rolls["out"]).sum(axis=1)
    fn = (rolls["ref"] & ~rolls["out"]).sum(axis=1)
    precision = np.where(tp + fp > 0, tp / np.maximum(tp + fp, 1), 1.0)
    recall = np.where(tp + fn > 0, tp / np.maximum(tp + fn, 1), 1.0)
    f1 = np.where(tp + fp + fn > 0, 2 * tp / np.maximum(2 * tp + fp + fn, 1), 1.0)
    return float(precision.mean()), float(recall.mean()), float(f1.mean())


def length_class(note: Note) -> str:
    """The name of ``note``'s class in :data:`LENGTH_CLASSES` (by its written duration)."""
    return next(name for name, low, high in LENGTH_CLASSES if low <= note.duration < high)


def duration_ratios(rows: tuple[NoteRow, ...] | list[NoteRow]) -> dict[str, list[float]]:
    """Played/written duration of every matched note, by the written note's length class (in
    :data:`LENGTH_CLASSES` order): pool several pieces' rows to take one median over a set."""
    out: dict[str, list[float]] = {name: [] for name, _, _ in LENGTH_CLASSES}
    for row in rows:
        if row.reference is not None and row.played is not None:
            out[length_class(row.reference)].append(row.played.duration / row.reference.duration)
    return out


def compare(
    reference: Piece,
    played: Piece,
    onset_tolerance: float = DEFAULT_ONSET_TOLERANCE,
    control_hz: float = ScoreSpec.control_hz,
    pedals: tuple[Pedal, Pedal] | None = None,
) -> Report:
    """Score ``played`` against ``reference``; with ``pedals`` (the reference's sustain pedal, the
    performance's), where either is pressed, also the pedal's figures."""
    ref_int, ref_hz, ref_vel = _arrays(reference)
    out_int, out_hz, out_vel = _arrays(played)
    pairs = match_notes(ref_int, ref_hz, out_int, out_hz, onset_tolerance)
    precision, recall, f1 = _f1(len(pairs), len(reference), len(played))
    f1_offsets = _f1(
        len(match_notes(ref_int, ref_hz, out_int, out_hz, onset_tolerance, OFFSET_RATIO)), len(reference), len(played)
    )[2]
    velocity_f1 = _f1(_velocity_matches(pairs, ref_vel, out_vel), len(reference), len(played))[2]

    matched = {r: p for r, p in pairs}
    rows = [NoteRow(n, played.notes[matched[i]] if i in matched else None) for i, n in enumerate(reference.notes)]
    used = set(matched.values())
    rows += [NoteRow(None, n) for j, n in enumerate(played.notes) if j not in used]
    rows.sort(key=lambda r: ((r.reference or r.played).onset, (r.reference or r.played).pitch))

    pairs_rows = [r for r in rows if r.reference is not None and r.played is not None]
    velocity_errors = [abs(r.velocity_error) for r in pairs_rows]
    onset_errors = [abs(r.onset_error) for r in pairs_rows]
    fingered = [r for r in pairs_rows if r.reference.finger is not None and r.played.finger is not None]
    step_p, step_r, step_f1 = key_press_f1(reference, played, control_hz)
    ratios = {name: float(np.median(r)) if r else None for name, r in duration_ratios(pairs_rows).items()}
    return Report(
        reference_notes=len(reference),
        played_notes=len(played),
        matched_notes=len(pairs_rows),
        precision=float(precision),
        recall=float(recall),
        f1=float(f1),
        f1_with_offsets=float(f1_offsets),
        velocity_f1=float(velocity_f1),
        velocity_mae=float(np.mean(velocity_errors)) if velocity_errors else None,
        velocity_max_error=int(max(velocity_errors)) if velocity_errors else None,
        onset_error_mean=round(float(np.mean(onset_errors)), 6) if onset_errors else None,
        onset_error_max=round(float(max(onset_errors)), 6) if onset_errors else None,
        step_precision=step_p,
        step_recall=step_r,
        step_f1=step_f1,
        duration_ratio_short=ratios["short"],
        duration_ratio_medium=ratios["medium"],
        duration_ratio_long=ratios["long"],
        fingering_accuracy=(
            sum(r.reference.finger == r.played.finger for r in fingered) / len(fingered) if fingered else None
        ),
        onset_tolerance=onset_tolerance,
        rows=tuple(rows),
        **_pedal_figures(reference, played, pedals, onset_tolerance),
    )


OFFSET_RATIO = 0.2
"""A note's offset matches within this share of the reference note's length (at least 50 ms):
mir_eval's default, the MIREX standard."""
VELOCITY_TOLERANCE = 0.1
"""mir_eval's: a matched note's velocity, rescaled to the reference's (least squares over the matched
notes), is within this share of the reference's velocity range."""
_BLOCK_GAP = 1e-3
"""Onsets this much farther apart than the tolerance never match (mir_eval rounds onset distances to 1e-4 s)."""


def _blocks(ref: np.ndarray, out: np.ndarray, tolerance: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Indices into ``ref`` and ``out`` (times, s) in groups that no match within ``tolerance`` joins:
    all the times sorted together, split wherever two neighbours lie farther apart; groups of both."""
    times = np.concatenate([ref, out])
    order = np.argsort(times, kind="stable")
    groups = np.split(order, np.flatnonzero(np.diff(times[order]) > tolerance + _BLOCK_GAP) + 1)
    found = [(np.sort(g[g < len(ref)]), np.sort(g[g >= len(ref)] - len(ref))) for g in groups]  # (in index order)
    return [(r, o) for r, o in found if len(r) and len(o)]


def match_notes(
    ref_int: np.ndarray,
    ref_hz: np.ndarray,
    out_int: np.ndarray,
    out_hz: np.ndarray,
    tolerance: float,
    offset_ratio=None,
) -> list[tuple[int, int]]:
    """mir_eval's one-to-one note matching (``transcription.match_notes``: the same pitch, onsets within
    ``tolerance``; with ``offset_ratio``, offsets too), as (reference, played) index pairs. Notes of
    one pitch whose onsets lie farther apart than the tolerance never match, so mir_eval matches
    each group of them alone: it compares every pair it is given, and a whole hour's notes at once
    took gigabytes; this way memory follows the largest group, not the piece's length squared."""
    _, transcription, _ = _mir_eval()
    pairs: list[tuple[int, int]] = []
    for hz in np.intersect1d(ref_hz, out_hz):  # (pitches from MIDI numbers: one frequency each)
        ref_i, out_i = np.flatnonzero(ref_hz == hz), np.flatnonzero(out_hz == hz)
        for r, o in _blocks(ref_int[ref_i, 0], out_int[out_i, 0], tolerance):
            r, o = ref_i[r], out_i[o]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = transcription.match_notes(
                    ref_int[r], ref_hz[r], out_int[o], out_hz[o], onset_tolerance=tolerance, offset_ratio=offset_ratio
                )
            pairs += [(int(r[i]), int(o[j])) for i, j in found]
    return sorted(pairs)


def _f1(matched: int, references: int, played: int) -> tuple[float, float, float]:
    """Precision, recall and F1 of ``matched`` notes (0 for all three where either piece has none, as mir_eval)."""
    util, _, _ = _mir_eval()
    if not references or not played:
        return 0.0, 0.0, 0.0
    precision, recall = matched / played, matched / references
    return precision, recall, float(util.f_measure(precision, recall))


def _velocity_matches(pairs: list[tuple[int, int]], ref_vel: np.ndarray, out_vel: np.ndarray) -> int:
    """How many of the matched ``pairs`` are also as loud, as mir_eval's ``transcription_velocity``
    judges it: the reference's velocities scaled to [0, 1], the played ones fitted to them by least
    squares over the matched notes, each within :data:`VELOCITY_TOLERANCE`."""
    if not pairs:
        return 0
    low, high = ref_vel.min(), ref_vel.max()
    ref = (ref_vel - low) / float(max(1, high - low))
    index = np.array(pairs)
    target, given = ref[index[:, 0]], out_vel[index[:, 1]]
    slope, intercept = np.linalg.lstsq(np.vstack([given, np.ones(len(given))]).T, target, rcond=None)[0]
    return int((np.abs(slope * given + intercept - target) < VELOCITY_TOLERANCE).sum())


def _pedal_figures(reference: Piece, played: Piece, pedals: tuple[Pedal, Pedal] | None, tolerance: float) -> dict:
    """The Report's pedal fields (empty where neither piece uses the pedal)."""
    if pedals is None or not any(pedals):
        return {}
    ref_int, ref_hz, _ = _arrays(pedals[0].sounding(reference))
    out_int, out_hz, _ = _arrays(pedals[1].sounding(played))
    matched = len(match_notes(ref_int, ref_hz, out_int, out_hz, tolerance, OFFSET_RATIO))
    sounding = _f1(matched, len(ref_int), len(out_int))[2]
    f1, error = pedal_f1(*pedals, tolerance)
    return {
        "sounding_f1_with_offsets": float(sounding),
        "pedal_f1": f1,
        "pedal_error_mean": None if math.isnan(error) else round(error, 6),
    }


def plot_report(reference: Piece, played: Piece, report: Report, path) -> None:
    """Both piano rolls, reference above and performance below, with misses, extras and velocity errors marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch, Rectangle

    fig, axes = plt.subplots(2, 1, sharex=True, sharey=True, figsize=(10, 6))
    pitches = [n.pitch for n in reference.notes + played.notes] or [60]
    end = max(reference.duration, played.duration, 0.1)
    colours = {"matched": "#4c72b0", "missed": "#d62728", "extra": "#d62728"}
    for ax, title in zip(axes, ("reference", "performance")):
        ax.set_title(title, loc="left")
        ax.set_ylabel("MIDI pitch")
        ax.set_xlim(0, end * 1.02)
        ax.set_ylim(min(pitches) - 1.5, max(pitches) + 1.5)
        ax.grid(alpha=0.3)
    for row in report.rows:
        status = "missed" if row.played is None else "extra" if row.reference is None else "matched"
        for ax, note in zip(axes, (row.reference, row.played)):
            if note is None:
                continue
            alpha = 0.3 + 0.7 * note.velocity / 127
            ax.add_patch(
                Rectangle((note.onset, note.pitch - 0.4), note.duration, 0.8, color=colours[status], alpha=alpha)
            )
        if status == "matched" and row.velocity_error:
            axes[1].annotate(
                f"{row.velocity_error:+d}", (row.played.onset, row.played.pitch + 0.5), fontsize=7, color="#d62728"
            )
    axes[1].set_xlabel("time (s)")
    axes[0].legend(
        handles=[
            Patch(color=colours["matched"], label="matched (shade = velocity)"),
            Patch(color=colours["missed"], label="missed / extra"),
        ],
        loc="upper right",
        fontsize=8,
    )
    mae = "n/a" if report.velocity_mae is None else f"{report.velocity_mae:.1f}"
    fig.suptitle(f"note F1 {report.f1:.3f}   velocity MAE {mae}")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    atomic_write(path, buffer.getvalue())


def pedal_f1(reference: Pedal, played: Pedal, tolerance: float = DEFAULT_ONSET_TOLERANCE) -> tuple[float, float]:
    """How closely ``played`` works the pedal as ``reference`` does: F1 of its presses and releases
    matched one to one with the reference's of the same kind within ``tolerance`` seconds
    (mir_eval's event matching), and the mean timing error (s) of the matched ones (nan where none is
    matched). Both without pedal: 1.0, nan."""
    util, _, _ = _mir_eval()
    if not reference and not played:
        return 1.0, math.nan
    hits, errors = 0, []
    for kind in (True, False):
        ref = np.array([t for t, down in reference.changes() if down is kind])
        out = np.array([t for t, down in played.changes() if down is kind])
        for r, o in _blocks(ref, out, tolerance):  # (each group alone, as the notes)
            for i, j in util.match_events(ref[r], out[o], tolerance):
                hits += 1
                errors.append(abs(ref[r][i] - out[o][j]))
    changes = 2 * (len(reference) + len(played))
    return 2 * hits / changes, float(np.mean(errors)) if errors else math.nan
