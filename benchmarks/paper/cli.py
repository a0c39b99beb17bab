"""The command line: ``python -m benchmarks.paper EXPERIMENT ...`` (``--help``)."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from benchmarks.paper.experiments import ROOT, SETTINGS, Options, experiment_named
from benchmarks.paper.records import read_records, records_path
from benchmarks.paper.report import listing, report
from benchmarks.paper.runs import expand
from benchmarks.paper.training import execute
from pianobot.errors import PianobotError


def parse(argv: list[str] | None = None) -> tuple[argparse.Namespace, Options]:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.paper",
        description=importlib.import_module(__package__).__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "experiment",
        help="1-9 or tasks, rhythm-chord, rewards, exploration, control, fingering, compose, additions, diagnosis",
    )
    parser.add_argument("--setting", choices=(*SETTINGS, "both"), default="both")
    parser.add_argument("--seeds", type=int, default=Options.seeds, help="seeds 0 .. N-1 (the paper used 5)")
    parser.add_argument(
        "--steps", type=int, default=None, help="steps per run (compose: per phrase); default: the experiment's"
    )
    parser.add_argument("--exploration-steps", type=int, default=Options.exploration_steps)
    parser.add_argument("--eval-every", type=int, default=Options.eval_every)
    parser.add_argument("--eval-episodes", type=int, default=None, help="training evaluations' episodes")
    parser.add_argument("--check-episodes", type=int, default=None, help="episodes of the linear-reward judgement")
    parser.add_argument("--tasks", nargs="+", default=None, help="instead of the experiment's tasks")
    parser.add_argument("--variants", nargs="+", default=None, help="only these arms (default: all)")
    parser.add_argument("--piece", type=Path, default=Options.piece, help="compose: the piece")
    parser.add_argument(
        "--lengths", nargs="+", type=int, default=list(Options.lengths), help="compose: first N phrases"
    )
    parser.add_argument("--tempo", type=float, default=Options.tempo, help="compose: re-time the piece (bpm)")
    parser.add_argument(
        "--stop-at",
        type=int,
        default=None,
        help="train each run only to this many steps this time (it checkpoints there; rerun without it to go on); "
        "--report --check then judges each run's best policy so far",
    )
    parser.add_argument("--workers", type=int, default=1, help="runs in parallel, one torch thread each")
    parser.add_argument("--store", type=Path, default=Options.store)
    parser.add_argument(
        "--plots",
        type=Path,
        default=ROOT / "docs" / "paper",
        help="where --report draws N-name.png and keeps N-name.json, the records of every run it has seen",
    )
    parser.add_argument("--report", action="store_true", help="train nothing: tables and plots of the runs so far")
    parser.add_argument(
        "--check", action="store_true", help="with --report: judge unfinished runs' best policies so far"
    )
    parser.add_argument("--list", action="store_true", help="train nothing: the runs and the CPU-hours they need")
    args = parser.parse_args(argv)
    for name in ("seeds", "workers", "check_episodes", "eval_episodes", "steps", "stop_at"):
        if getattr(args, name) is not None and getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1")
    if args.stop_at is not None and args.stop_at % args.eval_every:
        parser.error(f"--stop-at must be a multiple of --eval-every ({args.eval_every}): runs checkpoint only there")
    options = Options(
        settings=SETTINGS if args.setting == "both" else (args.setting,),
        seeds=args.seeds,
        steps=args.steps,
        exploration_steps=args.exploration_steps,
        eval_every=args.eval_every,
        eval_episodes=args.eval_episodes,
        check_episodes=args.check_episodes,
        tasks=tuple(args.tasks) if args.tasks else None,
        variants=tuple(args.variants) if args.variants else None,
        store=args.store,
        piece=args.piece,
        lengths=tuple(args.lengths),
        tempo=args.tempo,
        stop_at=args.stop_at,
    )
    return args, options


def main(argv: list[str] | None = None) -> None:
    args, options = parse(argv)
    try:
        experiment = experiment_named(args.experiment)
        runs = expand(experiment.name, options)
        if not args.list:  # before any training: its closing report writes them
            read_records(records_path(experiment, args.plots))
    except (PianobotError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        raise SystemExit(2) from None
    if args.list:
        print(listing(experiment, runs))
    elif args.report:
        print(report(experiment, runs, options, args.plots, args.check))
    else:
        execute(runs, options, args.workers)
        print()
        print(report(experiment, runs, options, args.plots, check=False))
