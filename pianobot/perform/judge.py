"""A phrase policy that ``play`` does not trust as it is plays only where it plays better.

A phrase policy is :func:`doubted` when it was trained on another simulator than this one
(:data:`pianobot.env.VERSION`) or kept by ``pianobot train`` beside another general policy than
the one that would play in its place now. :func:`perform_judged` then plays the piece both ways,
with it and with the general policy in its place, keeps the better (note F1, then velocity
error; the phrase policy on a tie) and says which in one warning line. :func:`play_one_hand`
plans and plays a one-hand piece so, as ``pianobot play`` does.
"""

from __future__ import annotations

import contextlib
import warnings
from pathlib import Path
from typing import Callable

from pianobot.agent import store
from pianobot.agent.general import describe
from pianobot.env import VERSION
from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.piece import Piece
from pianobot.perform.plan import DEFAULT_MODELS, Performance, PerformancePlan, Player, perform_plan, plan_performance


def doubted(plan: PerformancePlan, models: Path | str | None, general: Path | None = None) -> dict[Path, str]:
    """The phrase policies of ``plan`` that ``play`` does not trust as they are, each with why: one
    trained on another simulator than this one (:data:`pianobot.env.VERSION`), or one that
    ``pianobot train`` kept beside another general policy than ``general`` (the one that would
    play in its place now)."""
    judged = store.judged(Path(models) if models is not None else DEFAULT_MODELS)
    beside = describe(general)["sha256"] if general is not None else None
    out: dict[Path, str] = {}
    for folder in dict.fromkeys(s.policy for s in plan.stretches if s.player is Player.OWN):
        trained_on = store.simulator(folder)
        if trained_on != VERSION:
            out[folder] = f"trained on simulator v{trained_on}, this is v{VERSION}"
        elif beside is not None and judged.get(folder.name, {}).get("sha256", beside) != beside:
            out[folder] = f"kept beside another general policy ({judged[folder.name].get('path')})"
    return out


def _better(a: Performance, b: Performance) -> bool:
    """Whether ``a`` played better than ``b``: note F1, then velocity error (the learners' rule)."""
    ra, rb = a.report(), b.report()
    mae = lambda r: r.velocity_mae if r.velocity_mae is not None else float("inf")  # noqa: E731
    return (ra.f1, -mae(ra)) > (rb.f1, -mae(rb))


def play_one_hand(
    piece: Piece,
    controller: str = "sac",
    models: Path | str | None = None,
    seed: int = 0,
    video: bool = False,
    on_step: Callable[[int, int], None] | None = None,
    **options,
) -> Performance:
    """Perform ``piece`` as ``pianobot play`` does: :func:`plan_performance` (``controller``,
    ``models`` and ``options`` are its arguments), then :func:`perform_plan` from hand start ``seed``.

    A phrase policy :func:`doubted` (made on another simulator, or judged beside another general
    policy) plays as it is only where it plays better: the piece is played both ways, with it
    and with the general policy in its place, the better kept (note F1, then velocity error;
    the phrase policy on a tie), and one warning line says which. Without a general policy to
    judge it beside, it plays, and the line says so."""
    plan = plan_performance(piece, controller, models, **options)

    def replan(leave_out: frozenset[str]) -> PerformancePlan:
        return plan_performance(piece, controller, models, **options, leave_out=leave_out)

    return perform_judged(plan, models, replan, seed, video, on_step)


def perform_judged(
    plan: PerformancePlan,
    models: Path | str | None,
    replan: Callable[[frozenset[str]], PerformancePlan],
    seed: int = 0,
    video: bool = False,
    on_step: Callable[[int, int], None] | None = None,
) -> Performance:
    """:func:`perform_plan`, judging the :func:`doubted` phrase policies as :func:`play` says;
    ``replan(leave_out)``: the same plan with those policy folders left out."""
    suspect = frozenset(s.policy.name for s in plan.stretches if s.player is Player.OWN)
    if not suspect:
        return perform_plan(plan, seed, video, on_step)
    try:
        other = replan(suspect)
    except PianobotError:
        other = None
    doubts = doubted(plan, models, other.general if other is not None else None)
    if not doubts:
        return perform_plan(plan, seed, video, on_step)
    one = len(doubts) == 1
    names = f"phrase polic{'y' if one else 'ies'} " + ", ".join(f"{f.name} ({why})" for f, why in doubts.items())
    if doubts.keys() != {s.policy for s in plan.stretches if s.player is Player.OWN}:
        with contextlib.suppress(
            PianobotError
        ):  # (else the general policy cannot play beside the others: it plays all)
            other = replan(frozenset(f.name for f in doubts))
    if other is None or other.general is None:
        warnings.warn(
            PianobotWarning(f"{names}: played as {'it is' if one else 'they are'}, no general policy to judge beside")
        )
        return perform_plan(plan, seed, video, on_step)
    mine = perform_plan(plan, seed, video, on_step)
    theirs = perform_plan(other, seed, video, on_step)
    ours, general = mine.report().f1, theirs.report().f1
    if _better(theirs, mine):
        kept, said = (
            theirs,
            f"kept the general policy {other.general.name} (note F1 {general:.3f}; {ours:.3f} with {'it' if one else 'them'})",
        )
    else:
        kept, said = (
            mine,
            f"kept {'it' if one else 'them'} (note F1 {ours:.3f}; {general:.3f} with the general policy {other.general.name})",
        )
    warnings.warn(PianobotWarning(f"{names}: played both ways, {said}"))
    return kept
