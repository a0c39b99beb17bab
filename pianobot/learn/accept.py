"""Fine-tuning never makes a piece worse: after training a piece's phrases, the whole piece is
played as ``pianobot play`` will play it, and a phrase's own policy is used only where it helps.

A phrase's policy is kept by its training run on evaluation hand starts (``EVAL_SEED`` on); it
is judged here on other ones, :data:`JUDGE_SEEDS` (``play``'s own, its default ``--seed 0``
among them), inside the whole performance: its section, the hand-over to and from its
neighbours. :func:`settle_piece`:

1. records in the store's index (:func:`~pianobot.agent.store.general_plays`) every phrase whose
   training kept its start, because the general policy already played it at step 0 or no later
   evaluation beat it: no policy is stored;
2. plays the piece with the general policy alone (``before``), then adds the piece's own phrase
   policies one at a time, in order, keeping one only when the piece then plays better on the
   mean of :data:`JUDGE_SEEDS` and no worse from any of them; a policy not kept is recorded in
   the index as played by the general policy (its folder stays, unused);
3. returns a :class:`Verdict`: note F1 before and after, and which policies play.

So the piece's note F1 as ``play`` performs it from each of :data:`JUDGE_SEEDS` is never below
what the general policy alone gives. The judge is the general policy ``play`` would use beside
the piece's policies (:func:`judge_for`), whether or not training started from it. Without one
nothing is judged: there is no other player to fall back on.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from pianobot.agent import store
from pianobot.agent.general import describe, find_general
from pianobot.agent.policy import policy_configs
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError
from pianobot.music.phrases import Phrase
from pianobot.music.piece import Piece
from pianobot.perform.compose import find_policy
from pianobot.perform.plan import PerformancePlan, perform_plan, stretches_for

JUDGE_SEEDS = (0, 1, 2)
"""Hand starts a whole piece is judged from: ``play``'s, never the training evaluations'."""


@dataclass(frozen=True)
class Verdict:
    """What training changed in how the piece plays."""

    before: tuple[float, ...]
    """Note F1 from each of :data:`JUDGE_SEEDS` with the general policy playing every phrase."""
    after: tuple[float, ...]
    """The same with the policies kept (``used``)."""
    used: dict[int, str]
    """Phrase number -> the folder of its own policy that plays it."""
    dropped: dict[int, str]
    """Phrase number -> why its own policy is not used."""
    general_plays: tuple[int, ...]
    """Phrases whose training kept its start, the general policy: no policy stored."""

    def to_dict(self) -> dict:
        return {
            "seeds": list(JUDGE_SEEDS),
            "f1_before": list(self.before),
            "f1_after": list(self.after),
            "used": {str(k): v for k, v in self.used.items()},
            "dropped": {str(k): v for k, v in self.dropped.items()},
            "general_plays": list(self.general_plays),
        }


def judge_for(models: Path, env: EnvConfig, start: Path | None) -> Path | None:
    """The general policy a piece's phrase policies (trained in ``env``) are judged against: the
    one training started from, else the one ``play`` would use beside them (the user's newest in
    ``models`` that fits ``env``, then the packaged one). None when ``play`` would have none."""
    if start is not None:
        return start
    try:
        return find_general(models, env)
    except PianobotError:  # the user's general policy does not fit these phrases: play says so, and uses none
        return None


def _f1s(plan: PerformancePlan, seeds: tuple[int, ...]) -> tuple[float, ...]:
    return tuple(perform_plan(plan, seed).report().f1 for seed in seeds)


def settle_piece(
    piece: Piece,
    phrases: list[Phrase],
    models: Path,
    general: Path,
    started: dict[str, float],
    seeds: tuple[int, ...] = JUDGE_SEEDS,
    on_play: Callable[[str], None] = lambda what: None,
) -> Verdict:
    """Record and judge a piece's phrases after training (the module's steps). ``started``: the
    folder names of the phrases whose runs kept their start (the general policy played them at
    step 0 as well as any policy trained for them), each with the note F1 it played at. ``on_play(what)`` is told before each whole-piece play."""
    about = describe(general)  # its folder and the SHA-256 of its weights
    store.mark_general_plays(
        models,
        {
            name: {
                "why": f"it played at note F1 {f1:.3f} before any training step, and no policy trained for it played better",
                **about,
            }
            for name, f1 in started.items()
        },
    )
    config = policy_configs(general)[0]
    own: dict[int, Path] = {}  # every phrase policy of the piece that can play beside the general policy
    for phrase in phrases:
        folder = find_policy(models, phrase)
        if folder is not None and policy_configs(folder)[0] == config:
            own[phrase.index] = folder
    at_start = {p.index for p in phrases if p.index not in own and find_policy(models, p) is None}

    def plan(kept: dict[int, Path]) -> PerformancePlan:
        return PerformancePlan(piece, config, stretches_for(phrases, kept, general))

    on_play("the general policy alone")
    before = current = _f1s(plan({}), seeds)
    kept: dict[int, Path] = {}
    dropped: dict[int, str] = {}
    for number, folder in own.items():
        if folder in kept.values() or number in dropped:  # a repeated phrase shares its policy: judged once
            continue
        same = {i: f for i, f in own.items() if f == folder}  # every phrase this policy plays
        on_play(f"phrase {number}'s own policy")
        trial = _f1s(plan({**kept, **same}), seeds)
        if all(t >= c for t, c in zip(trial, current)) and sum(trial) > sum(current):
            kept.update(same)
            current = trial
        else:
            dropped.update(
                {
                    i: (
                        f"the piece played at mean note F1 {np.mean(trial):.3f} with it, {np.mean(current):.3f} without"
                    )
                    for i in same
                }
            )
    store.mark_general_plays(
        models,
        {folder.name: None for folder in kept.values()}
        | {
            own[i].name: {"why": f"its own policy made the piece play worse: {why}", **about}
            for i, why in dropped.items()
        },
    )
    return Verdict(
        before=before,
        after=current,
        used={i: f.name for i, f in kept.items()},
        dropped=dropped,
        general_plays=tuple(sorted(at_start)),
    )
