"""The report: Markdown tables (mean ± standard deviation over seeds), the plots, the training
time so far; and ``--list``'s table of runs and the CPU-hours they need."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.paper.evaluation import baseline_figures, check_episodes
from benchmarks.paper.experiments import SETTINGS, Experiment, Options, run_minutes
from benchmarks.paper.records import (
    RunProgress,
    progress,
    read_records,
    records_path,
    short_steps,
    with_records,
    write_records,
)
from benchmarks.paper.runs import Run
from pianobot.agent.config import SACConfig
from pianobot.config import to_dict
from pianobot.learn.config import TrainConfig


def mean_std(values: list[float], digits: int = 2) -> str:
    """Mean ± standard deviation (NumPy's, over the values given: 0 for one value)."""
    values = [v for v in values if v is not None]
    if not values:
        return "—"
    return f"{np.mean(values):.{digits}f} ± {np.std(values):.{digits}f}"


def table(experiment: Experiment, found: list[RunProgress], baselines: dict | None = None) -> str:
    """A Markdown table: one row per setting, task and variant, mean ± standard deviation over seeds."""
    fingering = experiment.fingering
    head = "| setting | task | variant | seeds judged / finished / started / planned | steps (mean) | linear return | note F1 | velocity MAE"
    head += " | fingering accuracy |" if fingering else " |"
    head += " latest training evaluation: note F1 |"
    lines = [head, "| " + " | ".join(["---"] * (head.count("|") - 1)) + " |"]
    groups: dict[tuple, list[RunProgress]] = {}
    for p in found:
        groups.setdefault(p.run.group, []).append(p)
    for (setting, task, variant), members in groups.items():
        judged = [p.figures for p in members if p.figures is not None]
        started = [p for p in members if p.state != "not started"]
        finished = [p for p in members if p.state == "finished"]
        latest = [np.mean([c[-1]["f1"] for c in p.curves if c]) for p in started if any(p.curves)]
        cells = [
            setting,
            task,
            variant,
            f"{len(judged)} / {len(finished)} / {len(started)} / {len(members)}",
            short_steps(np.mean([p.steps for p in started])) if started else "—",
            mean_std([f["return"] for f in judged]),
            mean_std([f["f1"] for f in judged], 3),
            mean_std([f["velocity_mae"] for f in judged], 1),
        ]
        if fingering:
            cells.append(mean_std([f["fingering_accuracy"] for f in judged], 3))
        cells.append(mean_std(latest, 3))
        lines.append("| " + " | ".join(cells) + " |")
    for (task, controller), figures in (baselines or {}).items():
        cells = ["—", task, f"{controller} controller", f"{len(figures)} / — / — / —", "—"]
        cells += [mean_std([f["return"] for f in figures]), mean_std([f["f1"] for f in figures], 3)]
        cells += [mean_std([f["velocity_mae"] for f in figures], 1)]
        cells += [mean_std([f["fingering_accuracy"] for f in figures], 3)] if fingering else []
        cells.append("—")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def by_seed(found: list[RunProgress]) -> str:
    """Each row's judged note F1 seed by seed (the figures behind the table's mean ± std)."""
    groups: dict[tuple, list[RunProgress]] = {}
    for p in found:
        if p.figures is not None:
            groups.setdefault(p.run.group, []).append(p)
    return "\n".join(
        f"- {' '.join(group)}: " + ", ".join(f"seed {p.run.seed} {p.figures['f1']:.3f}{_so_far(p)}" for p in members)
        for group, members in groups.items()
    )


def _so_far(p: RunProgress) -> str:
    return f" (so far: best at {p.figures['kept_steps'][0]} steps)" if p.figures.get("so_far") else ""


def report(experiment: Experiment, runs: list[Run], options: Options, plots: Path | None, check: bool) -> str:
    """The tables (and plot) of an experiment from its runs so far, in the store or in the
    records beside the plot (which it then updates); trains nothing."""
    found = [progress(run, options, check) for run in runs]
    if plots is not None:
        records = read_records(records_path(experiment, plots))
        found = with_records(found, records, options, check)
        write_records(records_path(experiment, plots), records, found, options)
    baselines = {}
    for task in options.tasks or experiment.tasks:
        for controller in experiment.baselines:
            baselines[task, controller] = [
                baseline_figures(controller, task, seed, options) for seed in range(options.seeds)
            ]
    text = (
        f"{experiment.number}. {experiment.title}: judged with the linear reward on "
        f"{check_episodes(runs[0], options) if runs else 0} "
        f"{'hand starts of the piece' if experiment.name == 'compose' else 'fresh task instances'}; "
        "mean ± standard deviation over seeds\n\n" + table(experiment, found, baselines)
    )
    seeds = by_seed(found)
    if seeds:
        text += "\n\nnote F1 by seed:\n" + seeds
    hours, policies = training_hours(found)
    text += (
        f"\n\ntraining so far: {hours:.1f} CPU-hours, {policies} polic{'y' if policies == 1 else 'ies'} (each on one core; "
        "a policy that several experiments share counts in each)"
    )
    recorded = [p for p in found if p.recorded]
    if recorded:
        text += (
            f"\n\nfrom the records ({records_path(experiment, plots)}), not in the store "
            f"{options.store}: {len(recorded)} run{'s' if len(recorded) > 1 else ''}"
        )
    unfinished = [p for p in found if p.state.startswith("at ")]
    if unfinished:
        text += "\n\nunfinished: " + ", ".join(f"{p.run.label} ({p.state})" for p in unfinished)
        if check:
            text += "\n(their rows' judged figures include their best policies so far)"
    if plots is not None and any(p.curves for p in found):
        text += f"\n\nplot: {plot(experiment, found, baselines, plots)}"
    return text


def training_hours(found: list[RunProgress]) -> tuple[float, int]:
    """The training time so far of the runs' distinct policies, in hours (the manifests' seconds,
    or the newest checkpoint's for an unfinished policy), and how many have begun."""
    seconds: dict[str, float] = {}
    for p in found:
        for folder, spent in p.seconds.items():  # a policy two runs share counts once
            seconds[folder] = max(spent, seconds.get(folder, 0.0))
    return sum(seconds.values()) / 3600, len(seconds)


def _binned(curves: list[list[dict]], key: str, every: int) -> tuple[list[int], list[float], list[float]]:
    """Mean and standard deviation over runs at each evaluation (steps rounded to ``every``)."""
    at: dict[int, list[float]] = {}
    for curve in curves:
        for point in curve:
            if point.get(key) is not None:
                at.setdefault(round(point["step"] / every) * every, []).append(point[key])
    steps = sorted(at)
    return steps, [float(np.mean(at[s])) for s in steps], [float(np.std(at[s])) for s in steps]


def plot(experiment: Experiment, found: list[RunProgress], baselines: dict, folder: Path) -> Path:
    """Return and note F1 against environment steps (``compose``: against the piece's length),
    one row per setting, mean and one standard deviation over seeds; a colour per task (per
    variant when there is one task), a line style per variant; the baselines as level lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    settings = [s for s in SETTINGS if any(p.run.setting == s and p.curves for p in found)]  # a row per setting run
    fig, axes = plt.subplots(len(settings), 2, figsize=(11, 3.6 * len(settings)), squeeze=False)
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    tasks = list(dict.fromkeys(p.run.task for p in found))
    variants = list(dict.fromkeys(p.run.variant for p in found))
    by_task = len(tasks) > 1 and experiment.name != "compose"

    def style(task: str, variant: str) -> dict:
        if by_task:
            return dict(
                color=cycle[tasks.index(task) % len(cycle)],
                linestyle=("-", "--", "-.", ":")[variants.index(variant) % 4],
            )
        return dict(color=cycle[variants.index(variant) % len(cycle)], linestyle="-")

    for row, setting in zip(axes, settings):
        mine = [p for p in found if p.run.setting == setting]
        if experiment.name == "compose":
            _plot_lengths(row, mine, style)
        else:
            _plot_curves(row, mine, style)
        for (task, controller), figures in baselines.items():
            look = {"scripted": ":", "idle": (0, (1, 4)), "random": "-."}[controller]
            level = dict(color=style(task, variants[0])["color"], linestyle=look)
            row[1].axhline(np.mean([f["f1"] for f in figures]), linewidth=1, **level, label=f"{task}, {controller}")
            if setting == "paper":  # its training reward is the linear one (gated: the baselines' fingers pass)
                row[0].axhline(np.mean([f["return"] for f in figures]), linewidth=1, **level)
        row[0].set_title(f"{setting} setting: return")
        row[1].set_title(f"{setting} setting: note F1")
        row[1].set_ylim(-0.02, 1.02)
        for ax in row:
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
    fig.suptitle(f"{experiment.number}. {experiment.title}")
    fig.tight_layout()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{experiment.number}-{experiment.name}.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _plot_curves(row, found: list[RunProgress], style) -> None:
    groups: dict[tuple, list[RunProgress]] = {}
    for p in found:
        groups.setdefault(p.run.group, []).append(p)
    for (_, task, variant), members in groups.items():
        curves = [c for p in members for c in p.curves if c]
        if not curves:
            continue
        every = members[0].run.config.eval_every
        look = style(task, variant)
        for ax, key in zip(row, ("return", "f1")):
            steps, mean, std = _binned(curves, key, every)
            label = f"{task}, {variant}, n={len(curves)}" if key == "return" else None
            ax.plot(steps, mean, marker=".", label=label, **look)
            ax.fill_between(steps, np.subtract(mean, std), np.add(mean, std), color=look["color"], alpha=0.15)
            ax.set_xlabel("environment steps")
    row[0].set_ylabel("evaluation return\n(in the reward trained with)")
    row[1].set_ylabel("evaluation note F1")


def _plot_lengths(row, found: list[RunProgress], style) -> None:
    for variant in ("compositional", "end-to-end"):
        by_length: dict[int, list[dict]] = {}
        for p in found:
            if p.run.variant == variant and p.figures is not None:
                by_length.setdefault(len(p.run.piece), []).append(p.figures)
        lengths = sorted(by_length)
        for ax, key in zip(row, ("return", "f1")):
            values = [[f[key] for f in by_length[n]] for n in lengths]
            ax.errorbar(
                lengths,
                [np.mean(v) for v in values],
                yerr=[np.std(v) for v in values],
                marker="o",
                capsize=3,
                label=variant if key == "return" else None,
                **style("", variant),
            )
            ax.set_xlabel("notes in the piece")
    row[0].set_ylabel("linear return, whole piece")
    row[1].set_ylabel("note F1, whole piece")


# -- listing ------------------------------------------------------------------------------------
def _flat(data: dict, prefix: str = "") -> dict:
    out = {}
    for key, value in data.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def differences(config: TrainConfig, than: TrainConfig) -> dict:
    """The fields (dotted paths) where ``config`` differs from ``than``."""
    mine, theirs = _flat(to_dict(config)), _flat(to_dict(than))
    return {k: v for k, v in mine.items() if theirs.get(k) != v}


def listing(experiment: Experiment, runs: list[Run]) -> str:
    """Every run, what it changes from pianobot's defaults, and the CPU-hours the training needs."""
    lines = ["| setting | task | variant | seed | steps | policies | differs from pianobot's defaults |"]
    lines.append("| --- | --- | --- | ---: | ---: | ---: | --- |")
    for run in runs:
        base = TrainConfig(
            steps=run.config.steps,
            seed=run.seed,
            eval_every=run.config.eval_every,
            eval_episodes=run.config.eval_episodes,
            checkpoint_every=run.config.checkpoint_every,
            sac=SACConfig(exploration_steps=run.config.sac.exploration_steps),
        )
        changed = ", ".join(f"{k}={v}" for k, v in differences(run.config, base).items()) or "—"
        lines.append(
            f"| {run.setting} | {run.task} | {run.variant} | {run.seed} | {run.config.steps} | {len(run.jobs)} | {changed} |"
        )
    hours, policies = estimate(runs)
    lines.append(
        f"\n{len(runs)} runs, {policies} policies to train (equal configurations once): about {hours:.0f} CPU-hours "
        "of training, estimated from docs/benchmarks.md's 4 minutes per 15k exploration steps and 10 minutes per "
        "further 10k learning steps (tactile images, one core); evaluations not counted"
    )
    return "\n".join(lines)


def estimate(runs: list[Run]) -> tuple[float, int]:
    """Estimated CPU-hours to train every distinct policy of ``runs``, and how many there are."""
    policies = {}
    for run in runs:
        for job in run.jobs:
            policies[job.folder] = run_minutes(run.config.steps, run.config.sac.exploration_steps)
    return sum(policies.values()) / 60, len(policies)
