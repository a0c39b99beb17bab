"""Compositional execution (paper, "Compositional Execution for long-horizon task"): a whole piece
played by the policies of its phrases, one after another, in one continuous simulation.

The performance is a series of sections, each played by one controller. Each phrase's own
policy was trained on its phrase alone, seeing a sliding score window of only that phrase's
notes, and it plays a section of that one phrase: the window at the current time, masked to its
phrase. Control passes from section k-1 to section k once the onset tolerance of section k-1's
last note has run out (a strike up to 50 ms late still counts, so its controller keeps the hand
until then), or one lead-in before section k's first note, whichever is later, but at the latest
one step before section k's first onset; the hand is wherever the previous controller left it.

Who plays a phrase is the performance plan's decision (:mod:`pianobot.perform.plan`): its own
policy, the general policy (:mod:`pianobot.agent.general`) or the scripted pianist, each
phrase a section of its own, except that consecutive phrases the general policy plays form one section: it
sees that stretch's whole window, a note held over a phrase break and the next phrase's notes
included, with no hand-over to itself at the breaks. It was trained on single phrases, each
alone in its window, so this is new to it; it plays better for it (docs/benchmarks.md, "What
the wrist guard and one section change"). With ``guard``, the general policy plays through a
:class:`~pianobot.perform.guard.WristGuard`, with ``hold`` through a
:class:`~pianobot.perform.guard.HoldGuard` (the scripted pianist moves the fingers that hold a
note). All of them play in one simulation, so the
policies must share one environment (the plan's).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

import numpy as np

from pianobot.agent import store
from pianobot.agent.policy import load_policy
from pianobot.env.piano import PianoEnv
from pianobot.music.metrics import DEFAULT_ONSET_TOLERANCE
from pianobot.music.phrases import DEFAULT_MAX_NOTES, Phrase, split_phrases
from pianobot.music.piece import Piece
from pianobot.music.tensor import score_tensor
from pianobot.perform.guard import HoldGuard, WristGuard
from pianobot.perform.rollout import Controller
from pianobot.pianist.scripted import ScriptedPianist


@dataclass
class Section:
    """One controller's stretch of the performance: one phrase, or consecutive phrases the general policy plays."""

    phrases: tuple[Phrase, ...]
    first_step: int
    """Env step at which this section's controller takes over."""
    start: int
    """Env step of the section's first score row (the step of its first onset, or the one before)."""
    tensor: np.ndarray
    """The section's own score tensor (steps x keys x channels), from env step ``start`` on. A phrase's
    own policy gets its phrase's tensor as in training (its first onset on row 0, the others placed
    from there); the general policy and the scripted pianist get each note on the step the
    environment scores it at. The two differ by a step for notes off the control-step grid."""
    controller: Controller
    stretch: object
    """The plan's :class:`~pianobot.perform.plan.Stretch` this section plays: who, with which policy."""

    def rows(self, begin: int, end: int) -> np.ndarray:
        """Env steps ``begin`` to ``end`` of the performance's score as this section's controller
        sees it: only its own notes. Memory stays that of the section, however long the piece."""
        out = np.zeros((end - begin, *self.tensor.shape[1:]), self.tensor.dtype)
        low, high = max(begin, self.start), min(end, self.start + len(self.tensor))
        if low < high:
            out[low - begin : high - begin] = self.tensor[low - self.start : high - self.start]
        return out


def find_policy(models: Path, phrase: Phrase) -> Path | None:
    found = store.find_policies(models, phrase.hash)
    return found[0] if found else None


def missing_phrases(models: Path, phrases: list[Phrase]) -> list[Phrase]:
    """The phrases the store has no player for: no policy of their own, and not in its index of
    phrases the general policy plays (:func:`~pianobot.agent.store.general_plays`)."""
    covered = store.covered_keys(models)
    return [p for p in phrases if p.hash not in covered]


def phrase_players(models: Path, phrases: list[Phrase]) -> dict[int, str]:
    """Who the store says plays each phrase, by index, in words: 'own policy', 'own policy (of
    simulator v0: play judges it)' where it was trained on another simulator than this one,
    'general policy (judged better)' where the store's index says the general policy plays it
    (training kept the general policy, or the phrase's own policy made its piece play worse),
    else 'general policy (phrase not trained)'. A policy of its own is a folder for the phrase, of any configuration."""
    from pianobot.env import VERSION

    own, general = store.trained_keys(models), {key.rsplit("-", 1)[0] for key in store.general_plays(models)}

    def own_policy(phrase: Phrase) -> str:
        version = store.simulator(find_policy(models, phrase))
        return "own policy" if version == VERSION else f"own policy (of simulator v{version}: play judges it)"

    return {
        p.index: "general policy (judged better)"
        if p.hash in general
        else own_policy(p)
        if p.hash in own
        else "general policy (phrase not trained)"
        for p in phrases
    }


def trained_split(models: Path, piece: Piece, phrase_notes: int | None) -> list[Phrase]:
    """The piece's phrases for compositional play.

    ``phrase_notes`` given: the split it makes. Otherwise the longest phrases (at most
    :data:`DEFAULT_MAX_NOTES` notes) whose policies are all stored, so that a piece trained with
    ``--phrase-notes 3`` plays without repeating the option; when no split is fully trained,
    the default split (whose missing phrases are then reported, or played by the fallback).
    """
    if phrase_notes is not None:
        return split_phrases(piece, phrase_notes)
    widest = max((len(c) for c in piece.chords()), default=1)  # a chord is never split across phrases
    for most in range(DEFAULT_MAX_NOTES, widest - 1, -1):
        phrases = split_phrases(piece, most)
        if not missing_phrases(models, phrases):
            return phrases
    return split_phrases(piece, DEFAULT_MAX_NOTES)


class Player(str, Enum):
    """Who plays a stretch of a performance (the plan, :mod:`pianobot.perform.plan`, decides)."""

    OWN = "own policy"
    GENERAL = "general policy"
    SCRIPTED = "scripted pianist"
    RANDOM = "random actions"


class CompositionalController:
    """Acts with the controller of the section the current step falls in. ``stretches`` say who
    plays what (:func:`pianobot.perform.plan.assign`): a phrase's own policy, the general policy
    (loaded once, shared by every stretch it plays), or the scripted pianist. ``guard``: the
    general policy plays through a :class:`~pianobot.perform.guard.WristGuard`; ``hold``: through a
    :class:`~pianobot.perform.guard.HoldGuard`, where its environment allows one (both: the hold
    guard outside)."""

    def __init__(self, env: PianoEnv, stretches, guard: bool = False, hold: bool = False):
        spec = env.spec_score
        lead = env.lead_steps
        grace = math.ceil(DEFAULT_ONSET_TOLERANCE * spec.control_hz - 1e-9)  # steps a strike may come late
        general_agent = None  # loaded once, shared by every stretch it plays (a policy keeps no state)
        runs: list[
            tuple[list[Phrase], Controller, object, bool]
        ] = []  # each section's phrases, controller, stretch, own?
        for stretch in stretches:
            if stretch.player is Player.OWN:
                controller = load_policy(stretch.policy, env)
            elif stretch.player is Player.GENERAL:
                if general_agent is None:
                    agent = load_policy(stretch.policy, env)
                    if guard and not env.config.world.discrete_wrist:  # (a wrist that goes to keys has no speed)
                        agent = WristGuard(agent, env.config)
                    general_agent = HoldGuard(agent, env.config) if hold and HoldGuard.fits(env.config) else agent
                controller = general_agent
            elif stretch.player is Player.SCRIPTED:
                controller = ScriptedPianist(env.config)
            else:
                raise ValueError(f"compositional execution has no {stretch.player.value}")
            runs.append((list(stretch.phrases), controller, stretch, stretch.player is Player.OWN))
        self.sections: list[Section] = []
        previous_last_onset = None
        for members, controller, stretch, own in runs:
            onset = lead + spec.step_of(members[0].start)  # the section's first onset's step
            if previous_last_onset is None:
                first = 0
            else:
                latest = max(onset - 1, previous_last_onset + 1)
                first = max(min(previous_last_onset + 1 + grace, latest), onset - lead)
            notes = Piece(tuple(note for phrase in members for note in phrase.notes))
            if own:  # a phrase's own policy sees its phrase exactly as in training: from its first onset
                row, shift = spec.step_of(members[0].start), members[0].start
            else:  # the others see every note on the step the environment scores it at (the piece's grid)
                row = math.floor(members[0].start * spec.control_hz + 1e-9)
                shift = min(row / spec.control_hz, members[0].start)
            tensor = score_tensor(notes.shift(-shift), spec)
            self.sections.append(Section(tuple(members), first, lead + row, tensor, controller, stretch))
            previous_last_onset = lead + spec.step_of(members[-1].notes[-1].onset)
        self.env = env
        self.lookahead = env.config.lookahead
        self.step = 0

    def reset(self) -> None:
        self.step = 0
        for section in self.sections:
            section.controller.reset()

    def section_at(self, step: int) -> Section:
        """The section whose controller acts at ``step`` (sections take over in order)."""
        index = bisect.bisect_right([s.first_step for s in self.sections], step) - 1
        return self.sections[max(index, 0)]

    def act(self, observation: dict) -> np.ndarray:
        section = self.section_at(self.step)
        window = section.rows(self.step, self.step + self.lookahead + 1)
        observation = {**observation, "score": window}
        if "targets" in observation:  # what the section's own window asks of each finger
            previous = section.rows(self.step - 1, self.step)[0] if self.step > 0 else np.zeros_like(window[0])
            observation["targets"] = self.env.targets(window, previous)
        self.step += 1
        return section.controller.act(observation)


def _guard(controller: Controller, kind: type):
    """The guard of ``kind`` the general policy plays through in ``controller`` (None: none)."""
    for section in controller.sections if isinstance(controller, CompositionalController) else []:
        guard = section.controller
        while isinstance(guard, (HoldGuard, WristGuard)):
            if isinstance(guard, kind):
                return guard
            guard = guard.policy
    return None


def slowed_steps(controller: Controller) -> int | None:
    """Steps at which the wrist guard slowed the general policy's wrist in ``controller`` (None: no guard played)."""
    guard = _guard(controller, WristGuard)
    return guard.capped if guard is not None else None


def held_steps(controller: Controller) -> int | None:
    """Finger-steps the hold guard moved a holding finger in ``controller`` (None: no guard played)."""
    guard = _guard(controller, HoldGuard)
    return guard.held if guard is not None else None


def wrist_steps(controller: Controller) -> int:
    """Control steps in which the hold guard moved the wrist in ``controller`` (0: none, or no guard)."""
    guard = _guard(controller, HoldGuard)
    return guard.wrist if guard is not None else 0
