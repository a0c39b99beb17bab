"""One performance, one call: who plays each stretch of a piece, in which environment, and playing it.

:func:`plan_performance` decides, before anything is simulated, who plays each phrase: its own
policy (from the model store), the general policy (the user's store first, then the one that
ships with pianobot), or the scripted pianist (``fallback``, or ``controller='scripted'``). The
answer is a :class:`PerformancePlan`: immutable, typed, and what the report and the MIDI track
say about who played. :func:`perform_plan` performs a plan in one continuous simulation
(compositional execution, :mod:`pianobot.perform.compose`);
:func:`pianobot.perform.judge.play_one_hand` does both, as ``pianobot play`` does::

    performance = pianobot.play(pianobot.load_piece("examples/midi/mary.mid"))
    print(performance.plan.performer, performance.report().f1)

Who plays a phrase, in order: its own policy, unless the store's index says the general policy
plays it (:func:`pianobot.agent.store.general_plays`: the phrase's training kept its start, the
general policy, or the phrase's own policy made its piece play worse); else the general policy;
else, with ``fallback``, the scripted pianist. Consecutive phrases the general policy plays are
one stretch: it plays them as one section, with no hand-over to itself at the phrase breaks.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

from pianobot.agent import store
from pianobot.agent.general import (
    PACKAGED,
    describe,
    find_general,
    general_candidates,
    on_keyboard,
    passed_over,
    plays_keyboard,
)
from pianobot.agent.policy import policy_configs
from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.errors import PianobotError, SettingError
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.metrics import Report
from pianobot.music.pedal import Pedal
from pianobot.music.phrases import DEFAULT_MAX_NOTES, Phrase, split_phrases
from pianobot.music.piece import Piece
from pianobot.perform import compose
from pianobot.perform import perform as simulation  # (called through the module: tests replace simulation.perform)
from pianobot.perform.compose import CompositionalController, Player, find_policy, trained_split
from pianobot.perform.controllers import CONTROLLERS, make_controller
from pianobot.perform.guard import guarded_family
from pianobot.perform.perform import PLAY_CONFIG
from pianobot.perform.rollout import Controller, Rollout
from pianobot.sim.hand import hand_config
from pianobot.sim.keyboard import KeyboardConfig
from pianobot.sim.world import WorldConfig

DEFAULT_MODELS = store.DEFAULT_STORE
"""The model store when none is named: ``models`` in the current folder (where ``pianobot train``
writes). The general policy that ships with pianobot is found from anywhere besides."""


ONE_PLAYER = {"scripted": Player.SCRIPTED, "random": Player.RANDOM}
"""The controllers (:data:`~pianobot.perform.controllers.CONTROLLERS`) that play a whole piece
alone; 'sac' is the trained policies: each phrase's own, else the general policy."""


@dataclass(frozen=True)
class Stretch:
    """Consecutive phrases played by one player: a phrase's own policy plays that phrase alone;
    the general policy plays consecutive phrases as one section."""

    phrases: tuple[Phrase, ...]
    player: Player
    policy: Path | None = None
    """The policy's folder (own policy, general policy); None for the scripted pianist and random actions."""

    def __post_init__(self) -> None:
        if not self.phrases:
            raise ValueError("a stretch has at least one phrase")
        if (self.policy is not None) != (self.player in (Player.OWN, Player.GENERAL)):
            raise ValueError(f"a stretch played by the {self.player.value} has {'no' if self.policy else 'a'} policy")
        if self.player is Player.OWN and len(self.phrases) != 1:
            raise ValueError("a phrase's own policy plays its phrase alone")

    def describe(self) -> str:
        """'own policy <folder>', 'general policy <folder>', 'scripted pianist' or 'random actions'."""
        return f"{self.player.value} {self.policy.name}" if self.policy is not None else self.player.value

    def to_dict(self) -> dict:
        return {
            "phrases": [p.index for p in self.phrases],
            "player": self.player.value,
            "policy": str(self.policy) if self.policy is not None else None,
        }


@dataclass(frozen=True)
class PerformancePlan:
    """A piece, the environment it is played in, and who plays each stretch of it, in order."""

    piece: Piece
    config: EnvConfig
    stretches: tuple[Stretch, ...]
    wrist_guard: bool = False
    """The general policy plays through a :class:`~pianobot.perform.guard.WristGuard`."""
    hold_guard: bool | None = None
    """The general policy plays through a :class:`~pianobot.perform.guard.HoldGuard`: the scripted
    pianist moves the fingers that hold a written note (where the policy's environment allows it).
    None: where the general policy was trained on a family of
    :data:`~pianobot.perform.guard.HOLD_GUARD_FAMILIES` (:attr:`holds`)."""
    pedal: Pedal = Pedal()
    """The piece's sustain pedal, which the foot plays as written (where the players do not work it)."""

    def __post_init__(self) -> None:
        if not self.stretches:
            raise ValueError("a plan has at least one stretch")

    @property
    def holds(self) -> bool:
        """Whether the general policy plays through the hold guard: :attr:`hold_guard`, or where that
        is None, whether it was trained on a family of :data:`~pianobot.perform.guard.HOLD_GUARD_FAMILIES`."""
        return self.hold_guard if self.hold_guard is not None else guarded_family(self.general)

    @property
    def phrases(self) -> tuple[Phrase, ...]:
        return tuple(p for s in self.stretches for p in s.phrases)

    @property
    def players(self) -> tuple[Player, ...]:
        """Every player that plays a stretch, in the order of :class:`Player`."""
        return tuple(p for p in Player if any(s.player is p for s in self.stretches))

    @property
    def general(self) -> Path | None:
        """The general policy's folder, when it plays a stretch."""
        return next((s.policy for s in self.stretches if s.player is Player.GENERAL), None)

    @property
    def performer(self) -> str:
        """Who played, in words: 'general policy', 'own policies and general policy', 'scripted pianist', ..."""
        names = [("own policies" if p is Player.OWN else p.value) for p in self.players]
        return " and ".join(names)

    def player_of(self, phrase: int) -> Stretch:
        """The stretch that plays phrase number ``phrase``."""
        return next(s for s in self.stretches if any(p.index == phrase for p in s.phrases))

    def to_dict(self) -> dict:
        """What a report says of the plan: the performer, each stretch, and the general policy's weights."""
        out: dict = {
            "performer": self.performer,
            "stretches": [s.to_dict() for s in self.stretches],
            "phrases": {str(p.index): s.describe() for s in self.stretches for p in s.phrases},
        }
        if self.general is not None:
            out["general_policy"] = describe(self.general)
        return out


@dataclass(frozen=True)
class Performance:
    """A plan, performed: what the piano played (:attr:`rollout`) and who played it (:attr:`plan`)."""

    plan: PerformancePlan
    rollout: Rollout
    seed: int
    slowed_steps: int | None = None
    """Steps at which the wrist guard slowed the general policy's wrist (None: no guard played)."""
    held_steps: int | None = None
    """Finger-steps the hold guard's scripted pianist moved a holding finger (None: no guard played)."""
    wrist_steps: int = 0
    """Control steps in which the hold guard's scripted pianist moved the wrist (a finger held, and no
    note was to start soon)."""

    @property
    def played(self) -> Piece:
        return self.rollout.played

    @property
    def pedal(self) -> Pedal:
        """The sustain pedal as the foot worked it, in the piece's time."""
        return self.rollout.pedal

    @property
    def frames(self) -> list:
        return self.rollout.frames

    @property
    def start(self) -> float:
        return self.rollout.start

    def report(self) -> Report:
        return self.rollout.report()

    def guards(self) -> dict:
        """What each guard (:mod:`pianobot.perform.guard`) did to the general policy's actions; empty
        when the general policy played nothing."""
        if self.plan.general is None:
            return {}
        return {
            "wrist_guard": {"on": self.slowed_steps is not None, "slowed_steps": self.slowed_steps or 0},
            "hold_guard": {
                "on": self.held_steps is not None,
                "held_finger_steps": self.held_steps or 0,
                "wrist_steps": self.wrist_steps,
            },
        }

    def to_dict(self) -> dict:
        """The report's JSON: who played (the plan) and with which fingers, the seed, what the guards
        did, and every figure."""
        spec = self.plan.config.world.hand.spec
        return {
            "seed": self.seed,
            **self.plan.to_dict(),
            "hand_model": spec.model,
            "fingers": list(spec.fingers),
            **self.guards(),
            **self.report().to_dict(),
        }


def assign(
    phrases: list[Phrase],
    models: Path,
    general: Path | None = None,
    fallback: bool = False,
    passed_over: Callable[[], str] | None = lambda: "",
    leave_out: frozenset[str] = frozenset(),
) -> tuple[Stretch, ...]:
    """Who plays each phrase (the module's rule), as stretches in order. A phrase nobody can play
    is a :class:`PianobotError` naming it, where the store is, why the packaged general policy
    does not play it (``passed_over()``, asked only then: :func:`passed_over`; None: the general
    policy was left out) and how to go on. ``leave_out``: policy folders (names) not to use."""
    index = store.general_plays(models).keys() | leave_out
    own = {p.index: f for p in phrases if (f := find_policy(models, p)) is not None and f.name not in index}
    for phrase in phrases:
        if phrase.index not in own and general is None and not fallback:
            notes = " ".join(n.name for n in phrase.notes)
            where = str(models) if Path(str(models)).is_absolute() else f"{models} ({Path(models).resolve()})"
            if passed_over is None:
                general_said = "and the general policy is left out (play.general)"
            else:
                why = f"looked there and in {PACKAGED}" + (f"; {reason}" if (reason := passed_over()) else "")
                general_said = f"and no general policy plays it ({why})"
            raise SettingError(
                f"phrase {phrase.index} ({notes}) has no policy of its own in the model store {where} "
                f"{general_said}: "
                "train it with `pianobot train` (same reading options), train a general policy with "
                "`pianobot train --task parts`, name another store with store.models DIR, play with play.fallback scripted, "
                "or play with play.controller scripted",
                "store.models",
            )
    return stretches_for(phrases, own, general)


def stretches_for(phrases: list[Phrase], own: dict[int, Path], general: Path | None) -> tuple[Stretch, ...]:
    """Stretches in which the phrases numbered in ``own`` play with those policies, the others with
    ``general`` (consecutive ones as one stretch), or, without it, each with the scripted pianist."""
    stretches: list[Stretch] = []
    for phrase in phrases:
        if phrase.index in own:
            stretches.append(Stretch((phrase,), Player.OWN, own[phrase.index]))
        elif general is None:
            stretches.append(Stretch((phrase,), Player.SCRIPTED))
        elif stretches and stretches[-1].player is Player.GENERAL:  # the general policy goes on playing
            stretches[-1] = replace(stretches[-1], phrases=(*stretches[-1].phrases, phrase))
        else:
            stretches.append(Stretch((phrase,), Player.GENERAL, general))
    return tuple(stretches)


def _own_environment(models: Path, phrases: list[Phrase], leave_out: frozenset[str] = frozenset()) -> EnvConfig | None:
    """The environment the piece's own phrase policies were trained in (None: none has one); one for all."""
    index = store.general_plays(models).keys() | leave_out
    folders = {f for f in (find_policy(models, p) for p in phrases) if f is not None and f.name not in index}
    configs = {policy_configs(folder)[0] for folder in folders}
    if len(configs) > 1:
        raise PianobotError(
            f"the policies in {models} for this piece were trained with different environments: "
            "retrain them with one set of options"
        )
    return configs.pop() if configs else None


def _general_for(
    models: Path, env: EnvConfig | None, keyboard: KeyboardSpec, hand: HandSpec, path: Path | None
) -> Path | None:
    """The general policy that fits: the phrase policies' environment when there are some, else the
    keyboard and hand the piece is played on. None when there is no general policy at all."""
    if env is not None:
        return find_general(
            models,
            env,
            path=path,
            ours="the phrase policies of this piece",
            remedy="play with play.fallback scripted, or train the general policy or the phrases with the same options",
        )
    candidates = [Path(path)] if path is not None else general_candidates(models)
    if path is not None:
        find_general(models, path=path)  # a folder that holds no policy: one line
    for folder in candidates:
        their_env, their_sac = policy_configs(folder)
        if plays_keyboard(their_env, their_sac, keyboard) and their_env.world.hand.spec == hand:
            return folder
    theirs = [f for f in candidates if path is not None or PACKAGED not in f.resolve().parents]
    if not theirs:  # (no packaged policy plays this keyboard and hand)
        return None
    world = policy_configs(theirs[0])[0].world
    raise SettingError(
        f"the general policy {theirs[0]} plays {world.keyboard.spec.describe()} with fingers "
        f"{world.hand.spec.describe()}, this piece is read for {keyboard.describe()} with fingers {hand.describe()} "
        "(keyboard.lowest, keyboard.count, hand.fingers): play with play.controller scripted, or train a general policy for them "
        "with `pianobot train --task parts` and the same options",
        "keyboard.lowest",
    )


def plan_performance(
    piece: Piece,
    controller: str = "sac",
    models: Path | str | None = None,
    *,
    keyboard: KeyboardSpec | None = None,
    hand: HandSpec | None = None,
    general: bool = True,
    general_policy: Path | str | None = None,
    fallback: bool = False,
    phrase_notes: int | None = None,
    wrist_guard: bool = PerformancePlan.wrist_guard,
    hold_guard: bool | None = PerformancePlan.hold_guard,
    gui: bool = False,
    leave_out: frozenset[str] = frozenset(),
    pedal: Pedal = Pedal(),
) -> PerformancePlan:
    """Who plays each stretch of ``piece`` and in which environment (the module's rule).

    ``controller``: 'sac' (trained policies), 'scripted' or 'random' (one player for the whole
    piece). ``models``: the user's model store (default :data:`DEFAULT_MODELS`). ``keyboard``,
    ``hand``: what the piece was read for (defaults: the paper's keyboard and the three-finger
    hand). ``general``: let the general policy play phrases without a policy of their own
    (``general_policy`` names one; default: the newest in ``models``, then the packaged one).
    ``fallback``: the scripted pianist plays what no policy plays. ``phrase_notes``: the phrase
    split (default: the longest whose phrases all have a player in the store). ``wrist_guard``,
    ``hold_guard``: the general policy plays through them (:mod:`pianobot.perform.guard`; a
    ``hold_guard`` of None: :attr:`PerformancePlan.holds`).
    ``gui``: show the simulation. ``leave_out``: phrase policy folders (names) not to use."""
    if controller not in CONTROLLERS:
        raise SettingError(f"play.controller {controller!r}: choose one of {', '.join(CONTROLLERS)}", "play.controller")
    if general_policy is not None and not general:
        raise SettingError(
            f"general.path {general_policy} names a general policy and play.general leaves it out: give one",
            "general.path",
        )
    keyboard, hand = keyboard or KeyboardSpec(), hand or HandSpec()
    models = Path(models) if models is not None else DEFAULT_MODELS
    world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=hand_config(hand), gui=gui)
    if controller in ONE_PLAYER:
        phrases = split_phrases(piece, phrase_notes or DEFAULT_MAX_NOTES)
        stretch = Stretch(tuple(phrases), ONE_PLAYER[controller])
        return PerformancePlan(piece, replace(PLAY_CONFIG, world=world), (stretch,), pedal=pedal)

    phrases = trained_split(models, piece, phrase_notes)
    env = _own_environment(models, phrases, leave_out)
    folder = _general_for(models, env, keyboard, hand, general_policy) if general else None
    said = (lambda: passed_over(keyboard, hand)) if general else None
    stretches = assign(phrases, models, folder, fallback, said, leave_out)
    if env is None and folder is not None:
        env = on_keyboard(*policy_configs(folder), keyboard)
    if env is None:  # the scripted pianist plays every phrase
        env = replace(PLAY_CONFIG, world=world)
    if env.world.keyboard.spec != keyboard or env.world.hand.spec != hand:
        raise SettingError(
            f"the policies in {models} were trained for another keyboard or hand: use the same keyboard.lowest, "
            "keyboard.count and hand.fingers",
            "keyboard.lowest",
        )
    if any(s.player is Player.SCRIPTED for s in stretches) and env.world.control == "torque":
        raise SettingError(
            "play.fallback scripted needs policies trained with train.env.world.control velocity or position",
            "play.fallback",
        )
    config = replace(env, world=replace(env.world, gui=gui))
    if config.tactile and not any(_reads_touch(s.policy) for s in stretches if s.policy is not None):
        config = replace(config, tactile=False)  # (no player reads touch: its images would be drawn for nobody)
    return PerformancePlan(piece, config, stretches, wrist_guard, hold_guard, pedal)


def _reads_touch(policy: Path) -> bool:
    """Whether a stored policy's actor reads the fingertips' images (the 'fingers' actor does not)."""
    return policy_configs(policy)[1].actor != "fingers"


def controller_for(plan: PerformancePlan, env: PianoEnv, seed: int = 0) -> Controller:
    """The controller that plays ``plan`` in ``env`` (an environment of ``plan.config`` for
    ``plan.piece``): one scripted pianist or random controller for the whole piece, else
    compositional execution of the plan's stretches."""
    (first, *others) = plan.stretches
    if not others and first.player in (Player.SCRIPTED, Player.RANDOM):
        return make_controller("scripted" if first.player is Player.SCRIPTED else "random", env, seed)
    return CompositionalController(env, plan.stretches, plan.wrist_guard, plan.holds)


def perform_plan(
    plan: PerformancePlan, seed: int = 0, video: bool = False, on_step: Callable[[int, int], None] | None = None
) -> Performance:
    """Play ``plan`` in one continuous simulation from hand start ``seed``; ``video`` keeps the
    frames; ``on_step(done, total)`` reports progress."""
    made: list[Controller] = []

    def controller(env):
        made.append(controller_for(plan, env, seed))
        return made[0]

    played = simulation.perform(plan.piece, controller, plan.config, seed, video, on_step, plan.pedal)
    guards = compose.slowed_steps(made[0]), compose.held_steps(made[0]), compose.wrist_steps(made[0])
    return Performance(plan, played, seed, *guards)
