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

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, TypeVar

import numpy as np

from pianobot.agent import store
from pianobot.agent.general import describe, find_general, on_keyboard
from pianobot.agent.policy import policy_configs
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.phrases import Phrase
from pianobot.music.piece import Piece
from pianobot.perform.compose import find_policy
from pianobot.perform.plan import PerformancePlan, perform_plan, stretches_for
from pianobot.perform.together import perform_hands

Key = TypeVar("Key", int, str)
"""A phrase: its number in a one-hand piece, '<hand> <number>' in a two-hand one."""

JUDGE_SEEDS = (0, 1, 2)
"""Hand starts a whole piece is judged from: ``play``'s, never the training evaluations'."""


@dataclass(frozen=True)
class Verdict:
    """What training changed in how the piece plays."""

    before: tuple[float, ...]
    """Note F1 from each of :data:`JUDGE_SEEDS` with the general policy playing every phrase."""
    after: tuple[float, ...]
    """The same with the policies kept (``used``)."""
    used: dict[int | str, str]
    """Phrase (its number; '<hand> <number>' in a two-hand piece) -> the folder of its own policy that plays it."""
    dropped: dict[int | str, str]
    """Phrase -> why its own policy is not used."""
    general_plays: tuple[int | str, ...]
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


def _mark_started(models: Path, started: dict[str, float], about: dict) -> None:
    """Record in the store's index the phrases whose training kept the general policy ``about`` describes."""
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


def _settle(
    own: dict[Key, Path],
    f1s: Callable[[dict[Key, Path]], tuple[float, ...]],
    on_play: Callable[[str], None],
    name: Callable[[Key], str],
    seeds: tuple[int, ...] = JUDGE_SEEDS,
) -> tuple[tuple[float, ...], tuple[float, ...], dict[Key, Path], dict[Key, str]]:
    """Step 2 of the module's: (F1s before, F1s after, policies kept, why each other was dropped).
    ``own``: every phrase's own policy that may play, by phrase; ``f1s(kept)``: the piece's note
    F1 from each judging hand start with those policies; ``name(key)``: a phrase in words."""
    on_play("the general policy alone")
    before = current = f1s({})
    kept: dict[Key, Path] = {}
    dropped: dict[Key, str] = {}
    for key, folder in own.items():
        if folder in kept.values() or key in dropped:  # a repeated phrase shares its policy: judged once
            continue
        same = {k: f for k, f in own.items() if f == folder}  # every phrase this policy plays
        on_play(f"{name(key)}'s own policy")
        trial = f1s({**kept, **same})
        if all(t >= c for t, c in zip(trial, current)) and sum(trial) > sum(current):
            kept.update(same)
            current = trial
        else:
            dropped.update(dict.fromkeys(same, _why_dropped(seeds, trial, current)))
    return before, current, kept, dropped


def _why_dropped(seeds: tuple[int, ...], trial: tuple[float, ...], current: tuple[float, ...]) -> str:
    """Which of the two rules a phrase's own policy failed: no judging start may play worse with it,
    and together they must play better."""
    worse = [(seed, t, c) for seed, t, c in zip(seeds, trial, current) if t < c]
    if worse:
        seed, t, c = worse[0]
        return f"from hand start {seed} the piece played at note F1 {t:.3f} with it, {c:.3f} without (no start may play worse)"
    return f"the piece played no better with it (mean note F1 {np.mean(trial):.3f}, the same without)"


def _mark_judged(models: Path, kept: dict, dropped: dict, own: dict, about: Callable[[object], dict]) -> None:
    """Record the verdict in the store's indexes: a kept policy plays its phrases (and was judged
    beside the general policy ``about`` describes: a later ``play`` with another judges again), a
    dropped one does not."""
    store.mark_judged(
        models,
        {folder.name: about(k) for k, folder in kept.items()} | {own[k].name: None for k in dropped},
    )
    store.mark_general_plays(
        models,
        {folder.name: None for folder in kept.values()}
        | {own[k].name: {"why": f"its own policy is not used: {why}", **about(k)} for k, why in dropped.items()},
    )


def settle_piece(
    piece: Piece,
    phrases: list[Phrase],
    models: Path,
    general: Path,
    started: dict[str, float],
    seeds: tuple[int, ...] = JUDGE_SEEDS,
    on_play: Callable[[str], None] = lambda what: None,
    keyboard: KeyboardSpec | None = None,
) -> Verdict:
    """Record and judge a piece's phrases after training (the module's steps). ``started``: the
    folder names of the phrases whose runs kept their start (the general policy played them at
    step 0 as well as any policy trained for them), each with the note F1 it played at.
    ``on_play(what)`` is told before each whole-piece play. ``keyboard``: the keys the piece was
    read for (default: the general policy's own)."""
    about = describe(general)  # its folder and the SHA-256 of its weights
    _mark_started(models, started, about)
    config = policy_configs(general)[0]
    config = on_keyboard(config, policy_configs(general)[1], keyboard or config.world.keyboard.spec)
    own = _own_policies(models, phrases, config)
    at_start = {p.index for p in phrases if p.index not in own and find_policy(models, p) is None}

    def f1s(kept: dict[int, Path]) -> tuple[float, ...]:
        plan = PerformancePlan(piece, config, stretches_for(phrases, kept, general))
        return tuple(perform_plan(plan, seed).report().f1 for seed in seeds)

    before, after, kept, dropped = _settle(own, f1s, on_play, lambda number: f"phrase {number}", seeds)
    _mark_judged(models, kept, dropped, own, lambda number: about)
    return Verdict(
        before=before,
        after=after,
        used={i: f.name for i, f in kept.items()},
        dropped=dropped,
        general_plays=tuple(sorted(at_start)),
    )


def _own_policies(models: Path, phrases: list[Phrase], config: EnvConfig) -> dict[int, Path]:
    """Every phrase policy in ``models`` for ``phrases`` that can play beside a general policy of ``config``."""
    own: dict[int, Path] = {}
    for phrase in phrases:
        folder = find_policy(models, phrase)
        if folder is not None and policy_configs(folder)[0] == config:
            own[phrase.index] = folder
    return own


def settle_hands(
    piece: Piece,
    parts: dict[str, tuple],
    phrases: dict[str, list[Phrase]],
    models: Path,
    generals: dict[str, Path],
    started: dict[str, dict[str, float]],
    seeds: tuple[int, ...] = JUDGE_SEEDS,
    on_play: Callable[[str], None] = lambda what: None,
) -> Verdict:
    """:func:`settle_piece` for a two-hand piece: the whole piece, both hands as ``pianobot play``
    plays them (:func:`~pianobot.perform.together.perform_hands`), is judged against the piece as
    written, each hand's phrase policies beside that hand's general policy (``generals``).
    ``parts``: :func:`~pianobot.perform.together.prepare_parts`'; ``phrases`` and ``started`` by
    hand. A policy that plays phrases of both hands is judged once, for all of them. The
    verdict's phrases are named '<hand> <number>'."""
    abouts = {hand: describe(general) for hand, general in generals.items()}
    configs = {
        hand: on_keyboard(*policy_configs(general), parts[hand][0].keyboard) for hand, general in generals.items()
    }
    for hand in parts:
        _mark_started(models, started.get(hand, {}), abouts[hand])
    own: dict[str, Path] = {}
    at_start = []
    for hand in parts:
        mine = _own_policies(models, phrases[hand], configs[hand])
        own |= {f"{hand} {number}": folder for number, folder in mine.items()}
        at_start += [
            f"{hand} {p.index}" for p in phrases[hand] if p.index not in mine and find_policy(models, p) is None
        ]

    def f1s(kept: dict[str, Path]) -> tuple[float, ...]:
        plans = {}
        for hand, part in parts.items():
            mine = {int(k.split()[1]): f for k, f in kept.items() if k.split()[0] == hand}
            plans[hand] = PerformancePlan(part[1], configs[hand], stretches_for(phrases[hand], mine, generals[hand]))
        with warnings.catch_warnings(record=True) as caught:  # (said once, below, not once a play)
            warnings.simplefilter("always")
            f1 = tuple(perform_hands(piece, parts, plans, seed).report().f1 for seed in seeds)
        for w in caught:
            said.setdefault((w.category, str(w.message)), w.message)
        return f1

    said: dict = {}

    def name(key: str) -> str:
        hand, number = key.split()
        return f"the {hand} hand's phrase {number}"

    before, after, kept, dropped = _settle(own, f1s, on_play, name, seeds)
    for message in said.values():
        warnings.warn(message)
    _mark_judged(models, kept, dropped, own, lambda key: abouts[key.split()[0]])
    return Verdict(
        before=before,
        after=after,
        used={k: f.name for k, f in kept.items()},
        dropped=dropped,
        general_plays=tuple(at_start),
    )
