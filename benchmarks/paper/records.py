"""What each run has so far (from the store), and the records: what the reports saw, kept
beside the plot (docs/paper/N-name.json) so that a report without the store still tables them."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from benchmarks.paper.evaluation import best_so_far, check_episodes, evaluate_run, has_evaluation, read_json
from benchmarks.paper.experiments import Experiment, Options
from benchmarks.paper.runs import Run
from pianobot.agent import store
from pianobot.errors import PianobotError
from pianobot.files import atomic_write


def short_steps(steps: float) -> str:
    return f"{steps / 1000:.0f}k" if steps >= 10_000 else f"{steps:.0f}"


@dataclass
class RunProgress:
    """What one run has so far."""

    run: Run
    state: str
    """'not started', 'at N steps', 'finished'."""
    steps: int = 0
    curves: list[list[dict]] = field(default_factory=list)
    """Each policy's training evaluations (step, f1, return in the training reward)."""
    figures: dict | None = None
    """The linear-reward evaluation (finished runs; unfinished ones with --check)."""
    seconds: dict[str, float] = field(default_factory=dict)
    """Each policy's training time so far, by its model folder (relative to the store)."""
    recorded: bool = False
    """Read from the experiment's records (:func:`records_path`), not from the store."""


def progress(run: Run, options: Options, check: bool = False) -> RunProgress:
    curves, steps, seconds, started, finished = [], 0, {}, False, True
    for job in run.jobs:
        name = job.folder.relative_to(options.store).as_posix()
        if store.is_trained(job.folder):
            manifest = store.read_manifest(job.folder)
            curves.append(manifest["evaluations"])
            steps += manifest["steps"]
            seconds[name] = manifest["seconds"]
            started = True
            continue
        finished = False
        state = store.checkpoint_state(job.folder)
        if state is not None:
            curves.append(state["evaluations"])
            steps += state["step"]
            seconds[name] = state.get("seconds", 0.0)
            started = True
    if finished:  # judged now if the training command was cut off before it judged the run
        figures = read_json(run.result) if has_evaluation(run, options) else evaluate_run(run, options)
        return RunProgress(run, "finished", steps, curves, figures, seconds)
    if not started:
        return RunProgress(run, "not started")
    figures = best_so_far(run, options) if check else None
    return RunProgress(run, f"at {short_steps(steps)} steps", steps, curves, figures, seconds)


# -- records: what the report saw, kept beside its plot -------------------------------------------
def records_path(experiment: Experiment, plots: Path) -> Path:
    """``N-name.json`` beside the plot: every run the experiment's reports have seen (its state,
    steps, training time, training evaluations and judged figures), so that a report on another
    machine, or after the store is gone, still tables and plots them. Checkpoints and policies
    stay in the store: a recorded run can be reported, not resumed or judged again."""
    return plots / f"{experiment.number}-{experiment.name}.json"


def record_key(run: Run, options: Options) -> str:
    """A run's name in the records: where its evaluation goes, relative to the store (the name
    holds the configuration's hash, and for ``compose`` the piece's, so another configuration or
    piece is another run)."""
    return run.result.relative_to(options.store).as_posix()


RECORD_FIELDS = ("label", "state", "steps", "seconds", "curves", "figures")


def read_records(path: Path) -> dict[str, dict]:
    """The records in ``path`` (none if it does not exist). A file that is there but cannot be
    read stops the report, which would otherwise write the store's runs over it."""
    if not path.exists():
        return {}
    try:
        runs = json.loads(path.read_text())["runs"]
        if not all(set(RECORD_FIELDS) <= record.keys() for record in runs.values()):
            raise ValueError
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        raise PianobotError(
            f"{path} is not a records file this report can read (a merge conflict?): "
            "mend it from git, or move it away to start new records"
        ) from None
    return runs


def _rank(state: str, steps: int, figures: dict | None) -> tuple:
    """How far along a run is: finished first, then more steps, then judged on more episodes."""
    return state == "finished", steps, (figures or {}).get("episodes", 0)


def with_records(
    found: list[RunProgress], records: dict[str, dict], options: Options, check: bool
) -> list[RunProgress]:
    """The runs the store lacks, as the records have them (the store's own are its). A recorded
    judgement counts only if it was judged as this report judges (the same number of episodes)
    and, for an unfinished run's best policy so far, only with ``--check``."""
    out = []
    for p in found:
        kept = records.get(record_key(p.run, options))
        if p.state == "not started" and kept is not None:
            figures = kept["figures"]
            if figures is not None and (
                figures.get("episodes") != check_episodes(p.run, options) or (figures.get("so_far") and not check)
            ):
                figures = None
            p = RunProgress(
                p.run, kept["state"], kept["steps"], kept["curves"], figures, kept["seconds"], recorded=True
            )
        out.append(p)
    return out


def write_records(path: Path, records: dict[str, dict], found: list[RunProgress], options: Options) -> None:
    """The records updated with the runs this report read from the store, where the store has
    the run at least as far along as the record (a run started afresh, or judged on fewer
    episodes, does not replace what was recorded); the other records kept."""
    for p in found:
        if p.recorded or p.state == "not started":
            continue
        key = record_key(p.run, options)
        kept = records.get(key)
        if kept is not None and _rank(p.state, p.steps, p.figures) < _rank(
            kept["state"], kept["steps"], kept["figures"]
        ):
            continue
        records[key] = {
            "label": p.run.label,
            "state": p.state,
            "steps": p.steps,
            "seconds": p.seconds,
            "curves": p.curves,
            "figures": p.figures,
        }
    if not records:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, json.dumps({"runs": records}, indent=1, sort_keys=True) + "\n")
